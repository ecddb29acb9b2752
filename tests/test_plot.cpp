// The plotting layer (lib/report/svg_plot) and the plots of the commands, checked
// on their SVG: tick values at 1-2-5 steps covering the data, tick marks
// drawn at those values, legend entries matching what is drawn, calibrate's
// before/after panels on one common scale, and the --report pages'
// structure (a headline, tables, inline plots, no script, no network).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "report/html_report.hpp"
#include "report/svg_plot.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;
using namespace umbmark::testing;
namespace fs = std::filesystem;

namespace {
const fs::path kSrc = UMBMARK_SOURCE_DIR;
const fs::path kEx = kSrc / "data/examples";

/// data-value of every tick of one axis, per panel (in document order).
std::vector<std::vector<double>> PanelTicks(const std::string& svg, const std::string& axis) {
  std::vector<std::vector<double>> out;
  const std::regex panel_re(R"re(<g class="panel")re");
  const std::regex tick_re("<g class=\"tick " + axis + "\" data-value=\"([-0-9.e+]+)\"");
  std::vector<std::size_t> starts;
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), panel_re); it != std::sregex_iterator(); ++it)
    starts.push_back(static_cast<std::size_t>(it->position()));
  starts.push_back(svg.size());
  for (std::size_t p = 0; p + 1 < starts.size(); ++p) {
    const std::string part = svg.substr(starts[p], starts[p + 1] - starts[p]);
    std::vector<double> ticks;
    for (auto it = std::sregex_iterator(part.begin(), part.end(), tick_re); it != std::sregex_iterator(); ++it)
      ticks.push_back(std::stod((*it)[1]));
    out.push_back(ticks);
  }
  return out;
}

