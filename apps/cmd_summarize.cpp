// `umbmark summarize CAL.json... [--json FILE] [--csv FILE] [--report FILE.html]`:
// a fleet of robots from their `calibrate` JSON outputs (a batch output's
// `results` count one robot each): one row per robot, the fleet's median and
// robust spread of each parameter, and the robots that stand out (robust
// z-score, calibration/fleet.hpp) with the reasons in words. Robots are
// named by their robot id (calibrate JSON `robot_id`, from the robot file) or
// their file's stem; the command's logic is api::Summarize (lib/api/summarize.hpp), the --report
// page lib/api/summarize_report.cpp.
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "api/summarize.hpp"
#include "api/summarize_report.hpp"
#include "calibration/fleet.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/errors.hpp"

namespace umbmark::cli {
namespace {

struct SummarizeOptions {
  std::vector<std::string> inputs;
  FleetOptions fleet;
  JsonFlag json;
  std::string csv;
  std::string report;
};

std::string Fmt(double v, FleetQuantity q) {
  switch (q) {
    case FleetQuantity::kEd:
    case FleetQuantity::kEb: return fmt::format("{:.6f}", v);
    case FleetQuantity::kEmaxBefore:
    case FleetQuantity::kResidualAfter: return fmt::format("{:.2f} mm", v * 1e3);
    default: return fmt::format("{:.6f} m", v);
  }
}

/// The text summary: the fleet's quantities, then every robot.
void PrintFleet(const api::SummarizeResult& r) {
  const std::vector<api::SummarizeRobot>& robots = r.robots;
  const FleetSummary& s = r.fleet;
  fmt::print("Fleet summary: {} robots from {} file(s), {} outlier(s) (robust |z| > {})\n", robots.size(),
             r.files, r.outliers, r.threshold);
  fmt::print("  {:<24} {:>4} {:>16} {:>16}\n", "quantity", "n", "median", "robust SD (MAD)");
  for (const auto& [q, st] : s.fleet)
    fmt::print("  {:<24} {:>4} {:>16} {:>16}\n", FleetQuantityKey(q), st.n, Fmt(st.median, q), Fmt(st.mad, q));
  fmt::print("  {:<40} {:>12} {:>12} {:>12}  {}\n", "robot", "wheelbase_m", "D_left_m", "D_right_m", "outlier");
  for (std::size_t i = 0; i < robots.size(); ++i) {
    const auto& p = robots[i].parameters;
    fmt::print("  {:<40} {:>12.6f} {:>12.6f} {:>12.6f}  {}\n", robots[i].robot, p["wheelbase_m"].get<double>(),
               p["wheel_diameter_left_m"].get<double>(), p["wheel_diameter_right_m"].get<double>(),
               s.robots[i].outlier ? "OUTLIER" : "-");
    for (const auto& reason : s.robots[i].reasons) fmt::print("      {}\n", reason);
  }
  for (const auto& w : r.warnings) fmt::print("warning: {}\n", w);
}

// Read the fleet and summarise (api::Summarize), then text, CSV, report and
// JSON in turn.
int RunSummarize(const SummarizeOptions& o) {
  if (auto e = o.fleet.Check(); !e.empty()) throw InvalidOptions("summarize: " + e);
  // Output safety: no output may be an input or another output.
  io::OutputSet& outs = CommandOutputs();
  RegisterInputs(o.inputs);
  outs.AddOutput("--json", o.json.path);
  outs.AddOutput("--csv", o.csv);
  outs.AddOutput("--report", o.report);
  outs.Check();
  const api::SummarizeResult r = api::Summarize({o.inputs, o.fleet});
  std::vector<std::string> written;
  if (o.json.PrintText()) PrintFleet(r);
  if (!o.csv.empty()) {
    outs.Write(o.csv, api::SummarizeCsv(r));
    written.push_back(o.csv + " (CSV, one row per robot)");
  }
  if (!o.report.empty()) {
    std::vector<FleetRobot> fr;
    for (const auto& robot : r.robots) fr.push_back(robot.fleet);
    api::FleetPage page{{}, &fr, &r.fleet, r.threshold, r.files, r.outliers, r.warnings};
    for (const auto& robot : r.robots) page.names.push_back(robot.robot);
    outs.Write(o.report, api::FleetReportHtml(page));
    written.push_back(o.report + " (HTML report)");
  }
  o.json.EmitAndListOutputs(api::ToJson(r), written);
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
