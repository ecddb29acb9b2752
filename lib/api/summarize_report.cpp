// The fleet page of `umbmark summarize --report` (see summarize_report.hpp).
#include "api/summarize_report.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "report/html_report.hpp"
#include "report/svg_plot.hpp"

namespace umbmark::api {
namespace {

constexpr std::size_t kMaxOutlierRows = 200;  // the table; the JSON and CSV list every robot
constexpr int kLabelRows = 4;                  // rows of outlier labels above a histogram

// How a quantity is drawn: title, axis unit and the factor from SI to it.
struct QuantityAxis {
  const char* title;
  const char* unit;
  double scale;
};
QuantityAxis AxisOf(FleetQuantity q) {
  switch (q) {
    case FleetQuantity::kWheelbase: return {"Corrected wheelbase", "mm", 1e3};
    case FleetQuantity::kDiameterLeft: return {"Corrected left wheel diameter", "mm", 1e3};
    case FleetQuantity::kDiameterRight: return {"Corrected right wheel diameter", "mm", 1e3};
    case FleetQuantity::kEd: return {"Diameter ratio error E_d", "", 1.0};
    case FleetQuantity::kEb: return {"Wheelbase error E_b", "", 1.0};
    case FleetQuantity::kEmaxBefore: return {"Systematic error before calibration E_max,syst", "mm", 1e3};
    case FleetQuantity::kResidualAfter: return {"Largest final position error after correction", "mm", 1e3};
  }
  return {"", "", 1.0};
}

std::string ValueText(double v, const QuantityAxis& a) {
  return a.unit[0] ? fmt::format("{:.3f} {}", v, a.unit) : fmt::format("{:.5f}", v);
}

struct Marked {
  std::size_t robot;
  double value, z;
};

// The histogram's range: every robot, but at most 8 robust SD either side of
// the median (robots beyond sit at the edge with their value in the label),
// and always the threshold band.
std::pair<double, double> View(const std::vector<double>& v, double median, double spread, double threshold) {
  const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
  double lo = std::max(*mn, median - 8.0 * spread), hi = std::min(*mx, median + 8.0 * spread);
  lo = std::min(lo, median - (threshold + 1.0) * spread);
  hi = std::max(hi, median + (threshold + 1.0) * spread);
  if (!(hi > lo)) {
    const double pad = std::max(std::abs(median) * 1e-6, 1e-12);
    lo = median - pad;
    hi = median + pad;
  }
  return {lo, hi};
}

// Labels placed left to right in the lowest free row; a label with no free
// row is left out (the table lists every outlier).
std::size_t LabelOutliers(io::SvgPanel& p, std::vector<Marked> marked, const FleetPage& page, const QuantityAxis& a,
                          double lo, double hi, double top) {
  std::sort(marked.begin(), marked.end(), [](const Marked& x, const Marked& y) { return x.value < y.value; });
  const double per_px = (hi - lo) / 980.0;
  std::vector<double> row_end(kLabelRows, -INFINITY);
  std::size_t labelled = 0;
  for (const auto& m : marked) {
    const bool off = m.value < lo || m.value > hi;
    const std::string text = off ? fmt::format("{} ({})", page.names[m.robot], ValueText(m.value, a)) : page.names[m.robot];
    const double width = (6.2 * static_cast<double>(text.size()) + 6.0) * per_px;
    double x = std::clamp(m.value, lo, hi) - 0.5 * width;
    x = std::clamp(x, lo, hi - width);
    for (int r = 0; r < kLabelRows; ++r) {
      if (x < row_end[r]) continue;
      row_end[r] = x + width;
      p.Text({x, top * (0.79 + 0.055 * r)}, text, "#b02020", 10.5);
      ++labelled;
      break;
    }
  }
  return labelled;
}

// One quantity: a histogram of every robot's value, the median and the
// threshold band, the outliers as triangles with their names.
std::string DistributionPlot(FleetQuantity q, const FleetPage& page, std::size_t& unlabelled) {
  const FleetSummary& s = *page.summary;
  const QuantityAxis a = AxisOf(q);
  const FleetStat& st = s.fleet.at(q);
  std::vector<double> v;
  std::vector<Marked> marked;
  for (std::size_t i = 0; i < page.robots->size(); ++i) {
    const auto it = (*page.robots)[i].values.find(q);
    if (it == (*page.robots)[i].values.end()) continue;
    v.push_back(it->second * a.scale);
    const auto z = s.robots[i].z.find(q);
    if (z != s.robots[i].z.end() && std::abs(z->second) > page.threshold)
      marked.push_back({i, it->second * a.scale, z->second});
  }
  const double median = st.median * a.scale, spread = st.spread * a.scale;
  const auto [lo, hi] = View(v, median, spread, page.threshold);
  const std::size_t bins = std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(2.0 * std::cbrt(v.size()))), 8, 60);
  const double w = (hi - lo) / static_cast<double>(bins);
  std::vector<double> count(bins, 0.0);
  for (double x : v) count[std::min(bins - 1, static_cast<std::size_t>(std::max(0.0, (std::clamp(x, lo, hi) - lo) / w)))] += 1.0;
  const double top = std::max(1.0, *std::max_element(count.begin(), count.end())) / 0.72;  // room for the labels
  io::SvgPanel p(70, 34, 980, 220, fmt::format("{} ({} robots)", a.title, v.size()));
  p.SetExtent(lo, hi, 0.0, top, false);
  std::vector<io::SvgPoint> base, bars;
  for (std::size_t b = 0; b < bins; ++b)
    for (double x : {lo + w * static_cast<double>(b), lo + w * static_cast<double>(b + 1)}) {
      base.push_back({x, 0.0});
      bars.push_back({x, count[b]});
    }
  p.Band(base, bars, "#35608f", 0.35);
  p.Polyline(bars, {"#35608f", "", "", 1.2, false});
  const io::SvgStyle median_style{"#222", "", "", 1.5, false}, band_style{"#b02020", "", "5,4", 1.2, false};
  p.VLine(median, median_style);
  if (s.robots.size() >= 3 && spread > 0.0) {
    p.VLine(median - page.threshold * spread, band_style);
    p.VLine(median + page.threshold * spread, band_style);
  }
  std::vector<io::SvgPoint> tri;
  for (const auto& m : marked) tri.push_back({std::clamp(m.value, lo, hi), top * 0.74});
  const io::SvgStyle outlier_style{"#b02020", "triangle", "", 1.5, true};
  p.Points(tri, outlier_style, 5.0, "outliers");
  unlabelled += marked.size() - LabelOutliers(p, marked, page, a, lo, hi, top);
  p.Axes(a.unit[0] ? fmt::format("{} [{}]", a.title, a.unit) : std::string(a.title), "robots per bin");
  p.Legend({{{"#35608f", "square", "", 1.5, true}, "robots per bin"},
            {median_style, "fleet median"},
            {band_style, fmt::format("median +- {} robust SD (outlier threshold)", page.threshold)},
            {outlier_style, "outlier (named above; beyond the axis: at the edge, with its value)"}});
  return io::SvgDocument(1080, p.Bottom() + 10, {p.Render()});
}

