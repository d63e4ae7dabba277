#pragma once
/// A report as a list of blocks, rendered once as Markdown (figures as linked .svg files) and once
/// as a self-contained HTML page (figures inlined), so both say the same thing.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "reports/svg_plot.hpp"

namespace vessel::reports {

/// `v` with `digits` significant digits (shortest form: 0.0131, 1.5e-05), as report tables show
/// numbers.
std::string significant(double v, int digits = 3);
/// `v` with `digits` digits after the point (0.441, 19.750), for columns read down a table.
std::string decimals(double v, int digits);
/// `text` fit for a Markdown table's cell: its bars escaped, its line breaks spaces.
std::string markdown_cell(const std::string& text);

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
};

struct Block {
  /// slot: a place report.html fills with something interactive ("cards", "view:<scene>");
  /// Markdown and the page without scripts leave it out.
  enum class Kind { heading, paragraph, table, figure, code, slot, details };
  Kind kind = Kind::paragraph;
  int level = 2;          ///< heading level
  std::string summary;    ///< details: the line shown folded (its text: the body)
  std::string text;       ///< heading or paragraph (inline Markdown: `code`, **bold**, *italic*),
                          ///< caption, or a preformatted line (kind code, e.g. a command)
  Table table;
  std::string svg;        ///< figure
  std::string file_name;  ///< figure: its .svg file beside the Markdown report
  std::optional<Plot> plot;  ///< figure: the data the SVG draws, for report.html's plots
  /// Shown in Markdown and the page without scripts; report.html with its libraries shows the
  /// slot that says the same instead.
  bool text_only = false;
};

class Document {
 public:
  void heading(int level, std::string text);
  void paragraph(std::string text);
  void table(Table table);
  void figure(std::string file_name, std::string svg, std::string caption);
  /// A figure with the plot it draws (rendered as SVG here).
  void figure(std::string file_name, const Plot& plot, std::string caption);
  void slot(std::string id);
  /// A folded block: `summary` shown, `text` (preformatted) on demand; in Markdown an HTML
  /// <details> element, which Markdown viewers fold too.
  void details(std::string summary, std::string text);
  /// Marks the last block as text_only.
  void text_only();
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

/// One block as HTML (a slot: nothing), as html_text writes it.
std::string block_html(const Block& block);

/// The report's stylesheet.
const char* document_style();

/// Inline Markdown (`code`, **bold**, *italic*) of escaped text as HTML.
std::string inline_html(const std::string& markdown);

}  // namespace vessel::reports
