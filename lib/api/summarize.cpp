// `summarize` as a library call (see summarize.hpp).
#include "api/summarize.hpp"

#include <sys/stat.h>

#include <filesystem>
#include <iterator>
#include <map>

#include <fmt/format.h>

#include "core/errors.hpp"
#include "formats/csv_writer.hpp"
#include "formats/file_text.hpp"
#include "formats/params_json.hpp"

namespace umbmark::api {

namespace {

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
SummarizeRobot RobotFromResult(const nlohmann::json& j, const std::string& file) {
  SummarizeRobot r;
  r.fleet.file = file;
  const bool refined = j.contains("refined") && j["refined"].is_object() && j["refined"].contains("parameters");
  r.parameters = refined ? j["refined"]["parameters"] : j.at("parameters");
  r.parameters_from = refined ? "refined" : "umbmark";
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

std::vector<SummarizeRobot> ReadRobots(const std::string& path) {
  const nlohmann::json j = io::ParseJsonDocument(io::ReadWholeFile(path), path);
  std::vector<SummarizeRobot> out;
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
void NameRobots(std::vector<SummarizeRobot>& robots) {
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
    r.robot = k == 1 ? name : fmt::format("{} ({})", name, k);
  }
}

}  // namespace

std::string SummarizeOptions::Check() const {
  if (inputs.empty()) return "inputs: give at least one calibrate JSON output (CAL)";
  if (auto e = fleet.Check(); !e.empty()) return "summarize: " + e;
  return {};
}

SummarizeResult Summarize(const SummarizeOptions& o) {
  if (const std::string err = o.Check(); !err.empty()) throw InvalidOptions(err);
  SummarizeResult out;
  out.files = o.inputs.size();
  out.threshold = o.fleet.threshold;
  for (const auto& path : DistinctInputs(o.inputs, out.warnings)) {
    auto more = ReadRobots(path);
    out.robots.insert(out.robots.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
  }
  NameRobots(out.robots);
  std::vector<FleetRobot> fr;
  for (const auto& r : out.robots) fr.push_back(r.fleet);
  out.fleet = SummarizeFleet(fr, o.fleet);
  if (out.fleet.groups > 1) {
    out.warnings.push_back(fmt::format(
        "the robots were recorded with {} different parameter sets (recorded_parameters: robot files); E_d, E_b and "
        "E_max_syst_m are relative to them and compared only between robots with the same set (at least 3); the "
        "corrected parameters are compared across the whole fleet",
        out.fleet.groups));
  }
  if (out.robots.size() < 3)
    out.warnings.push_back(fmt::format("{} robot(s): a fleet spread needs at least 3; no outliers are flagged", out.robots.size()));
  for (const auto& r : out.fleet.robots) out.outliers += r.outlier ? 1 : 0;
  return out;
}

nlohmann::json ToJson(const SummarizeResult& r) {
  const FleetSummary& s = r.fleet;
  nlohmann::json j;
  j["robots"] = nlohmann::json::array();
  for (std::size_t i = 0; i < r.robots.size(); ++i) {
    const SummarizeRobot& robot = r.robots[i];
    nlohmann::json z = nlohmann::json::object();
    for (const auto& [q, v] : s.robots[i].z) z[FleetQuantityKey(q)] = v;
    j["robots"].push_back({{"file", robot.fleet.file},
                           {"robot", robot.robot},
                           {"robot_id", robot.robot_id.empty() ? nlohmann::json(nullptr) : nlohmann::json(robot.robot_id)},
                           {"parameters", robot.parameters},
                           {"parameters_from", robot.parameters_from},
                           {"robust_z", z},
                           {"outlier", s.robots[i].outlier},
                           {"outlier_reasons", s.robots[i].reasons}});
  }
  j["fleet"] = nlohmann::json::object();
  for (const auto& [q, st] : s.fleet)
    j["fleet"][FleetQuantityKey(q)] = {{"n", st.n}, {"median", st.median}, {"mad", st.mad}, {"spread_used", st.spread}};
  j["threshold"] = r.threshold;
  j["outliers"] = r.outliers;
  j["warnings"] = r.warnings;
  return j;
}

std::string SummarizeCsv(const SummarizeResult& result) {
  const std::vector<SummarizeRobot>& robots = result.robots;
  const FleetSummary& s = result.fleet;
  std::string csv = "file,wheelbase_m,wheel_diameter_left_m,wheel_diameter_right_m,E_d,E_b,E_max_syst_m,residual_after_m,outlier,reasons,robot\n";
  for (std::size_t i = 0; i < robots.size(); ++i) {
    std::string row = io::CsvField(robots[i].fleet.file);
    for (FleetQuantity q : kFleetQuantities) {
      const auto it = robots[i].fleet.values.find(q);
      row += it == robots[i].fleet.values.end() ? "," : fmt::format(",{:.9g}", it->second);
    }
    std::string reasons;
    for (const auto& r : s.robots[i].reasons) reasons += (reasons.empty() ? "" : "; ") + r;
    row += fmt::format(",{},{},{}\n", s.robots[i].outlier ? "true" : "false", io::CsvField(reasons), io::CsvField(robots[i].robot));
    csv += row;
  }
  return csv;
}

}  // namespace umbmark::api