// One row per outlier robot, the largest |z| first.
std::vector<std::vector<std::string>> OutlierRows(const FleetPage& page, std::size_t& shown) {
  const FleetSummary& s = *page.summary;
  std::vector<std::pair<double, std::size_t>> order;
  for (std::size_t i = 0; i < s.robots.size(); ++i) {
    if (!s.robots[i].outlier) continue;
    double zmax = 0.0;
    for (const auto& [q, z] : s.robots[i].z) zmax = std::max(zmax, std::abs(z));
    order.push_back({zmax, i});
  }
  std::stable_sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  std::vector<std::vector<std::string>> rows;
  for (const auto& [zmax, i] : order) {
    if (rows.size() == kMaxOutlierRows) break;
    std::string why;
    for (const auto& r : s.robots[i].reasons) why += (why.empty() ? "" : "; ") + r;
    rows.push_back({page.names[i], why, fmt::format("{:.1f}", zmax)});
  }
  shown = rows.size();
  return rows;
}

std::string StatText(double v, FleetQuantity q) {
  const QuantityAxis a = AxisOf(q);
  return a.unit[0] ? fmt::format("{:.3f} {}", v * a.scale, a.unit) : fmt::format("{:.6f}", v);
}

}  // namespace

std::string FleetReportHtml(const FleetPage& page) {
  const FleetSummary& s = *page.summary;
  const std::size_t n = page.robots->size();
  io::HtmlReport rep("umbmark summarize: fleet of " + std::to_string(n) + " robots",
                     fmt::format("{} calibration file(s)", page.files));
  if (page.outliers == 0)
    rep.Headline(fmt::format("No robot stands out of the fleet of {} (robust |z| <= {} in every quantity).", n,
                             page.threshold),
                 io::HtmlReport::Level::kGood);
  else
    rep.Headline(fmt::format("{} of {} robots stand out of the fleet (robust |z| > {}).", page.outliers, n,
                             page.threshold),
                 io::HtmlReport::Level::kWarn);
  std::vector<std::string> steps;
  if (page.outliers > 0) {
    steps.push_back("Inspect the robots in the table below for the reason given (wheel wear, wheel mounting, tyre pressure).");
    steps.push_back("Recalibrate a flagged robot after the repair and summarize again.");
  } else {
    steps.push_back("Load each robot's corrected parameters (its calibrate JSON, or the --ros2 snippet).");
  }
  steps.push_back("Every robot's values and z-scores: the --csv or --json output of this command.");
  rep.NextSteps(steps);
  rep.Warnings(page.warnings);
  if (page.outliers > 0) {
    std::size_t shown = 0;
    const auto rows = OutlierRows(page, shown);
    rep.Heading(fmt::format("Outlier robots ({})", page.outliers));
    rep.Table({"robot", "why (largest |z| first)", "largest |z|"}, rows, 2);
    if (shown < page.outliers)
      rep.Paragraph(fmt::format("The {} with the largest |z| are shown; all {} are in the --csv and --json output.", shown,
                                page.outliers));
  }
  rep.Heading("Fleet distribution");
  std::vector<std::vector<std::string>> rows;
  for (const auto& [q, st] : s.fleet) {
    std::size_t out = 0;
    for (const auto& r : s.robots)
      if (const auto z = r.z.find(q); z != r.z.end() && std::abs(z->second) > page.threshold) ++out;
    rows.push_back({FleetQuantityKey(q), std::to_string(st.n), StatText(st.median, q), StatText(st.mad, q),
                    std::to_string(out)});
  }
  rep.Table({"quantity", "robots", "median", "robust SD (1.4826 MAD)", "outliers"}, rows);
  std::size_t unlabelled = 0;
  for (FleetQuantity q : kFleetQuantities) {
    if (!s.fleet.count(q) || s.fleet.at(q).n == 0) continue;
    const bool grouped = s.groups > 1 && FleetQuantityIsRelative(q);
    rep.Figure(DistributionPlot(q, page, unlabelled),
               fmt::format("{}: every robot's value, binned; triangles mark the outliers in this quantity (|z| > {}){}.",
                           AxisOf(q).title, page.threshold,
                           grouped ? "; scored within each group of robots recorded with the same robot file, the "
                                     "lines show the whole fleet's median and threshold"
                                   : ""));
  }
  if (unlabelled > 0)
    rep.Paragraph(fmt::format("{} outlier marks have no label (no room beside their neighbours); the table names them.",
                              unlabelled));
  return rep.Render();
}

}  // namespace umbmark::api
