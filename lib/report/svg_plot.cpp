// SVG plotting layer (see svg_plot.hpp).
#include "report/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>

namespace umbmark::io {

namespace {
std::string DashAttr(const std::string& dash) {
  return dash.empty() ? "" : fmt::format(R"svg( stroke-dasharray="{}")svg", dash);
}
double TickStep(double lo, double hi, int target) {
  // The 1-2-5 step nearest (in ratio) to range / target.
  const double raw = (hi - lo) / std::max(target, 1);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  double best = p;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (std::abs(std::log(m * p / raw)) < std::abs(std::log(best / raw))) best = m * p;
  return best;
}
}  // namespace

std::vector<double> NiceTicks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo)) return {};
  // A narrow range can fall between two round values: refine until at
  // least three ticks label it.
  std::vector<double> ticks;
  for (int t = std::max(target, 1); ticks.size() < 3 && t <= 64; t *= 2) {
    const double step = TickStep(lo, hi, t);
    ticks.clear();
    for (double k = std::ceil(lo / step - 1e-9); k * step <= hi + 1e-9 * step; k += 1.0) {
      const double v = k * step;
      ticks.push_back(std::abs(v) < 1e-12 * step ? 0.0 : v);
    }
  }
  return ticks;
}

std::string TickLabel(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::abs(value) >= 1e6 || (value != 0.0 && std::abs(value) < 1e-4 && decimals > 6))
    return fmt::format("{:.2g}", value);
  return fmt::format("{:.{}f}", value, decimals);
}

SvgPanel::SvgPanel(double left, double top, double width, double height, std::string title)
    : left_(left), top_(top), width_(width), height_(height), bottom_(top + height + 40), title_(std::move(title)) {}

void SvgPanel::SetExtent(double xmin, double xmax, double ymin, double ymax, bool equal_aspect) {
  if (!(xmax > xmin)) { xmin -= 1e-3; xmax += 1e-3; }
  if (!(ymax > ymin)) { ymin -= 1e-3; ymax += 1e-3; }
  if (equal_aspect) {
    const double sx = (xmax - xmin) / width_, sy = (ymax - ymin) / height_;
    const double s = std::max(sx, sy);
    const double cx = 0.5 * (xmin + xmax), cy = 0.5 * (ymin + ymax);
    xmin = cx - 0.5 * s * width_;
    xmax = cx + 0.5 * s * width_;
    ymin = cy - 0.5 * s * height_;
    ymax = cy + 0.5 * s * height_;
  }
  xmin_ = xmin; xmax_ = xmax; ymin_ = ymin; ymax_ = ymax;
}

void SvgPanel::FitExtent(const std::vector<SvgPoint>& pts, bool equal_aspect, bool include_origin) {
  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  auto add = [&](double x, double y) {
    if (!std::isfinite(x) || !std::isfinite(y)) return;
    xmin = std::min(xmin, x); xmax = std::max(xmax, x);
    ymin = std::min(ymin, y); ymax = std::max(ymax, y);
  };
  for (const auto& p : pts) add(p.x, p.y);
  if (include_origin || !std::isfinite(xmin)) add(0.0, 0.0);
  const double mx = 0.08 * std::max(xmax - xmin, 1e-6), my = 0.08 * std::max(ymax - ymin, 1e-6);
  SetExtent(xmin - mx, xmax + mx, ymin - my, ymax + my, equal_aspect);
}

double SvgPanel::Px(double x) const { return left_ + (x - xmin_) / (xmax_ - xmin_) * width_; }
double SvgPanel::Py(double y) const { return top_ + height_ - (y - ymin_) / (ymax_ - ymin_) * height_; }

