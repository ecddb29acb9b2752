// Plots and report page of a diagnosis (see diagnose_report.hpp).
#include "diagnose_report.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "io/html_report.hpp"
#include "io/svg_plot.hpp"

namespace umbmark::cli {

// Plots of a diagnosis, from its JSON (so they follow whatever the diagnosis
// provides): the standardised size of each located discrepancy against the
// 95% band of the baseline model, largest marked, grouped by experiment;
// the held-out shrink of each candidate effect; and, when the diagnosis
// explains the gap by several effects, the cumulative held-out shrink as
// they are added.
std::string DiagnosePlotsSvg(const nlohmann::json& j) {
  std::vector<std::string> parts;
  double bottom = 20;
  const auto& where = j.at("gap").value("where", nlohmann::json::array());
  if (!where.empty()) {
    io::SvgPanel p(90, 40, 760, 300, "Where the runs leave the model: standardised discrepancies");
    std::vector<io::SvgPoint> in_band, out_band;
    double zmax = 3.0;
    std::vector<std::string> labels;
    for (std::size_t i = 0; i < where.size(); ++i) {
      const double z = where[i].value("size_se", 0.0);
      zmax = std::max(zmax, std::abs(z) + 1.0);
      (std::abs(z) > 1.96 ? out_band : in_band).push_back({static_cast<double>(i + 1), z});
    }
    const double right = static_cast<double>(where.size()) + 0.7;
    p.SetExtent(0.3, right, std::min(-zmax / 4, -2.5), zmax, false);
    p.Band({{0.3, -1.96}, {right, -1.96}}, {{0.3, 1.96}, {right, 1.96}}, "#777", 0.2);
    p.Axes("discrepancy rank (1 = largest)", "size [standard errors]");
    p.Points(in_band, {"#35608f", "circle", "", 1.5, false}, 4);
    p.Points(out_band, {"#b02020", "triangle", "", 1.5, true}, 5.5);
    for (std::size_t i = 0; i < std::min<std::size_t>(where.size(), 5); ++i) {
      const auto& w = where[i];
      p.Text({static_cast<double>(i + 1) + 0.15, w.value("size_se", 0.0)},
             fmt::format("{}: {} {} ({})", i + 1, w.value("statistic", ""), w.value("component", ""), w.value("subset", "")),
             "#111", 10);
    }
    p.Legend({{{"#777", "square", "", 1.5, true}, "95% band of the baseline model (|z| <= 1.96)"},
              {{"#b02020", "triangle", "", 1.5, true}, "discrepancy outside the band (top 5 labelled)"},
              {{"#35608f", "circle", "", 1.5, false}, "discrepancy within the band"}});
    parts.push_back(p.Render());
    bottom = p.Bottom() + 30;
  }
  std::vector<std::string> names;
  std::vector<double> shrink, heldout;
  for (const auto& c : j.value("candidates", nlohmann::json::array())) {
    if (names.size() >= 12) break;
    names.push_back(c.value("effect", "?"));
    shrink.push_back(c.contains("shrink") && c["shrink"].is_number() ? c["shrink"].get<double>() : NAN);
    heldout.push_back(c.contains("heldout_shrink") && c["heldout_shrink"].is_number() ? c["heldout_shrink"].get<double>() : NAN);
  }
  if (!names.empty()) {
    parts.push_back(fmt::format(R"svg(<g transform="translate(0,{:.0f})">)svg", bottom) +
                    io::SvgBarChart("How much of the gap each candidate effect closes (best first)", names,
                                    {heldout, shrink}, {"held-out shrink (runs not used to fit)", "in-sample shrink"},
                                    {"#1f5fa8", "#444444"}, "shrink = 1 - gap after / gap before (1: gap gone)") +
                    "</g>\n");
    bottom += 44 + (2 * 12 + 10) * static_cast<double>(names.size()) + 50 + 2 * 16 + 20;
  }
  const auto& ex = j.value("explanation", nlohmann::json::array());
  if (!ex.empty()) {
    std::vector<std::string> steps;
    std::vector<double> cum, cum_held;
    std::string so_far;
    for (const auto& e : ex) {
      so_far += (so_far.empty() ? "" : " + ") + e.value("effect", "?");
      steps.push_back(so_far);
      cum.push_back(e.value("cumulative_shrink", NAN));
      cum_held.push_back(e.value("cumulative_heldout_shrink", NAN));
    }
    parts.push_back(fmt::format(R"svg(<g transform="translate(0,{:.0f})">)svg", bottom) +
                    io::SvgBarChart("The explanation: gap closed as effects are added", steps, {cum_held, cum},
                                    {"cumulative held-out shrink", "cumulative in-sample shrink"}, {"#1f7a3a", "#444444"},
                                    "fraction of the gap closed") +
                    "</g>\n");
    bottom += 44 + (2 * 12 + 10) * static_cast<double>(steps.size()) + 50 + 2 * 16 + 20;
  }
  return io::SvgDocument(900, bottom + 10, parts);
}

std::string DiagnoseReportHtml(const nlohmann::json& j, const std::string& manifest) {
  io::HtmlReport rep("umbmark diagnose", manifest);
  const auto& v = j.at("verdict");
  const std::string effect = v.value("effect", "?");
  const auto& gap = j.at("gap");
  const double p = gap.value("p_value", NAN);
  if (effect == "none") {
    rep.Headline(fmt::format("No significant gap between the runs and the model (p = {:.3g}).", p), io::HtmlReport::Level::kGood);
  } else if (effect == "unexplained") {
    rep.Headline(fmt::format("The runs leave the model (p = {:.3g}) and no known effect explains it.", p),
                 io::HtmlReport::Level::kBad);
  } else {
    rep.Headline(fmt::format("The runs leave the model (p = {:.3g}); the cause: {}. {}", p, effect, v.value("reason", "")),
                 io::HtmlReport::Level::kWarn);
  }
  std::vector<std::string> steps;
  if (effect == "none") {
    steps.push_back("The calibrated model describes these runs: use it (calibrate JSON, fit-noise k_L/k_R) in your simulation.");
  } else if (effect == "unexplained") {
    steps.push_back("Look at the largest discrepancies below: which experiment, which motion, which component.");
    steps.push_back("Record a campaign with more kinds of motion (arcs, back-and-forth, free paths) so effects can be told apart.");
  } else {
    steps.push_back(fmt::format("Model or fix `{}` (its fitted parameters are in the table below), then diagnose again.", effect));
    steps.push_back("Simulate with the effect (`umbmark simulate --effect ...`) to check your simulation reproduces the runs.");
  }
  rep.NextSteps(steps);
  std::vector<std::string> warnings;
  for (const auto& w : j.value("warnings", nlohmann::json::array())) warnings.push_back(w.get<std::string>());
  for (const auto& w : j.value("notes", nlohmann::json::array()))
    if (w.is_string()) warnings.push_back(w.get<std::string>());
  rep.Warnings(warnings);
  rep.Heading("Gap");
  rep.Table({"quantity", "value"},
            {{"gap score", fmt::format("{:.3g}", gap.value("score", NAN))},
             {"p-value (combined)", fmt::format("{:.3g}", p)},
             {"null simulations; alpha", fmt::format("{}; {}", gap.value("null_simulations", 0), gap.value("alpha", NAN))}});
  rep.Heading("Candidate effects (best first)");
  std::vector<std::vector<std::string>> rows;
  for (const auto& c : j.value("candidates", nlohmann::json::array())) {
    std::string params;
    const nlohmann::json fitted = c.value("params", nlohmann::json::object());
    for (const auto& [k, val] : fitted.items())
      params += fmt::format("{}{} = {}", params.empty() ? "" : ", ", k, val.is_number() ? fmt::format("{:.4g}", val.get<double>()) : val.dump());
    auto num = [&](const char* key) {
      return c.contains(key) && c[key].is_number() ? fmt::format("{:.3f}", c[key].get<double>()) : std::string("-");
    };
    rows.push_back({c.value("effect", "?"), params, num("shrink"), num("heldout_shrink")});
  }
  rep.Table({"effect", "fitted parameters", "shrink", "held-out shrink"}, rows, 2);
  rep.Heading("Plots");
  rep.Figure(DiagnosePlotsSvg(j), "Top: the located discrepancies in standard errors against the model's 95% band. "
                                  "Below: how much of the gap each effect closes.");
  return rep.Render();
}

}  // namespace umbmark::cli
