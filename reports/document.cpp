#include "reports/document.hpp"

#include <iomanip>
#include <sstream>

#include "reports/svg_plot.hpp"

namespace vessel::reports {

std::string significant(double v, int digits) {
  std::ostringstream s;
  s << std::setprecision(digits) << v;
  return s.str();
}

std::string decimals(double v, int digits) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(digits) << v;
  return s.str();
}

std::string markdown_cell(const std::string& s) {
  std::string out;
  // A pipe would end the cell and a line break the row.
  for (const char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c == '\n' ? ' ' : c);
  return out;
}

namespace {

std::string table_html(const Table& t) {
  std::ostringstream out;
  out << "<table>\n<thead><tr>";
  for (const auto& h : t.header) out << "<th>" << inline_html(h) << "</th>";
  out << "</tr></thead>\n<tbody>\n";
  for (const auto& row : t.rows) {
    out << "<tr>";
    for (const auto& c : row) out << "<td>" << inline_html(c) << "</td>";
    out << "</tr>\n";
  }
  out << "</tbody></table>\n";
  return out.str();
}

const char* kStyle = R"(body{font-family:system-ui,sans-serif;max-width:1180px;margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
table{border-collapse:collapse;margin:1em 0;font-size:13px}th,td{border:1px solid #ccc;padding:3px 7px;text-align:right}
th{background:#f2f2f2}td:first-child,th:first-child{text-align:left}code{background:#f4f4f4;padding:0 3px}
pre{background:#f4f4f4;padding:.6em;overflow-x:auto}figure{margin:1.5em 0}figcaption{font-size:13px;color:#555;max-width:760px}
h1{border-bottom:2px solid #333}h2{border-bottom:1px solid #aaa;margin-top:2em})";

}  // namespace

std::string inline_html(const std::string& md) {
  const std::string s = escape_xml(md);
  std::string out;
  bool code = false, bold = false, italic = false;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '`') {
      out += code ? "</code>" : "<code>";
      code = !code;
    } else if (!code && s.compare(i, 2, "**") == 0) {
      out += bold ? "</strong>" : "<strong>";
      bold = !bold;
      ++i;
    } else if (!code && s[i] == '*' && (italic || (i + 1 < s.size() && s[i + 1] != ' '))) {
      out += italic ? "</em>" : "<em>";
      italic = !italic;
    } else {
      out += s[i];
    }
  }
  if (code) out += "</code>";
  if (bold) out += "</strong>";
  if (italic) out += "</em>";
  return out;
}

void Document::heading(int level, std::string text) {
  Block b;
  b.kind = Block::Kind::heading;
  b.level = level;
  b.text = std::move(text);
  blocks_.push_back(std::move(b));
}

void Document::paragraph(std::string text) {
  Block b;
  b.kind = Block::Kind::paragraph;
  b.text = std::move(text);
  blocks_.push_back(std::move(b));
}

void Document::table(Table table) {
  Block b;
  b.kind = Block::Kind::table;
  b.table = std::move(table);
  blocks_.push_back(std::move(b));
}

void Document::figure(std::string file_name, std::string svg, std::string caption) {
  Block b;
  b.kind = Block::Kind::figure;
  b.file_name = std::move(file_name);
  b.svg = std::move(svg);
  b.text = std::move(caption);
  blocks_.push_back(std::move(b));
}

void Document::figure(std::string file_name, const Plot& plot, std::string caption) {
  figure(std::move(file_name), render_svg(plot), std::move(caption));
  blocks_.back().plot = plot;
}

void Document::slot(std::string id) {
  Block b;
  b.kind = Block::Kind::slot;
  b.text = std::move(id);
  blocks_.push_back(std::move(b));
}

void Document::details(std::string summary, std::string text) {
  Block b;
  b.kind = Block::Kind::details;
  b.summary = std::move(summary);
  b.text = std::move(text);
  blocks_.push_back(std::move(b));
}

void Document::text_only() {
  if (!blocks_.empty()) blocks_.back().text_only = true;
}

void Document::code(std::string text) {
  Block b;
  b.kind = Block::Kind::code;
  b.text = std::move(text);
  blocks_.push_back(std::move(b));
}

std::string Document::markdown_text(const std::string& figures_dir) const {
  std::ostringstream out;
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Block::Kind::heading:
        out << std::string(static_cast<std::size_t>(b.level), '#') << ' ' << b.text << "\n\n";
        break;
      case Block::Kind::paragraph:
        out << b.text << "\n\n";
        break;
      case Block::Kind::table: {
        out << '|';
        for (const auto& h : b.table.header) out << ' ' << markdown_cell(h) << " |";
        out << "\n|";
        for (std::size_t i = 0; i < b.table.header.size(); ++i) out << "---|";
        out << '\n';
        for (const auto& row : b.table.rows) {
          out << '|';
          for (const auto& c : row) out << ' ' << markdown_cell(c) << " |";
          out << '\n';
        }
        out << '\n';
        break;
      }
      case Block::Kind::figure:
        out << "![" << b.text << "](" << figures_dir << '/' << b.file_name << ")\n\n*" << b.text
            << "*\n\n";
        break;
      case Block::Kind::code: {
        std::istringstream lines(b.text);
        for (std::string line; std::getline(lines, line);) out << "    " << line << '\n';
        out << '\n';
        break;
      }
      case Block::Kind::slot:
        break;
      case Block::Kind::details:
        out << "<details><summary>" << escape_xml(b.summary) << "</summary>\n\n<pre>"
            << escape_xml(b.text) << "</pre>\n</details>\n\n";
        break;
    }
  }
  return out.str();
}

std::string block_html(const Block& b) {
  std::ostringstream out;
  switch (b.kind) {
    case Block::Kind::heading:
      out << "<h" << b.level << ">" << inline_html(b.text) << "</h" << b.level << ">\n";
      break;
    case Block::Kind::paragraph:
      out << "<p>" << inline_html(b.text) << "</p>\n";
      break;
    case Block::Kind::table:
      out << table_html(b.table);
      break;
    case Block::Kind::figure:
      out << "<figure>\n" << b.svg << "<figcaption>" << inline_html(b.text)
          << "</figcaption>\n</figure>\n";
      break;
    case Block::Kind::code:
      out << "<pre>" << escape_xml(b.text) << "</pre>\n";
      break;
    case Block::Kind::slot:
      break;
    case Block::Kind::details:
      out << "<details class=\"vv-failure\"><summary>" << inline_html(b.summary)
          << "</summary><p>" << escape_xml(b.text) << "</p></details>\n";
      break;
  }
  return out.str();
}

const char* document_style() { return kStyle; }

std::string Document::html_text(const std::string& title) const {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>"
      << escape_xml(title) << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n";
  for (const Block& b : blocks_) out << block_html(b);
  out << "</body>\n</html>\n";
  return out.str();
}

}  // namespace vessel::reports