std::string SvgPanel::Marker(double x, double y, const SvgStyle& st, double r) const {
  const std::string paint = st.filled ? fmt::format(R"svg(fill="{0}" stroke="{0}")svg", st.color)
                                      : fmt::format(R"svg(fill="white" stroke="{}" stroke-width="1.5")svg", st.color);
  if (st.marker == "square")
    return fmt::format(R"svg(<rect x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" {}/>)svg", x - r, y - r, 2 * r,
                       2 * r, paint);
  if (st.marker == "triangle")
    return fmt::format(R"svg(<path d="M{:.1f},{:.1f}L{:.1f},{:.1f}L{:.1f},{:.1f}Z" {}/>)svg", x, y - 1.2 * r, x + 1.1 * r,
                       y + 0.8 * r, x - 1.1 * r, y + 0.8 * r, paint);
  if (st.marker == "diamond")
    return fmt::format(R"svg(<path d="M{:.1f},{:.1f}L{:.1f},{:.1f}L{:.1f},{:.1f}L{:.1f},{:.1f}Z" {}/>)svg", x, y - 1.3 * r,
                       x + 1.3 * r, y, x, y + 1.3 * r, x - 1.3 * r, y, paint);
  if (st.marker == "cross")
    return fmt::format(R"svg(<path d="M{:.1f},{:.1f}L{:.1f},{:.1f}M{:.1f},{:.1f}L{:.1f},{:.1f}" stroke="{}" stroke-width="2"/>)svg",
                       x - r, y - r, x + r, y + r, x - r, y + r, x + r, y - r, st.color);
  if (st.marker == "plus")
    return fmt::format(R"svg(<path d="M{:.1f},{:.1f}L{:.1f},{:.1f}M{:.1f},{:.1f}L{:.1f},{:.1f}" stroke="{}" stroke-width="2.5"/>)svg",
                       x - 1.4 * r, y, x + 1.4 * r, y, x, y - 1.4 * r, x, y + 1.4 * r, st.color);
  return fmt::format(R"svg(<circle cx="{:.1f}" cy="{:.1f}" r="{:.1f}" {}/>)svg", x, y, r, paint);
}

void SvgPanel::Points(const std::vector<SvgPoint>& pts, const SvgStyle& style, double r, const std::string& name) {
  SvgStyle st = style;
  if (st.marker.empty()) st.marker = "circle";
  body_ += fmt::format(R"svg(<g class="series points" data-n="{}"{}>)svg", pts.size(),
                       name.empty() ? std::string() : fmt::format(R"svg( data-name="{}")svg", XmlEscape(name)));
  for (const auto& p : pts) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    body_ += Marker(Px(p.x), Py(p.y), st, r);
  }
  body_ += "</g>\n";
}

void SvgPanel::Polyline(const std::vector<SvgPoint>& pts, const SvgStyle& st) {
  std::string d;
  for (const auto& p : pts) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    d += fmt::format("{:.1f},{:.1f} ", Px(p.x), Py(p.y));
  }
  body_ += fmt::format(R"svg(<polyline class="series line" points="{}" fill="none" stroke="{}" stroke-width="{}"{}/>)svg",
                       d, st.color, st.line_width, DashAttr(st.dash));
  body_ += "\n";
}

void SvgPanel::Circle(SvgPoint c, double radius, const SvgStyle& st) {
  const double rx = radius / (xmax_ - xmin_) * width_, ry = radius / (ymax_ - ymin_) * height_;
  body_ += fmt::format(
      R"svg(<ellipse class="series circle" cx="{:.1f}" cy="{:.1f}" rx="{:.1f}" ry="{:.1f}" fill="none" stroke="{}" stroke-width="{}"{}/>)svg",
      Px(c.x), Py(c.y), rx, ry, st.color, st.line_width, DashAttr(st.dash));
  body_ += "\n";
}

