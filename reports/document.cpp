#include "reports/document.hpp"

#include <sstream>

#include "reports/svg_plot.hpp"

namespace vessel::reports {

namespace {

std::string cell_md(const std::string& s) {
  std::string out;
  for (const char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
  return out;
}

std::vector<std::string> split_row(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::string body = line;
  if (!body.empty() && body.front() == '|') body.erase(0, 1);
  if (!body.empty() && body.back() == '|') body.pop_back();
  for (std::size_t i = 0; i < body.size(); ++i) {
    if (body[i] == '\\' && i + 1 < body.size() && body[i + 1] == '|') {
      cell += '|';
      ++i;
    } else if (body[i] == '|') {
      cells.push_back(cell);
      cell.clear();
    } else {
      cell += body[i];
    }
  }
  cells.push_back(cell);
  for (auto& c : cells) {
    const auto a = c.find_first_not_of(' ');
    const auto b = c.find_last_not_of(' ');
    c = a == std::string::npos ? "" : c.substr(a, b - a + 1);
  }
  return cells;
}

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

std::string markdown_to_html(const std::string& md) {
  std::istringstream in(md);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  std::ostringstream out;
  std::string paragraph;
  const auto flush = [&] {
    if (!paragraph.empty()) out << "<p>" << inline_html(paragraph) << "</p>\n";
    paragraph.clear();
  };
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& line = lines[i];
    if (line.empty()) {
      flush();
    } else if (line.rfind("```", 0) == 0) {
      flush();
      out << "<pre>";
      for (++i; i < lines.size() && lines[i].rfind("```", 0) != 0; ++i) {
        out << escape_xml(lines[i]) << "\n";
      }
      out << "</pre>\n";
    } else if (line.rfind("    ", 0) == 0 && paragraph.empty()) {
      out << "<pre>";
      for (; i < lines.size() && lines[i].rfind("    ", 0) == 0; ++i) {
        out << escape_xml(lines[i].substr(4)) << "\n";
      }
      --i;
      out << "</pre>\n";
    } else if (line[0] == '#') {
      flush();
      std::size_t level = line.find_first_not_of('#');
      const std::string text = line.substr(std::min(line.size(), level + 1));
      out << "<h" << level << ">" << inline_html(text) << "</h" << level << ">\n";
    } else if (line[0] == '|') {
      flush();
      Table t;
      t.header = split_row(line);
      i += 2;  // the header and the |---| line
      for (; i < lines.size() && !lines[i].empty() && lines[i][0] == '|'; ++i) {
        t.rows.push_back(split_row(lines[i]));
      }
      --i;
      out << table_html(t);
    } else if (line.rfind("- ", 0) == 0) {
      flush();
      out << "<ul>\n";
      for (; i < lines.size() && lines[i].rfind("- ", 0) == 0; ++i) {
        std::string item = lines[i].substr(2);
        while (i + 1 < lines.size() && lines[i + 1].rfind("  ", 0) == 0) item += " " + lines[++i];
        out << "<li>" << inline_html(item) << "</li>\n";
      }
      --i;
      out << "</ul>\n";
    } else {
      paragraph += (paragraph.empty() ? "" : " ") + line;
    }
  }
  flush();
  return out.str();
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

void Document::markdown(std::string text) {
  Block b;
  b.kind = Block::Kind::markdown;
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
        for (const auto& h : b.table.header) out << ' ' << cell_md(h) << " |";
        out << "\n|";
        for (std::size_t i = 0; i < b.table.header.size(); ++i) out << "---|";
        out << '\n';
        for (const auto& row : b.table.rows) {
          out << '|';
          for (const auto& c : row) out << ' ' << cell_md(c) << " |";
          out << '\n';
        }
        out << '\n';
        break;
      }
      case Block::Kind::figure:
        out << "![" << b.text << "](" << figures_dir << '/' << b.file_name << ")\n\n*" << b.text
            << "*\n\n";
        break;
      case Block::Kind::markdown:
        out << b.text << (b.text.ends_with("\n") ? "\n" : "\n\n");
        break;
    }
  }
  return out.str();
}

std::string Document::html_text(const std::string& title) const {
  std::ostringstream out;
  out << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>"
      << escape_xml(title) << "</title>\n<style>" << kStyle << "</style>\n</head>\n<body>\n";
  for (const Block& b : blocks_) {
    switch (b.kind) {
      case Block::Kind::heading:
        out << "<h" << b.level << ">" << inline_html(b.text) << "</h" << b.level << ">\n";
        break;
      case Block::Kind::paragraph:
        out << markdown_to_html(b.text);
        break;
      case Block::Kind::table:
        out << table_html(b.table);
        break;
      case Block::Kind::figure:
        out << "<figure>\n" << b.svg << "<figcaption>" << inline_html(b.text)
            << "</figcaption>\n</figure>\n";
        break;
      case Block::Kind::markdown:
        out << markdown_to_html(b.text);
        break;
    }
  }
  out << "</body>\n</html>\n";
  return out.str();
}

}  // namespace vessel::reports
