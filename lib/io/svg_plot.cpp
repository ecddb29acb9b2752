// SVG plot builder (see svg_plot.hpp).
#include "io/svg_plot.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace umbmark::io {

std::string SvgEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

SvgPanel::SvgPanel(double left, double top, double width, double height, std::string title)
    : left_(left), top_(top), width_(width), height_(height), title_(std::move(title)) {}

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
  const double mx = 0.1 * std::max(xmax - xmin, 1e-6), my = 0.1 * std::max(ymax - ymin, 1e-6);
  SetExtent(xmin - mx, xmax + mx, ymin - my, ymax + my, equal_aspect);
}

double SvgPanel::Px(double x) const { return left_ + (x - xmin_) / (xmax_ - xmin_) * width_; }
double SvgPanel::Py(double y) const { return top_ + height_ - (y - ymin_) / (ymax_ - ymin_) * height_; }

void SvgPanel::Points(const std::vector<SvgPoint>& pts, const std::string& color, double r,
                      const std::string& shape) {
  for (const auto& p : pts) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    const double x = Px(p.x), y = Py(p.y);
    if (shape == "cross") {
      body_ += fmt::format(R"svg(<path d="M{:.1f},{:.1f}L{:.1f},{:.1f}M{:.1f},{:.1f}L{:.1f},{:.1f}" stroke="{}" stroke-width="2"/>)svg",
                           x - r, y - r, x + r, y + r, x - r, y + r, x + r, y - r, color);
    } else {
      body_ += fmt::format(R"svg(<circle cx="{:.1f}" cy="{:.1f}" r="{:.1f}" fill="{}" fill-opacity="0.75"/>)svg", x, y, r, color);
    }
    body_ += "\n";
  }
}

void SvgPanel::Polyline(const std::vector<SvgPoint>& pts, const std::string& color, double w,
                        const std::string& dash) {
  std::string d;
  for (const auto& p : pts) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
    d += fmt::format("{:.1f},{:.1f} ", Px(p.x), Py(p.y));
  }
  body_ += fmt::format(R"svg(<polyline points="{}" fill="none" stroke="{}" stroke-width="{}"{}/>)svg", d, color, w,
                       dash.empty() ? "" : fmt::format(R"svg( stroke-dasharray="{}")svg", dash));
  body_ += "\n";
}

void SvgPanel::Circle(SvgPoint c, double radius, const std::string& color, const std::string& dash) {
  const double rx = radius / (xmax_ - xmin_) * width_, ry = radius / (ymax_ - ymin_) * height_;
  body_ += fmt::format(R"svg(<ellipse cx="{:.1f}" cy="{:.1f}" rx="{:.1f}" ry="{:.1f}" fill="none" stroke="{}"{}/>)svg",
                       Px(c.x), Py(c.y), rx, ry, color,
                       dash.empty() ? "" : fmt::format(R"svg( stroke-dasharray="{}")svg", dash));
  body_ += "\n";
}

void SvgPanel::CovarianceEllipse(SvgPoint c, double cxx, double cxy, double cyy, double scale,
                                 const std::string& color, const std::string& dash) {
  // Eigen-decomposition of the symmetric 2x2 covariance.
  const double tr = cxx + cyy, det = cxx * cyy - cxy * cxy;
  const double disc = std::sqrt(std::max(0.0, tr * tr / 4.0 - det));
  const double l1 = std::max(0.0, tr / 2.0 + disc), l2 = std::max(0.0, tr / 2.0 - disc);
  const double angle = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);
  std::vector<SvgPoint> pts;
  for (int k = 0; k <= 72; ++k) {
    const double t = 2.0 * M_PI * k / 72.0;
    const double u = scale * std::sqrt(l1) * std::cos(t), v = scale * std::sqrt(l2) * std::sin(t);
    pts.push_back({c.x + u * std::cos(angle) - v * std::sin(angle), c.y + u * std::sin(angle) + v * std::cos(angle)});
  }
  Polyline(pts, color, 1.5, dash);
}

void SvgPanel::Text(SvgPoint at, const std::string& text, const std::string& color, double size) {
  body_ += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="{}" fill="{}">{}</text>)svg", Px(at.x), Py(at.y), size,
                       color, SvgEscape(text));
  body_ += "\n";
}

void SvgPanel::Legend(const std::vector<std::pair<std::string, std::string>>& entries) {
  double y = top_ + 16;
  for (const auto& [color, label] : entries) {
    body_ += fmt::format(R"svg(<rect x="{:.1f}" y="{:.1f}" width="10" height="10" fill="{}"/>)svg", left_ + 8, y - 9, color);
    body_ += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="11" fill="#222">{}</text>)svg", left_ + 22, y,
                         SvgEscape(label));
    body_ += "\n";
    y += 15;
  }
}

