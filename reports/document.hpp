#pragma once
/// A report as a list of blocks, rendered once as Markdown (figures as linked .svg files) and once
/// as a self-contained HTML page (figures inlined), so both say the same thing.
#include <filesystem>
#include <string>
#include <vector>

namespace vessel::reports {

/// `v` with `digits` significant digits (shortest form: 0.0131, 1.5e-05), as report tables show
/// numbers.
std::string significant(double v, int digits = 3);

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct Block {
  enum class Kind { heading, paragraph, table, figure, code };
  Kind kind = Kind::paragraph;
  int level = 2;          ///< heading level
  std::string text;       ///< heading or paragraph (inline Markdown: `code`, **bold**, *italic*),
                          ///< caption, or a preformatted line (kind code, e.g. a command)
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
  /// Preformatted text shown as it is (a command line): indented in Markdown, <pre> in HTML.
  void code(std::string text);

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

}  // namespace vessel::reports
