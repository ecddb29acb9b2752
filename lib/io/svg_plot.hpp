// A small SVG plot builder for the commands' --plot outputs: panels with
// equal-aspect or free data axes, points, polylines, circles, ellipses,
// bars and text. Produces a string; the caller writes it (atomically).
#pragma once

#include <string>
#include <vector>

namespace umbmark::io {

struct SvgPoint {
  double x = 0.0, y = 0.0;
};

/// One panel: a data rectangle mapped onto a pixel rectangle.
class SvgPanel {
 public:
  /// Panel placed at pixel (left, top) with size (width, height).
  SvgPanel(double left, double top, double width, double height, std::string title);

  /// Data extent; equal_aspect keeps metres square on screen.
  void SetExtent(double xmin, double xmax, double ymin, double ymax, bool equal_aspect);
  /// Extent fitted to points (with 10% margin), always containing the origin
  /// when include_origin.
  void FitExtent(const std::vector<SvgPoint>& pts, bool equal_aspect, bool include_origin);

  void Points(const std::vector<SvgPoint>& pts, const std::string& color, double radius_px = 3.0,
              const std::string& shape = "circle");
  void Polyline(const std::vector<SvgPoint>& pts, const std::string& color, double width_px = 1.5,
                const std::string& dash = "");
  void Circle(SvgPoint centre, double radius_data, const std::string& color, const std::string& dash = "");
  /// Ellipse from a 2x2 covariance scaled to `scale` sigma (e.g. 2.4477 for 95%).
  void CovarianceEllipse(SvgPoint centre, double cxx, double cxy, double cyy, double scale, const std::string& color,
                         const std::string& dash = "");
  void Text(SvgPoint at, const std::string& text, const std::string& color = "#222", double size_px = 11.0);
  void Legend(const std::vector<std::pair<std::string, std::string>>& entries);  // (color, label)
  void Axes(const std::string& xlabel, const std::string& ylabel);

  std::string Render() const;

 private:
  double Px(double x) const;
  double Py(double y) const;
  double left_, top_, width_, height_;
  double xmin_ = -1, xmax_ = 1, ymin_ = -1, ymax_ = 1;
  std::string title_;
  std::string body_;   // clipped to the panel
  std::string frame_;  // axis labels, outside the clip
};

/// Horizontal bar chart rows (label, values per series), for gap-per-statistic plots.
std::string SvgBarChart(const std::string& title, const std::vector<std::string>& labels,
                        const std::vector<std::vector<double>>& series, const std::vector<std::string>& series_names,
                        const std::vector<std::string>& colors);

/// Wraps panels into a document of the given pixel size.
std::string SvgDocument(double width, double height, const std::vector<std::string>& parts);

/// Escapes &, <, > and quotes for SVG text.
std::string SvgEscape(const std::string& s);

}  // namespace umbmark::io