void SvgPanel::Axes(const std::string& xlabel, const std::string& ylabel) {
  // Zero lines, if visible, and axis labels with the extent.
  if (xmin_ < 0 && xmax_ > 0)
    body_ += fmt::format(R"svg(<line x1="{0:.1f}" y1="{1:.1f}" x2="{0:.1f}" y2="{2:.1f}" stroke="#bbb"/>)svg", Px(0), top_,
                         top_ + height_);
  if (ymin_ < 0 && ymax_ > 0)
    body_ += fmt::format(R"svg(<line x1="{1:.1f}" y1="{0:.1f}" x2="{2:.1f}" y2="{0:.1f}" stroke="#bbb"/>)svg", Py(0), left_,
                         left_ + width_);
  frame_ += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="11" fill="#444">{} [{:.4g} .. {:.4g}]</text>)svg",
                       left_, top_ + height_ + 16, SvgEscape(xlabel), xmin_, xmax_);
  frame_ += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="11" fill="#444" transform="rotate(-90 {:.1f} {:.1f})">{} [{:.4g} .. {:.4g}]</text>)svg",
                       left_ - 8, top_ + height_, left_ - 8, top_ + height_, SvgEscape(ylabel), ymin_, ymax_);
  frame_ += "\n";
}

std::string SvgPanel::Render() const {
  std::string out = fmt::format(
      R"svg(<g><rect x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="white" stroke="#888"/>)svg"
      R"svg(<text x="{:.1f}" y="{:.1f}" font-size="13" font-weight="bold" fill="#111">{}</text>)svg"
      "\n",
      left_, top_, width_, height_, left_, top_ - 6, SvgEscape(title_));
  out += fmt::format(R"svg(<svg x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" viewBox="{:.1f} {:.1f} {:.1f} {:.1f}" overflow="hidden">)svg",
                     left_, top_, width_, height_, left_, top_, width_, height_);
  out += "\n" + body_ + "</svg>\n" + frame_ + "</g>\n";
  return out;
}

std::string SvgBarChart(const std::string& title, const std::vector<std::string>& labels,
                        const std::vector<std::vector<double>>& series, const std::vector<std::string>& series_names,
                        const std::vector<std::string>& colors) {
  const double left = 220, top = 40, bar_h = 10, width = 420;
  double vmax = 1e-12;
  for (const auto& s : series)
    for (double v : s) vmax = std::max(vmax, std::abs(v));
  std::string out = fmt::format(R"svg(<text x="10" y="20" font-size="14" font-weight="bold">{}</text>)svg", SvgEscape(title));
  out += "\n";
  const double group_h = bar_h * static_cast<double>(series.size()) + 8;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    const double y0 = top + group_h * static_cast<double>(i);
    out += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="end">{}</text>)svg", left - 6,
                       y0 + bar_h, SvgEscape(labels[i]));
    for (std::size_t s = 0; s < series.size(); ++s) {
      const double v = i < series[s].size() ? series[s][i] : 0.0;
      const double w = std::abs(v) / vmax * width;
      out += fmt::format(R"svg(<rect x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="{}"/>)svg", left,
                         y0 + bar_h * static_cast<double>(s), w, bar_h - 1, colors[s % colors.size()]);
      out += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="9">{:.3g}</text>)svg", left + w + 4,
                         y0 + bar_h * static_cast<double>(s) + bar_h - 2, v);
    }
    out += "\n";
  }
  double ly = top + group_h * static_cast<double>(labels.size()) + 10;
  for (std::size_t s = 0; s < series_names.size(); ++s) {
    out += fmt::format(R"svg(<rect x="{:.1f}" y="{:.1f}" width="10" height="10" fill="{}"/><text x="{:.1f}" y="{:.1f}" font-size="11">{}</text>)svg",
                       left, ly, colors[s % colors.size()], left + 14, ly + 9, SvgEscape(series_names[s]));
    out += "\n";
    ly += 15;
  }
  return out;
}

std::string SvgDocument(double width, double height, const std::vector<std::string>& parts) {
  std::string out = fmt::format(
      R"svg(<?xml version="1.0" encoding="UTF-8"?>)svg"
      "\n"
      R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="{0:.0f}" height="{1:.0f}" viewBox="0 0 {0:.0f} {1:.0f}" font-family="sans-serif">)svg"
      "\n"
      R"svg(<rect width="100%" height="100%" fill="#fafafa"/>)svg"
      "\n",
      width, height);
  for (const auto& p : parts) out += p;
  return out + "</svg>\n";
}

}  // namespace umbmark::io
