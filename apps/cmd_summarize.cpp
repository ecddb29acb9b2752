// `umbmark summarize CAL.json... [--json FILE] [--csv FILE] [--report FILE.html]`:
// a fleet of robots from their `calibrate` JSON outputs (a batch output's
// `results` count one robot each): one row per robot, the fleet's median and
// robust spread of each parameter, and the robots that stand out (robust
// z-score, calibration/fleet.hpp) with the reasons in words.
#include <algorithm>
#include <cmath>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "calibration/fleet.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/errors.hpp"
#include "output/atomic_write.hpp"
#include "formats/file_text.hpp"
#include "formats/csv_writer.hpp"
#include "report/html_report.hpp"
#include "formats/params_json.hpp"
#include "report/svg_plot.hpp"

namespace umbmark::cli {
namespace {

struct SummarizeOptions {
  std::vector<std::string> inputs;
  FleetOptions fleet;
  JsonFlag json;
  std::string csv;
  std::string report;
};

struct Robot {
  FleetRobot fleet;
  nlohmann::json parameters;
  std::string source;  // "refined" or "umbmark"
};

/// Wheelbase and diameters of `obj` (a `parameters` object): refused naming
/// the file when missing, not numbers or impossible (negative, 1e308: a
/// robot with such parameters is no robot of the fleet).
RobotParams ParamsFrom(const nlohmann::json& obj, const std::string& file, const char* what) {
  RobotParams p;
  double* fields[] = {&p.wheelbase_m, &p.wheel_diameter_left_m, &p.wheel_diameter_right_m};
  const char* keys[] = {"wheelbase_m", "wheel_diameter_left_m", "wheel_diameter_right_m"};
  for (int k = 0; k < 3; ++k) {
    if (!obj.is_object() || !obj.contains(keys[k]) || !obj[keys[k]].is_number())
      throw InputError(file, fmt::format("calibration JSON without a numeric {}.{}", what, keys[k]));
    *fields[k] = obj[keys[k]].get<double>();
  }
  if (auto e = io::ImplausibleParams(p); !e.empty())
    throw InputError(file, fmt::format("{}: {} (impossible for a robot; this is no calibrate output of a real robot)",
                                       what, e));
  return p;
}

// One calibrate result (an object with `parameters`) -> a fleet robot.
Robot RobotFromResult(const nlohmann::json& j, const std::string& file) {
  Robot r;
  r.fleet.file = file;
  const bool refined = j.contains("refined") && j["refined"].is_object() && j["refined"].contains("parameters");
  r.parameters = refined ? j["refined"]["parameters"] : j.at("parameters");
  r.source = refined ? "refined" : "umbmark";
  auto number = [&](const nlohmann::json& obj, const char* key, FleetQuantity q) {
    if (obj.contains(key) && obj[key].is_number()) r.fleet.values[q] = obj[key].get<double>();
  };
  ParamsFrom(r.parameters, file, refined ? "refined.parameters" : "parameters");
  if (j.contains("recorded_parameters")) {
    const RobotParams rec = ParamsFrom(j["recorded_parameters"], file, "recorded_parameters");
    r.fleet.recorded = FleetRecordedKey(rec.wheelbase_m, rec.wheel_diameter_left_m, rec.wheel_diameter_right_m);
  }
  number(r.parameters, "wheelbase_m", FleetQuantity::kWheelbase);
  number(r.parameters, "wheel_diameter_left_m", FleetQuantity::kDiameterLeft);
  number(r.parameters, "wheel_diameter_right_m", FleetQuantity::kDiameterRight);
  for (const char* key : {"E_d", "E_b"}) {
    if (j.contains(key) && j[key].is_number() && !(j[key].get<double>() > 0.0 && j[key].get<double>() < 10.0))
      throw InputError(file, fmt::format("{} = {} is impossible (a ratio of positive lengths near 1)", key,
                                         j[key].get<double>()));
  }
  number(j, "E_d", FleetQuantity::kEd);
  number(j, "E_b", FleetQuantity::kEb);
  number(j, "E_max_syst_m", FleetQuantity::kEmaxBefore);
  if (j.contains("evaluation") && j["evaluation"].contains("after"))
    number(j["evaluation"]["after"], "max_final_position_error_m", FleetQuantity::kResidualAfter);
  return r;
}

std::vector<Robot> ReadRobots(const std::string& path) {
  const nlohmann::json j = io::ParseJsonDocument(io::ReadWholeFile(path), path);
  std::vector<Robot> out;
  try {
    if (j.contains("results") && j["results"].is_array()) {  // a batch calibrate output
      int k = 0;
      for (const auto& r : j["results"]) {
        ++k;
        if (r.contains("error")) continue;  // a failed calibration in the batch
        out.push_back(RobotFromResult(r, fmt::format("{}#{}", path, k)));
      }
    } else {
      out.push_back(RobotFromResult(j, path));
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(path, fmt::format("not a calibrate JSON output: {}", e.what()));
  }
  return out;
}

/// The inputs with each file once: the same file given twice (a.json and
/// ./a.json, a symbolic or hard link: same device and inode) would count one
/// robot twice and pull the fleet's median towards it. A warning names each
/// repeat. Files that cannot be read are kept for the reader to report.
std::vector<std::string> DistinctInputs(const std::vector<std::string>& inputs, std::vector<std::string>& warnings) {
  std::vector<std::string> out;
  for (const auto& path : inputs) {
    const auto same = std::find_if(out.begin(), out.end(), [&](const std::string& p) { return io::SameFile(p, path); });
    if (same == out.end()) {
      out.push_back(path);
    } else {
      warnings.push_back(fmt::format("{} is the same file as {} (given twice): counted once", path, *same));
    }
  }
  return out;
}

std::string Fmt(double v, FleetQuantity q) {
  switch (q) {
    case FleetQuantity::kEd:
    case FleetQuantity::kEb: return fmt::format("{:.6f}", v);
    case FleetQuantity::kEmaxBefore:
    case FleetQuantity::kResidualAfter: return fmt::format("{:.2f} mm", v * 1e3);
    default: return fmt::format("{:.6f} m", v);
  }
}

// Robust z-scores of every robot per quantity, outliers marked: a strip
// chart with the threshold band.
std::string FleetPlot(const std::vector<Robot>& robots, const FleetSummary& s, double threshold) {
  std::vector<FleetQuantity> qs;
  for (FleetQuantity q : kFleetQuantities)
    if (s.fleet.count(q) && s.fleet.at(q).n >= 3) qs.push_back(q);
  io::SvgPanel p(90, 40, 760, 360, "Robust z-score of each robot per quantity");
  double zmax = threshold + 1.0;
  for (const auto& r : s.robots)
    for (const auto& [q, z] : r.z) zmax = std::max(zmax, std::abs(z) + 0.5);
  p.SetExtent(-0.5, static_cast<double>(qs.size()) - 0.5, -zmax, zmax, false);
  const double right = static_cast<double>(qs.size()) - 0.5;
  p.Band({{-0.5, -threshold}, {right, -threshold}}, {{-0.5, threshold}, {right, threshold}}, "#888", 0.15);
  std::vector<io::SvgPoint> normal, outlying;
  for (std::size_t k = 0; k < qs.size(); ++k) {
    for (std::size_t i = 0; i < robots.size(); ++i) {
      const auto it = s.robots[i].z.find(qs[k]);
      if (it == s.robots[i].z.end()) continue;
      const double jitter = 0.25 * (static_cast<double>((i * 37) % 17) / 16.0 - 0.5);
      (std::abs(it->second) > threshold ? outlying : normal).push_back({static_cast<double>(k) + jitter, it->second});
    }
    static const char* kShort[] = {"wheelbase", "D left", "D right", "E_d", "E_b", "E_max,syst", "after"};
    p.Text({static_cast<double>(k) - 0.3, -zmax + (k % 2 == 0 ? 0.25 : 0.8)}, kShort[static_cast<int>(qs[k])], "#111", 11);
  }
  p.Axes("quantity (one column each; robots spread sideways)", "robust z = (value - median) / (1.4826 MAD)");
  p.Points(normal, {"#35608f", "circle", "", 1.5, false}, 3.5);
  p.Points(outlying, {"#b02020", "triangle", "", 1.5, true}, 5.5);
  p.Legend({{{"#35608f", "circle", "", 1.5, false}, "robot within the fleet"},
            {{"#b02020", "triangle", "", 1.5, true}, fmt::format("outlier (|z| > {})", threshold)},
            {{"#888", "square", "", 1.5, true}, fmt::format("band |z| <= {}", threshold)}});
  return io::SvgDocument(880, p.Bottom() + 10, {p.Render()});
}

/// The JSON of the fleet summary.
nlohmann::json FleetJson(const SummarizeOptions& o, const std::vector<Robot>& robots, const FleetSummary& s,
                         std::size_t n_out, const std::vector<std::string>& warnings) {
  nlohmann::json j;
  j["robots"] = nlohmann::json::array();
  for (std::size_t i = 0; i < robots.size(); ++i) {
    nlohmann::json z = nlohmann::json::object();
    for (const auto& [q, v] : s.robots[i].z) z[FleetQuantityKey(q)] = v;
    j["robots"].push_back({{"file", robots[i].fleet.file},
                           {"parameters", robots[i].parameters},
                           {"parameters_from", robots[i].source},
                           {"robust_z", z},
                           {"outlier", s.robots[i].outlier},
                           {"outlier_reasons", s.robots[i].reasons}});
  }
  j["fleet"] = nlohmann::json::object();
  for (const auto& [q, st] : s.fleet)
    j["fleet"][FleetQuantityKey(q)] = {{"n", st.n}, {"median", st.median}, {"mad", st.mad}, {"spread_used", st.spread}};
  j["threshold"] = o.fleet.threshold;
  j["outliers"] = n_out;
  j["warnings"] = warnings;

  return j;
}

/// The text summary: the fleet's quantities, then every robot.
void PrintFleet(const SummarizeOptions& o, const std::vector<Robot>& robots, const FleetSummary& s, std::size_t n_out,
                const std::vector<std::string>& warnings) {
  fmt::print("Fleet summary: {} robots from {} file(s), {} outlier(s) (robust |z| > {})\n", robots.size(),
             o.inputs.size(), n_out, o.fleet.threshold);
  fmt::print("  {:<24} {:>4} {:>16} {:>16}\n", "quantity", "n", "median", "robust SD (MAD)");
  for (const auto& [q, st] : s.fleet)
    fmt::print("  {:<24} {:>4} {:>16} {:>16}\n", FleetQuantityKey(q), st.n, Fmt(st.median, q), Fmt(st.mad, q));
  fmt::print("  {:<40} {:>12} {:>12} {:>12}  {}\n", "robot", "wheelbase_m", "D_left_m", "D_right_m", "outlier");
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const auto& p = robots[i].parameters;
    fmt::print("  {:<40} {:>12.6f} {:>12.6f} {:>12.6f}  {}\n", robots[i].fleet.file, p["wheelbase_m"].get<double>(),
               p["wheel_diameter_left_m"].get<double>(), p["wheel_diameter_right_m"].get<double>(),
               s.robots[i].outlier ? "OUTLIER" : "-");
    for (const auto& reason : s.robots[i].reasons) fmt::print("      {}\n", reason);
  }
  for (const auto& w : warnings) fmt::print("warning: {}\n", w);
}

/// --csv: one row per robot.
std::string FleetCsv(const std::vector<Robot>& robots, const FleetSummary& s) {
  std::string csv = "file,wheelbase_m,wheel_diameter_left_m,wheel_diameter_right_m,E_d,E_b,E_max_syst_m,residual_after_m,outlier,reasons\n";
  for (std::size_t i = 0; i < robots.size(); ++i) {
    std::string row = io::CsvField(robots[i].fleet.file);
    for (FleetQuantity q : kFleetQuantities) {
      const auto it = robots[i].fleet.values.find(q);
      row += it == robots[i].fleet.values.end() ? "," : fmt::format(",{:.9g}", it->second);
    }
    std::string reasons;
    for (const auto& r : s.robots[i].reasons) reasons += (reasons.empty() ? "" : "; ") + r;
    row += fmt::format(",{},{}\n", s.robots[i].outlier ? "true" : "false", io::CsvField(reasons));
    csv += row;
  }
  return csv;
}

/// --report: the fleet page.
std::string FleetReportHtml(const SummarizeOptions& o, const std::vector<Robot>& robots, const FleetSummary& s,
                            std::size_t n_out, const std::vector<std::string>& warnings) {
  io::HtmlReport rep("umbmark summarize: fleet of " + std::to_string(robots.size()) + " robots",
                     fmt::format("{} calibration file(s)", o.inputs.size()));
  if (n_out == 0)
    rep.Headline(fmt::format("No robot stands out of the fleet of {} (robust |z| <= {} in every quantity).",
                             robots.size(), o.fleet.threshold),
                 io::HtmlReport::Level::kGood);
  else
    rep.Headline(fmt::format("{} of {} robots stand out of the fleet (robust |z| > {}).", n_out, robots.size(),
                             o.fleet.threshold),
                 io::HtmlReport::Level::kWarn);
  std::vector<std::string> steps;
  if (n_out > 0) {
    steps.push_back("Inspect the flagged robots for the reason given (wheel wear, wheel mounting, tyre pressure).");
    steps.push_back("Recalibrate a flagged robot after the repair and summarize again.");
  } else {
    steps.push_back("Load each robot's corrected parameters (its calibrate JSON, or the --ros2 snippet).");
  }
  rep.NextSteps(steps);
  rep.Warnings(warnings);
  rep.Heading("Fleet distribution");
  std::vector<std::vector<std::string>> rows;
  for (const auto& [q, st] : s.fleet)
    rows.push_back({FleetQuantityKey(q), std::to_string(st.n), Fmt(st.median, q), Fmt(st.mad, q)});
  rep.Table({"quantity", "robots", "median", "robust SD (1.4826 MAD)"}, rows);
  rep.Heading("Robots");
  rows.clear();
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const auto& p = robots[i].parameters;
    std::string reasons;
    for (const auto& r : s.robots[i].reasons) reasons += (reasons.empty() ? "" : " | ") + r;
    rows.push_back({robots[i].fleet.file, fmt::format("{:.6f}", p["wheelbase_m"].get<double>()),
                    fmt::format("{:.6f}", p["wheel_diameter_left_m"].get<double>()),
                    fmt::format("{:.6f}", p["wheel_diameter_right_m"].get<double>()),
                    s.robots[i].outlier ? "OUTLIER" : "-", reasons});
  }
  rep.Table({"robot (file)", "wheelbase [m]", "D left [m]", "D right [m]", "outlier", "why"}, rows);
  rep.Figure(FleetPlot(robots, s, o.fleet.threshold),
             "Each robot's robust z-score per quantity; the grey band is the outlier threshold. Triangles: outliers.");
  return rep.Render();
}

// Read the fleet, summarise, then text, CSV, report and JSON in turn.
int RunSummarize(const SummarizeOptions& o) {
  if (auto e = o.fleet.Check(); !e.empty()) throw InvalidOptions("summarize: " + e);
  // Output safety: no output may be an input or another output.
  io::OutputSet& outs = CommandOutputs();
  RegisterInputs(o.inputs);
  outs.AddOutput("--json", o.json.path);
  outs.AddOutput("--csv", o.csv);
  outs.AddOutput("--report", o.report);
  outs.Check();
  std::vector<std::string> warnings;
  std::vector<Robot> robots;
  for (const auto& path : DistinctInputs(o.inputs, warnings)) {
    auto more = ReadRobots(path);
    robots.insert(robots.end(), more.begin(), more.end());
  }
  std::vector<FleetRobot> fr;
  for (const auto& r : robots) fr.push_back(r.fleet);
  const FleetSummary s = SummarizeFleet(fr, o.fleet);
  if (s.groups > 1) {
    warnings.push_back(fmt::format(
        "the robots were recorded with {} different parameter sets (recorded_parameters: robot files); E_d, E_b and "
        "E_max_syst_m are relative to them and compared only between robots with the same set (at least 3); the "
        "corrected parameters are compared across the whole fleet",
        s.groups));
  }
  if (robots.size() < 3) warnings.push_back(fmt::format("{} robot(s): a fleet spread needs at least 3; no outliers are flagged", robots.size()));
  std::size_t n_out = 0;
  for (const auto& r : s.robots) n_out += r.outlier ? 1 : 0;

  const nlohmann::json j = FleetJson(o, robots, s, n_out, warnings);
  std::vector<std::string> written;
  if (o.json.PrintText()) PrintFleet(o, robots, s, n_out, warnings);
  if (!o.csv.empty()) {
    outs.Write(o.csv, FleetCsv(robots, s));
    written.push_back(o.csv + " (CSV, one row per robot)");
  }
  if (!o.report.empty()) {
    outs.Write(o.report, FleetReportHtml(o, robots, s, n_out, warnings));
    written.push_back(o.report + " (HTML report)");
  }
  o.json.EmitAndListOutputs(j, written);
  return 0;
}

}  // namespace

Command SetupSummarize(CLI::App& parent) {
  auto opts = std::make_shared<SummarizeOptions>();
  auto* app = parent.add_subcommand("summarize", "Fleet summary of many robots' calibrate JSON outputs: spread and outliers");
  app->add_option("CAL", opts->inputs, "calibrate JSON outputs (one robot each; a batch output counts each result)")
      ->required();
  app->add_option("--threshold", opts->fleet.threshold, "Robust |z| above which a robot is an outlier")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  opts->json.Bind(*app);
  app->add_option("--csv", opts->csv, "Write one row per robot (CSV)");
  app->add_option("--report", opts->report, "Write a self-contained HTML report");
  return {app, [opts] { return RunSummarize(*opts); }};
}

}  // namespace umbmark::cli
