// Self-contained HTML report pages (see html_report.hpp).
#include "report/html_report.hpp"

#include <fmt/format.h>

namespace umbmark::io {

HtmlReport::HtmlReport(std::string title, std::string subject) : title_(std::move(title)), subject_(std::move(subject)) {}

void HtmlReport::Headline(const std::string& text, Level level) {
  const char* cls = level == Level::kGood ? "good" : level == Level::kWarn ? "warn" : level == Level::kBad ? "bad" : "info";
  const char* word = level == Level::kGood ? "Result" : level == Level::kWarn ? "Attention" : level == Level::kBad ? "Problem" : "Result";
  body_ += fmt::format("<section class=\"headline {}\"><strong>{}:</strong> {}</section>\n", cls, word, XmlEscape(text));
}

void HtmlReport::NextSteps(const std::vector<std::string>& steps) {
  if (steps.empty()) return;
  body_ += "<section class=\"next\"><h2>What to do next</h2><ol>\n";
  for (const auto& s : steps) body_ += fmt::format("<li>{}</li>\n", XmlEscape(s));
  body_ += "</ol></section>\n";
}

void HtmlReport::Heading(const std::string& text) { body_ += fmt::format("<h2>{}</h2>\n", XmlEscape(text)); }

void HtmlReport::Paragraph(const std::string& text) { body_ += fmt::format("<p>{}</p>\n", XmlEscape(text)); }

void HtmlReport::Table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                       std::size_t numeric_from) {
  body_ += "<table class=\"numbers\"><thead><tr>";
  for (const auto& h : header) body_ += fmt::format("<th>{}</th>", XmlEscape(h));
  body_ += "</tr></thead><tbody>\n";
  for (const auto& row : rows) {
    body_ += "<tr>";
    for (std::size_t c = 0; c < row.size(); ++c)
      body_ += fmt::format("<td{}>{}</td>", c >= numeric_from ? " class=\"num\"" : "", XmlEscape(row[c]));
    body_ += "</tr>\n";
  }
  body_ += "</tbody></table>\n";
}

void HtmlReport::Warnings(const std::vector<std::string>& warnings) {
  if (warnings.empty()) return;
  body_ += "<section class=\"warnings\"><h2>Warnings</h2><ul>\n";
  for (const auto& w : warnings) body_ += fmt::format("<li>{}</li>\n", XmlEscape(w));
  body_ += "</ul></section>\n";
}

void HtmlReport::Figure(const std::string& svg, const std::string& caption) {
  body_ += fmt::format("<figure class=\"plot\">\n{}<figcaption>{}</figcaption></figure>\n", svg, XmlEscape(caption));
}

std::string HtmlReport::Render() const {
  constexpr const char* kCss = R"css(
body { font-family: "DejaVu Sans", Helvetica, Arial, sans-serif; color: #111; max-width: 1180px; margin: 24px auto; padding: 0 16px; line-height: 1.45; }
h1 { font-size: 1.5em; margin-bottom: 0; } .subject { color: #444; margin-top: 4px; font-family: monospace; word-break: break-all; }
h2 { font-size: 1.15em; margin-top: 1.6em; border-bottom: 1px solid #ccc; }
.headline { padding: 12px 16px; margin: 16px 0; border-left: 8px solid; font-size: 1.08em; }
.headline.good { border-color: #2b7a2b; background: #eef7ee; } .headline.warn { border-color: #b07800; background: #fff7e0; }
.headline.bad { border-color: #b02020; background: #fdecec; } .headline.info { border-color: #35608f; background: #eef3f9; }
table.numbers { border-collapse: collapse; margin: 8px 0; font-size: 0.95em; }
table.numbers th, table.numbers td { border: 1px solid #ccc; padding: 3px 9px; text-align: left; overflow-wrap: break-word; }
table.numbers th { background: #f0f0f0; } td.num { text-align: right; font-variant-numeric: tabular-nums; white-space: nowrap; }
.warnings { background: #fff7e0; padding: 4px 12px; }
figure.plot { margin: 18px 0; overflow-x: auto; } figure.plot svg { max-width: 100%; height: auto; }
figcaption { color: #333; font-size: 0.92em; margin-top: 4px; }
footer { color: #666; font-size: 0.85em; margin-top: 2em; }
)css";
  return fmt::format(
      "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
      "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{0} - {1}</title>\n"
      "<style>{2}</style>\n</head>\n<body>\n<h1>{0}</h1>\n<p class=\"subject\">{1}</p>\n{3}"
      "<footer>Written by umbmark. Units: SI unless a column says otherwise (mm, deg). Formats and keys: "
      "docs/formats.md.</footer>\n</body>\n</html>\n",
      XmlEscape(title_), XmlEscape(subject_), kCss, body_);
}

}  // namespace umbmark::io
