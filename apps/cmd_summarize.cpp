// `umbmark summarize CAL.json... [--json FILE] [--csv FILE] [--report FILE.html]`:
// a fleet of robots from their `calibrate` JSON outputs (a batch output's
// `results` count one robot each): one row per robot, the fleet's median and
// robust spread of each parameter, and the robots that stand out (robust
// z-score, calibration/fleet.hpp) with the reasons in words. Robots are
// named by their robot id (calibrate JSON `robot_id`, from the robot file) or
// their file's stem; the --report page is summarize_report.cpp.
#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "calibration/fleet.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/errors.hpp"
#include "output/atomic_write.hpp"
#include "formats/file_text.hpp"
#include "formats/csv_writer.hpp"
#include "formats/params_json.hpp"
#include "summarize_report.hpp"

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
  std::string robot_id;  // calibrate JSON `robot_id`, when it has one
  std::string name;      // robot_id or the file's stem (unique over the fleet)
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
  if (j.contains("robot_id") && j["robot_id"].is_string() && !j["robot_id"].get<std::string>().empty())
    r.robot_id = j["robot_id"].get<std::string>();
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
/// repeat. Files that cannot be read are kept for the reader to report. One
/// stat per input (thousands of robots).
std::vector<std::string> DistinctInputs(const std::vector<std::string>& inputs, std::vector<std::string>& warnings) {
  std::vector<std::string> out;
  std::map<std::pair<dev_t, ino_t>, std::string> seen;
  std::map<std::string, std::string> unreadable;  // by the path as given, made lexically normal
  for (const auto& path : inputs) {
    struct stat st {};
    const std::string* first = nullptr;
    if (::stat(path.c_str(), &st) == 0) {
      const auto [it, fresh] = seen.emplace(std::pair{st.st_dev, st.st_ino}, path);
      if (!fresh) first = &it->second;
    } else {
      const std::string key = std::filesystem::path(path).lexically_normal().string();
      const auto [it, fresh] = unreadable.emplace(key, path);
      if (!fresh) first = &it->second;
    }
    if (first == nullptr) {
      out.push_back(path);
    } else {
      warnings.push_back(fmt::format("{} is the same file as {} (given twice): counted once", path, *first));
    }
  }
  return out;
}

/// Each robot's name for people: its robot id, else its file's stem (a
/// batch output's results "stem#k"); a name given to several robots gets
/// " (2)", " (3)", ... in input order.
void NameRobots(std::vector<Robot>& robots) {
  std::map<std::string, int> uses;
  for (auto& r : robots) {
    std::string name = r.robot_id;
    if (name.empty()) {
      const std::string& file = r.fleet.file;
      const auto hash = file.rfind('#');
      const bool batch = hash != std::string::npos && file.find('/', hash) == std::string::npos;
      const std::string path = batch ? file.substr(0, hash) : file;
      name = std::filesystem::path(path).stem().string() + (batch ? file.substr(hash) : "");
      if (name.empty()) name = path;
    }
    const int k = ++uses[name];
    r.name = k == 1 ? name : fmt::format("{} ({})", name, k);
  }
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

/// The JSON of the fleet summary.
nlohmann::json FleetJson(const SummarizeOptions& o, const std::vector<Robot>& robots, const FleetSummary& s,
                         std::size_t n_out, const std::vector<std::string>& warnings) {
  nlohmann::json j;
  j["robots"] = nlohmann::json::array();
  for (std::size_t i = 0; i < robots.size(); ++i) {
    nlohmann::json z = nlohmann::json::object();
    for (const auto& [q, v] : s.robots[i].z) z[FleetQuantityKey(q)] = v;
    j["robots"].push_back({{"file", robots[i].fleet.file},
                           {"robot", robots[i].name},
                           {"robot_id", robots[i].robot_id.empty() ? nlohmann::json(nullptr) : nlohmann::json(robots[i].robot_id)},
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
    fmt::print("  {:<40} {:>12.6f} {:>12.6f} {:>12.6f}  {}\n", robots[i].name, p["wheelbase_m"].get<double>(),
               p["wheel_diameter_left_m"].get<double>(), p["wheel_diameter_right_m"].get<double>(),
               s.robots[i].outlier ? "OUTLIER" : "-");
    for (const auto& reason : s.robots[i].reasons) fmt::print("      {}\n", reason);
  }
  for (const auto& w : warnings) fmt::print("warning: {}\n", w);
}

/// --csv: one row per robot.
std::string FleetCsv(const std::vector<Robot>& robots, const FleetSummary& s) {
  std::string csv = "file,wheelbase_m,wheel_diameter_left_m,wheel_diameter_right_m,E_d,E_b,E_max_syst_m,residual_after_m,outlier,reasons,robot\n";
  for (std::size_t i = 0; i < robots.size(); ++i) {
    std::string row = io::CsvField(robots[i].fleet.file);
    for (FleetQuantity q : kFleetQuantities) {
      const auto it = robots[i].fleet.values.find(q);
      row += it == robots[i].fleet.values.end() ? "," : fmt::format(",{:.9g}", it->second);
    }
    std::string reasons;
    for (const auto& r : s.robots[i].reasons) reasons += (reasons.empty() ? "" : "; ") + r;
    row += fmt::format(",{},{},{}\n", s.robots[i].outlier ? "true" : "false", io::CsvField(reasons), io::CsvField(robots[i].name));
    csv += row;
  }
  return csv;
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
    robots.insert(robots.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  }
  NameRobots(robots);
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
    FleetPage page{{}, &fr, &s, o.fleet.threshold, o.inputs.size(), n_out, warnings};
    for (const auto& r : robots) page.names.push_back(r.name);
    outs.Write(o.report, FleetReportHtml(page));
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