void SvgPanel::CovarianceEllipse(SvgPoint c, double cxx, double cxy, double cyy, double scale, const SvgStyle& st) {
  // Eigen-decomposition of the symmetric 2x2 covariance.
  const double tr = cxx + cyy, det = cxx * cyy - cxy * cxy;
  const double disc = std::sqrt(std::max(0.0, tr * tr / 4.0 - det));
  const double l1 = std::max(0.0, tr / 2.0 + disc), l2 = std::max(0.0, tr / 2.0 - disc);
  const double angle = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
  std::vector<SvgPoint> pts;
  for (int k = 0; k <= 72; ++k) {
    const double t = 2.0 * std::numbers::pi * k / 72.0;
    const double u = scale * std::sqrt(l1) * std::cos(t), v = scale * std::sqrt(l2) * std::sin(t);
    pts.push_back({c.x + u * std::cos(angle) - v * std::sin(angle), c.y + u * std::sin(angle) + v * std::cos(angle)});
  }
  Polyline(pts, st);
}

void SvgPanel::Band(const std::vector<SvgPoint>& lo, const std::vector<SvgPoint>& hi, const std::string& color,
                    double opacity) {
  std::string d;
  for (const auto& p : lo)
    if (std::isfinite(p.x) && std::isfinite(p.y)) d += fmt::format("{:.1f},{:.1f} ", Px(p.x), Py(p.y));
  for (auto it = hi.rbegin(); it != hi.rend(); ++it)
    if (std::isfinite(it->x) && std::isfinite(it->y)) d += fmt::format("{:.1f},{:.1f} ", Px(it->x), Py(it->y));
  body_ += fmt::format(R"svg(<polygon class="series band" points="{}" fill="{}" fill-opacity="{}" stroke="none"/>)svg", d,
                       color, opacity);
  body_ += "\n";
}

void SvgPanel::HLine(double y, const SvgStyle& st) { Polyline({{xmin_, y}, {xmax_, y}}, st); }
void SvgPanel::VLine(double x, const SvgStyle& st) { Polyline({{x, ymin_}, {x, ymax_}}, st); }

void SvgPanel::Text(SvgPoint at, const std::string& text, const std::string& color, double size) {
  body_ += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="{}" fill="{}">{}</text>)svg", Px(at.x), Py(at.y),
                       size, color, XmlEscape(text));
  body_ += "\n";
}

void SvgPanel::Axes(const std::string& xlabel, const std::string& ylabel) {
  const auto xt = NiceTicks(xmin_, xmax_, std::max(3, static_cast<int>(width_ / 80)));
  const auto yt = NiceTicks(ymin_, ymax_, std::max(3, static_cast<int>(height_ / 60)));
  const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1.0, ystep = yt.size() > 1 ? yt[1] - yt[0] : 1.0;
  const double bottom = top_ + height_;
  for (double v : xt) {
    const double x = Px(v);
    grid_ += fmt::format(R"svg(<line x1="{0:.1f}" y1="{1:.1f}" x2="{0:.1f}" y2="{2:.1f}" stroke="{3}"/>)svg", x, top_,
                         bottom, v == 0.0 ? "#999" : "#e4e4e4");
    frame_ += fmt::format(
        R"svg(<g class="tick x" data-value="{4:.10g}"><line x1="{0:.1f}" y1="{1:.1f}" x2="{0:.1f}" y2="{2:.1f}" stroke="#333"/><text x="{0:.1f}" y="{3:.1f}" font-size="11" text-anchor="middle" fill="#333">{5}</text></g>)svg",
        x, bottom, bottom + 5, bottom + 17, v, TickLabel(v, xstep));
  }
  for (double v : yt) {
    const double y = Py(v);
    grid_ += fmt::format(R"svg(<line x1="{1:.1f}" y1="{0:.1f}" x2="{2:.1f}" y2="{0:.1f}" stroke="{3}"/>)svg", y, left_,
                         left_ + width_, v == 0.0 ? "#999" : "#e4e4e4");
    frame_ += fmt::format(
        R"svg(<g class="tick y" data-value="{4:.10g}"><line x1="{1:.1f}" y1="{0:.1f}" x2="{2:.1f}" y2="{0:.1f}" stroke="#333"/><text x="{3:.1f}" y="{5:.1f}" font-size="11" text-anchor="end" fill="#333">{6}</text></g>)svg",
        y, left_ - 5, left_, left_ - 8, v, y + 4, TickLabel(v, ystep));
  }
  frame_ += fmt::format(R"svg(<text class="axis-label x" x="{:.1f}" y="{:.1f}" font-size="12" text-anchor="middle" fill="#111">{}</text>)svg",
                        left_ + width_ / 2, bottom + 34, XmlEscape(xlabel));
  const double ly = top_ + height_ / 2, lx = left_ - 46;
  frame_ += fmt::format(
      R"svg(<text class="axis-label y" x="{0:.1f}" y="{1:.1f}" font-size="12" text-anchor="middle" fill="#111" transform="rotate(-90 {0:.1f} {1:.1f})">{2}</text>)svg",
      lx, ly, XmlEscape(ylabel));
  frame_ += "\n";
  bottom_ = std::max(bottom_, bottom + 40);
}

