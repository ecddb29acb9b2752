// One self-contained HTML page for a command's result (--report FILE.html):
// inline CSS and inline SVG plots, no scripts, no network. A page reads top
// down: the headline (what was found, coloured by how good it is, and said
// in words so it survives greyscale), what to do next, the numbers with
// units and intervals in tables, warnings, then the plots.
#pragma once

#include <string>
#include <vector>

#include "report/xml_escape.hpp"

namespace umbmark::io {

class HtmlReport {
 public:
  /// `title`: e.g. "umbmark calibrate"; `subject`: what it ran on.
  HtmlReport(std::string title, std::string subject);

  enum class Level { kGood, kWarn, kBad, kInfo };
  /// The finding in one sentence, and its level.
  void Headline(const std::string& text, Level level);
  /// What to do next (an ordered list).
  void NextSteps(const std::vector<std::string>& steps);
  void Heading(const std::string& text);
  void Paragraph(const std::string& text);
  /// A table; cells are plain text (escaped). `numeric_from`: columns from
  /// this index on are right-aligned.
  void Table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
             std::size_t numeric_from = 1);
  void Warnings(const std::vector<std::string>& warnings);
  /// An inline SVG (as produced by io::SvgDocument) with a caption.
  void Figure(const std::string& svg, const std::string& caption);

  std::string Render() const;

 private:
  std::string title_, subject_;
  std::string body_;
};

/// Escapes &, <, >, quotes for HTML text and attributes (XmlEscape).
inline std::string HtmlEscape(const std::string& s) { return XmlEscape(s); }

}  // namespace umbmark::io
