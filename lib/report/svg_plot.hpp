// The plotting layer of every picture umbmark draws (--plot SVG files and
// the plots inside --report HTML pages): panels with real axes (1-2-5 ticks,
// tick labels, grid, axis titles with units), legends that show each
// series' marker and dash (readable in greyscale, not colour alone), and
// data drawn as points, polylines, circles, covariance ellipses, bands and
// bars. Produces SVG text; the caller writes it (atomically). Elements carry
// classes and data-* attributes (ticks, legend entries, series) so tests can
// check what a plot shows by parsing it.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "report/xml_escape.hpp"

namespace umbmark::io {

struct SvgPoint {
  double x = 0.0, y = 0.0;
};

/// How a series looks: colour plus a marker and a dash pattern, so series
/// stay apart in greyscale. marker: "circle", "square", "triangle",
/// "diamond", "cross", "plus" or "" (none); dash: SVG dasharray or "".
struct SvgStyle {
  std::string color = "#222";
  std::string marker;
  std::string dash;
  double line_width = 1.5;
  bool filled = true;  ///< filled or hollow marker
};

/// Tick values at 1, 2 or 5 times a power of ten covering [lo, hi], about
/// `target` of them (at least 3 when lo < hi).
std::vector<double> NiceTicks(double lo, double hi, int target = 6);
/// A tick label with just the digits the tick step needs.
std::string TickLabel(double value, double step);

/// One panel: a data rectangle mapped onto a pixel rectangle.
class SvgPanel {
 public:
  /// Panel placed at pixel (left, top) with size (width, height).
  SvgPanel(double left, double top, double width, double height, std::string title);

  /// Data extent; equal_aspect keeps metres square on screen.
  void SetExtent(double xmin, double xmax, double ymin, double ymax, bool equal_aspect);
  /// Extent fitted to points (with 8% margin), containing the origin when
  /// include_origin.
  void FitExtent(const std::vector<SvgPoint>& pts, bool equal_aspect, bool include_origin);
  double xmin() const { return xmin_; }
  double xmax() const { return xmax_; }
  double ymin() const { return ymin_; }
  double ymax() const { return ymax_; }

  /// Markers at `pts`; `name` (optional) tags the series (data-name) for tests.
  void Points(const std::vector<SvgPoint>& pts, const SvgStyle& style, double radius_px = 3.5,
              const std::string& name = "");
  void Polyline(const std::vector<SvgPoint>& pts, const SvgStyle& style);
  void Circle(SvgPoint centre, double radius_data, const SvgStyle& style);
  /// Ellipse from a 2x2 covariance scaled to `scale` sigma (e.g. 2.4477 for 95%).
  void CovarianceEllipse(SvgPoint centre, double cxx, double cxy, double cyy, double scale, const SvgStyle& style);
  /// A shaded band between lo(x) and hi(x) (same x for both).
  void Band(const std::vector<SvgPoint>& lo, const std::vector<SvgPoint>& hi, const std::string& color,
            double opacity = 0.18);
  /// Horizontal or vertical reference line across the panel.
  void HLine(double y, const SvgStyle& style);
  void VLine(double x, const SvgStyle& style);
  /// Text at a data point (clipped to the panel).
  void Text(SvgPoint at, const std::string& text, const std::string& color = "#222", double size_px = 11.0);
  /// Ticks, tick labels, grid and axis titles (give units: "e_x [mm]").
  void Axes(const std::string& xlabel, const std::string& ylabel);
  /// Legend below the panel: one row per entry with its marker and dash.
  void Legend(const std::vector<std::pair<SvgStyle, std::string>>& entries);

  /// Lowest pixel row used (legend included), to size the document.
  double Bottom() const { return bottom_; }
  std::string Render() const;

 private:
  double Px(double x) const;
  double Py(double y) const;
  std::string Marker(double x, double y, const SvgStyle& style, double r) const;
  double left_, top_, width_, height_;
  double xmin_ = -1, xmax_ = 1, ymin_ = -1, ymax_ = 1;
  double bottom_;
  std::string title_;
  std::string grid_;   // under the data
  std::string body_;   // clipped to the panel
  std::string frame_;  // ticks, labels, legend: outside the clip
};

/// Horizontal bars, one group per label, one bar per series (legend below).
/// `value_label` names the quantity and unit of the bar length; the axis
/// starts at 0, or at the smallest value when some are negative.
std::string SvgBarChart(const std::string& title, const std::vector<std::string>& labels,
                        const std::vector<std::vector<double>>& series, const std::vector<std::string>& series_names,
                        const std::vector<std::string>& colors, const std::string& value_label = "");

/// Wraps panels into a document of the given pixel size.
std::string SvgDocument(double width, double height, const std::vector<std::string>& parts);

/// Escapes &, <, > and quotes for SVG text (XmlEscape).
inline std::string SvgEscape(const std::string& s) { return XmlEscape(s); }

}  // namespace umbmark::io