void SvgPanel::Legend(const std::vector<std::pair<SvgStyle, std::string>>& entries) {
  double y = bottom_ + 6;
  for (const auto& [st, label] : entries) {
    const double x = left_;
    frame_ += fmt::format(R"svg(<g class="legend-entry" data-label="{}">)svg", XmlEscape(label));
    if (st.marker.empty() || !st.dash.empty() || st.marker == "line")
      frame_ += fmt::format(R"svg(<line x1="{:.1f}" y1="{:.1f}" x2="{:.1f}" y2="{:.1f}" stroke="{}" stroke-width="{}"{}/>)svg",
                            x, y, x + 28, y, st.color, std::max(st.line_width, 1.5), DashAttr(st.dash));
    if (!st.marker.empty() && st.marker != "line") frame_ += Marker(x + 14, y, st, 4.0);
    frame_ += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="11" fill="#222">{}</text></g>)svg", x + 36, y + 4,
                          XmlEscape(label));
    frame_ += "\n";
    y += 16;
  }
  bottom_ = y;
}

std::string SvgPanel::Render() const {
  std::string out = fmt::format(
      R"svg(<g class="panel" data-title="{6}"><rect x="{0:.1f}" y="{1:.1f}" width="{2:.1f}" height="{3:.1f}" fill="white" stroke="none"/>)svg"
      R"svg(<text class="panel-title" x="{0:.1f}" y="{4:.1f}" font-size="13" font-weight="bold" fill="#111">{5}</text>)svg"
      "\n",
      left_, top_, width_, height_, top_ - 8, XmlEscape(title_), XmlEscape(title_));
  out += grid_;
  out += fmt::format(R"svg(<svg x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" viewBox="{:.1f} {:.1f} {:.1f} {:.1f}" overflow="hidden">)svg",
                     left_, top_, width_, height_, left_, top_, width_, height_);
  out += "\n" + body_ + "</svg>\n";
  out += fmt::format(R"svg(<rect x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="none" stroke="#555"/>)svg", left_,
                     top_, width_, height_);
  out += frame_ + "</g>\n";
  return out;
}