std::vector<std::string> LegendLabels(const std::string& svg) {
  std::vector<std::string> out;
  const std::regex re(R"re(<g class="legend-entry" data-label="([^"]*)")re");
  for (auto it = std::sregex_iterator(svg.begin(), svg.end(), re); it != std::sregex_iterator(); ++it) out.push_back((*it)[1]);
  return out;
}
}  // namespace

TEST_CASE("NiceTicks: 1-2-5 steps covering the range", "[plot]") {
  CHECK(io::NiceTicks(0.0, 10.0, 5) == std::vector<double>{0, 2, 4, 6, 8, 10});
  CHECK(io::NiceTicks(0.0, 10.0, 3) == std::vector<double>{0, 5, 10});
  CHECK(io::NiceTicks(-36.55, 36.55, 6) == std::vector<double>{-30, -20, -10, 0, 10, 20, 30});
  const auto t = io::NiceTicks(0.0012, 0.0049, 4);
  REQUIRE(t.size() >= 3);
  CHECK(t.front() >= 0.0012);
  CHECK(t.back() <= 0.0049);
  CHECK(t[1] - t[0] == Approx(0.001));
  CHECK(io::NiceTicks(1.0, 1.0).empty());
  CHECK(io::TickLabel(0.25, 0.05) == "0.25");
  CHECK(io::TickLabel(-30.0, 10.0) == "-30");
  CHECK(io::TickLabel(0.002, 0.001) == "0.002");
}

TEST_CASE("a panel draws its ticks at the tick values and a legend entry per series", "[plot]") {
  io::SvgPanel p(60, 40, 400, 300, "test");
  p.SetExtent(-5.0, 25.0, 0.0, 1.0, false);
  p.Axes("x [m]", "y [-]");
  const io::SvgStyle a{"#111", "circle", "", 1.5, true}, b{"#c00", "", "5,3", 1.5, false};
  p.Points({{1, 0.5}, {2, 0.25}}, a);
  p.Polyline({{0, 0}, {20, 1}}, b);
  p.Legend({{a, "series A"}, {b, "series B"}});
  const std::string svg = io::SvgDocument(500, p.Bottom(), {p.Render()});
  const auto xt = PanelTicks(svg, "x"), yt = PanelTicks(svg, "y");
  REQUIRE(xt.size() == 1);
  auto same = [](const std::vector<double>& got, const std::vector<double>& want) {
    if (got.size() != want.size()) return false;
    for (std::size_t i = 0; i < got.size(); ++i)
      if (std::abs(got[i] - want[i]) > 1e-9 * (1 + std::abs(want[i]))) return false;
    return true;
  };
  CHECK(same(xt[0], io::NiceTicks(-5.0, 25.0, 5)));
  CHECK(same(yt[0], io::NiceTicks(0.0, 1.0, 5)));
  CHECK(LegendLabels(svg) == std::vector<std::string>{"series A", "series B"});
  CHECK(svg.find("x [m]") != std::string::npos);
  CHECK(svg.find("stroke-dasharray=\"5,3\"") != std::string::npos);  // dashes, not colour alone
  CHECK(p.Bottom() > 40 + 300 + 2 * 16);  // the legend sits below the panel
}

TEST_CASE("calibrate --plot: before and after on one scale; the legend lists only what is drawn", "[plot][cli]") {
  const fs::path dir = TempDir("plot");
  REQUIRE(RunCli("calibrate " + Q(kEx / "calibrate.toml") + " --plot " + Q(dir / "cal.svg")).status == 0);
  const std::string svg = Slurp((dir / "cal.svg").string());
  const auto xt = PanelTicks(svg, "x"), yt = PanelTicks(svg, "y");
  REQUIRE(xt.size() >= 2);
  CHECK(xt[0] == xt[1]);  // common scale: the 287 mm before and 9 mm after share the axes
  CHECK(yt[0] == yt[1]);
  CHECK(xt[0].size() >= 4);
  const auto legend = LegendLabels(svg);
  CHECK(std::count_if(legend.begin(), legend.end(), [](const std::string& s) { return s.find("excluded") != std::string::npos; }) == 0);
  CHECK(std::count_if(legend.begin(), legend.end(), [](const std::string& s) { return s.rfind("E_max,syst = 286.72 mm", 0) == 0; }) == 1);
  // Excluding a run makes it appear, and be named, in the legend.
  REQUIRE(RunCli("calibrate " + Q(kEx / "calibrate.toml") + " --exclude-runs 1 --plot " + Q(dir / "ex.svg")).status == 0);
  const auto legend2 = LegendLabels(Slurp((dir / "ex.svg").string()));
  CHECK(std::count(legend2.begin(), legend2.end(), "excluded or rejected runs (1)") == 2);  // both panels
}

TEST_CASE("a report page is self-contained HTML with the parts a reader needs", "[plot][report]") {
  io::HtmlReport rep("umbmark test", "a <subject> & more");
  rep.Headline("All good: 3 mm", io::HtmlReport::Level::kGood);
  rep.NextSteps({"do this"});
  rep.Table({"a", "b [mm]"}, {{"x", "1.00"}});
  rep.Figure(io::SvgDocument(10, 10, {}), "caption");
  const std::string html = rep.Render();
  CHECK(html.rfind("<!DOCTYPE html>", 0) == 0);
  CHECK(html.find("a &lt;subject&gt; &amp; more") != std::string::npos);
  CHECK(html.find("class=\"headline good\"") != std::string::npos);
  CHECK(html.find("<script") == std::string::npos);
  CHECK(html.find("http://") == html.find("http://www.w3.org/2000/svg"));  // only the SVG namespace
  CHECK(html.find("<figure class=\"plot\">") != std::string::npos);
}

TEST_CASE("each command's --report writes one page", "[report][cli]") {
  const fs::path dir = TempDir("report");
  const auto cal = RunCli("calibrate " + Q(kEx / "calibrate.toml") + " --report " + Q(dir / "cal.html") + " --json " +
                          Q(dir / "cal.json"));
  REQUIRE(cal.status == 0);
  CHECK(cal.out.find("wrote " + (dir / "cal.html").string()) != std::string::npos);
  REQUIRE(RunCli("evaluate " + Q(kEx / "calibrate.toml") + " --params " + Q(dir / "cal.json") + " --report " +
                 Q(dir / "ev.html")).status == 0);
  REQUIRE(RunCli("fit-noise " + Q(kEx / "fit-noise.toml") + " --report " + Q(dir / "fn.html")).status == 0);
  REQUIRE(RunCli("diagnose " + Q(kEx / "diagnose.toml") + " --null-sims 50 --report " + Q(dir / "dg.html")).status == 0);
  for (const char* page : {"cal.html", "ev.html", "fn.html", "dg.html"}) {
    INFO(page);
    const std::string html = Slurp((dir / page).string());
    CHECK(html.find("class=\"headline") != std::string::npos);
    CHECK(html.find("<table class=\"numbers\">") != std::string::npos);
    CHECK(html.find("<figure class=\"plot\">") != std::string::npos);
    CHECK(html.find("class=\"tick x\"") != std::string::npos);
    CHECK(html.find("<script") == std::string::npos);
  }
  // The calibrate page states the numbers with units.
  const std::string c = Slurp((dir / "cal.html").string());
  CHECK(c.find("286.72 mm before") != std::string::npos);
  CHECK(c.find("What to do next") != std::string::npos);
}

TEST_CASE("calibrate and evaluate plots show every run; the worst are marked and named", "[plot][cli]") {
  const fs::path dir = TempDir("plot-all-runs");
  REQUIRE(RunCli("calibrate " + Q(kEx / "calibrate.toml") + " --plot " + Q(dir / "cal.svg") + " --json " +
                 Q(dir / "cal.json")).status == 0);
  const std::string cal = Slurp((dir / "cal.svg").string());
  // Two return-error panels, then one path panel per run: all 10 runs.
  auto count = [](const std::string& text, const std::string& what) {
    int n = 0;
    for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
  };
  auto panels = [&](const std::string& svg) {  // titled panels (the shared legend has no title)
    return count(svg, "<g class=\"panel\" data-title=\"") - count(svg, "<g class=\"panel\" data-title=\"\"");
  };
  CHECK(panels(cal) == 2 + 10);
  CHECK(count(cal, "class=\"worst-frame\"") == 3);
  CHECK(cal.find("Paths of all 10 runs") != std::string::npos);
  // The marked runs are those with the largest final error after correction:
  // their titles carry the largest numbers.
  const std::regex title_re(R"re(data-title="(WORST \d: )?[^"]*, ([0-9.]+) mm")re");
  std::vector<std::pair<bool, double>> titles;
  for (auto it = std::sregex_iterator(cal.begin(), cal.end(), title_re); it != std::sregex_iterator(); ++it)
    titles.push_back({(*it)[1].matched, std::stod((*it)[2])});
  REQUIRE(titles.size() == 10);
  double min_marked = 1e9, max_unmarked = 0;
  for (const auto& [marked, mm] : titles) (marked ? min_marked : max_unmarked) = marked ? std::min(min_marked, mm) : std::max(max_unmarked, mm);
  CHECK(min_marked >= max_unmarked);

  REQUIRE(RunCli("evaluate " + Q(kEx / "calibrate.toml") + " --params " + Q(dir / "cal.json") + " --plot " +
                 Q(dir / "ev.svg")).status == 0);
  const std::string ev = Slurp((dir / "ev.svg").string());
  CHECK(ev.find("Position error along the path (all 10 runs)") != std::string::npos);
  // Every run drawn as a line in each error panel (before and after), and
  // the paths of the 8 worst, worst first.
  CHECK(panels(ev) == 2 + 8);
  CHECK(ev.find("data-title=\"1: run ") != std::string::npos);
  CHECK(ev.find("data-title=\"8: run ") != std::string::npos);
  const auto legend = LegendLabels(ev);
  CHECK(std::count(legend.begin(), legend.end(), "bold, numbered: the 8 runs with the largest final error (--params)") == 1);
}
