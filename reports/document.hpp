#pragma once
/// A report as a list of blocks, rendered once as Markdown (figures as linked .svg files) and once
/// as a self-contained HTML page (figures inlined), so both say the same thing.
#include <filesystem>
#include <string>
#include <vector>

namespace vessel::reports {

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct Block {
  enum class Kind { heading, paragraph, table, figure, markdown };
  Kind kind = Kind::paragraph;
  int level = 2;          ///< heading level
  std::string text;       ///< heading or paragraph (inline Markdown: `code`, **bold**), caption,
                          ///< or a Markdown section (kind markdown)
  Table table;
  std::string svg;        ///< figure
  std::string file_name;  ///< figure: its .svg file beside the Markdown report
};

class Document {
 public:
  void heading(int level, std::string text);
  void paragraph(std::string text);
  void table(Table table);
  void figure(std::string file_name, std::string svg, std::string caption);
  /// A Markdown section written elsewhere (e.g. stability.md), embedded as it is.
  void markdown(std::string text);

  /// Markdown; figures are referenced as `figures_dir/<file_name>`.
  [[nodiscard]] std::string markdown_text(const std::string& figures_dir) const;
  /// A complete HTML page with inline SVG and a small stylesheet.
  [[nodiscard]] std::string html_text(const std::string& title) const;
  [[nodiscard]] const std::vector<Block>& blocks() const { return blocks_; }

 private:
  std::vector<Block> blocks_;
};

/// Inline Markdown (`code`, **bold**, *italic*) of escaped text as HTML.
std::string inline_html(const std::string& markdown);
/// A Markdown section (headings, paragraphs, pipe tables, "- " lists, fenced or indented code)
/// as HTML: enough for the sections this project writes itself.
std::string markdown_to_html(const std::string& markdown);

}  // namespace vessel::reports