// Bars grow from the axis origin; one tick axis below the last group; each
// bar's value is printed at its end.
std::string SvgBarChart(const std::string& title, const std::vector<std::string>& labels,
                        const std::vector<std::vector<double>>& series, const std::vector<std::string>& series_names,
                        const std::vector<std::string>& colors, const std::string& value_label) {
  const double left = 240, top = 44, bar_h = 12, width = 420;
  double vmax = 0.0, vmin = 0.0;
  for (const auto& s : series)
    for (double v : s)
      if (std::isfinite(v)) { vmax = std::max(vmax, v); vmin = std::min(vmin, v); }
  if (!(vmax > vmin)) vmax = vmin + 1.0;
  const auto ticks = NiceTicks(vmin, vmax, 5);
  const double lo = std::min(vmin, ticks.empty() ? vmin : ticks.front());
  const double hi = std::max(vmax, ticks.empty() ? vmax : ticks.back());
  auto X = [&](double v) { return left + (v - lo) / (hi - lo) * width; };
  std::string out = fmt::format(R"svg(<g class="panel bars" data-title="{0}"><text class="panel-title" x="10" y="22" font-size="13" font-weight="bold">{0}</text>)svg",
                                XmlEscape(title));
  out += "\n";
  const double group_h = bar_h * static_cast<double>(series.size()) + 10;
  const double bottom = top + group_h * static_cast<double>(labels.size());
  const double step = ticks.size() > 1 ? ticks[1] - ticks[0] : 1.0;
  for (double v : ticks) {
    out += fmt::format(
        R"svg(<g class="tick x" data-value="{3:.10g}"><line x1="{0:.1f}" y1="{1:.1f}" x2="{0:.1f}" y2="{2:.1f}" stroke="{5}"/><text x="{0:.1f}" y="{4:.1f}" font-size="11" text-anchor="middle">{6}</text></g>)svg",
        X(v), top - 4, bottom, v, bottom + 14, v == 0.0 ? "#777" : "#e4e4e4", TickLabel(v, step));
  }
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const double y0 = top + group_h * static_cast<double>(i);
    out += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="end">{}</text>)svg", left - 8,
                       y0 + bar_h * static_cast<double>(series.size()) / 2 + 4, XmlEscape(labels[i]));
    for (std::size_t s = 0; s < series.size(); ++s) {
      const double v = i < series[s].size() ? series[s][i] : 0.0;
      if (!std::isfinite(v)) continue;
      const double x0 = X(std::min(0.0, v)), x1 = X(std::max(0.0, v));
      // Series differ by fill pattern as well as colour: solid, hatched, hollow.
      const std::string fill = s % 3 == 0 ? colors[s % colors.size()] : s % 3 == 1 ? "url(#hatch)" : "white";
      out += fmt::format(R"svg(<rect class="bar" data-series="{}" data-value="{:.6g}" x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="{}" stroke="{}"/>)svg",
                         XmlEscape(series_names[s]), v, x0, y0 + bar_h * static_cast<double>(s), std::max(x1 - x0, 0.5),
                         bar_h - 2, fill, colors[s % colors.size()]);
      out += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="10">{:.3g}</text>)svg", x1 + 4,
                         y0 + bar_h * static_cast<double>(s) + bar_h - 3, v);
    }
    out += "\n";
  }
  out += fmt::format(R"svg(<text class="axis-label x" x="{:.1f}" y="{:.1f}" font-size="12" text-anchor="middle">{}</text>)svg",
                     left + width / 2, bottom + 32, XmlEscape(value_label));
  double ly = bottom + 50;
  for (std::size_t s = 0; s < series_names.size(); ++s) {
    const std::string fill = s % 3 == 0 ? colors[s % colors.size()] : s % 3 == 1 ? "url(#hatch)" : "white";
    out += fmt::format(R"svg(<g class="legend-entry" data-label="{3}"><rect x="{0:.1f}" y="{1:.1f}" width="14" height="10" fill="{4}" stroke="{2}"/><text x="{5:.1f}" y="{6:.1f}" font-size="11">{3}</text></g>)svg",
                       left, ly, colors[s % colors.size()], XmlEscape(series_names[s]), fill, left + 20, ly + 9);
    out += "\n";
    ly += 16;
  }
  return out + "</g>\n";
}

std::string SvgDocument(double width, double height, const std::vector<std::string>& parts) {
  std::string out = fmt::format(
      R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="{0:.0f}" height="{1:.0f}" viewBox="0 0 {0:.0f} {1:.0f}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif">)svg"
      "\n"
      R"svg(<defs><pattern id="hatch" width="6" height="6" patternUnits="userSpaceOnUse" patternTransform="rotate(45)"><rect width="6" height="6" fill="white"/><line x1="0" y1="0" x2="0" y2="6" stroke="#444" stroke-width="2"/></pattern></defs>)svg"
      "\n"
      R"svg(<rect width="100%" height="100%" fill="#ffffff"/>)svg"
      "\n",
      width, height);
  for (const auto& p : parts) out += p;
  return out + "</svg>\n";
}

}  // namespace umbmark::io
