// Campaign manifest reader (TOML): [robot], [[experiment]] (kind, side_m /
// distance_m, file relative to the manifest), optional [ground_truth].
#include "formats/manifest.hpp"

#include <cmath>
#include <filesystem>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "core/errors.hpp"
#include "core/plausible_units.hpp"
#include "formats/file_text.hpp"
#include "formats/robot_toml.hpp"
#include "formats/toml_util.hpp"

namespace umbmark::io {
namespace {

using detail::FailAt;

const toml::table& RequireTable(const toml::table& root, std::string_view key, const std::string& name) {
  const toml::node* node = root.get(key);
  if (node == nullptr) throw InputError(name, fmt::format("missing [{}] table", key));
  const toml::table* table = node->as_table();
  if (table == nullptr) FailAt(name, node->source(), fmt::format("{} must be a table, not {}", key, detail::TypeName(*node)));
  return *table;
}

/// A number > 0 (side_m, distance_m) at `node`.
double PositiveValue(const toml::node& node, std::string_view key, const std::string& name) {
  const double v = detail::NumberValue(node, key, name);
  if (!(v > 0.0)) FailAt(name, node.source(), fmt::format("{} = {} must be > 0", key, v));
  if (const std::string problem = ImplausibleValue(key, v); !problem.empty()) FailAt(name, node.source(), problem);
  return v;
}

Experiment ReadExperiment(const toml::table& t, std::size_t number, const std::filesystem::path& base,
                          const std::string& name) {
  detail::RejectUnknownKeys(t, {"kind", "side_m", "distance_m", "file"}, fmt::format("experiment {}", number), name);
  Experiment e;
  const toml::node* kind = t.get("kind");
  if (kind == nullptr) FailAt(name, t.source(), fmt::format("experiment {}: missing key 'kind'", number));
  const std::string kind_text = detail::StringValue(*kind, "kind", name);
  if (kind_text == "square") {
    e.kind = ExperimentKind::kSquare;
  } else if (kind_text == "back_and_forth") {
    e.kind = ExperimentKind::kBackAndForth;
  } else if (kind_text == "free") {
    e.kind = ExperimentKind::kFree;
  } else {
    FailAt(name, kind->source(),
           fmt::format("experiment {}: unknown kind '{}' (expected square, back_and_forth or free)", number,
                       kind_text));
  }

  // side_m belongs to squares, distance_m to back_and_forth, and each is
  // required there; elsewhere it is a mistake worth reporting.
  const struct {
    const char* key;
    ExperimentKind kind;
    double* target;
  } sizes[] = {{"side_m", ExperimentKind::kSquare, &e.side_m},
               {"distance_m", ExperimentKind::kBackAndForth, &e.distance_m}};
  for (const auto& s : sizes) {
    const toml::node* node = t.get(s.key);
    if (s.kind == e.kind) {
      if (node == nullptr) {
        FailAt(name, t.source(), fmt::format("experiment {} (kind = \"{}\"): missing key '{}'", number, kind_text,
                                             s.key));
      }
      *s.target = PositiveValue(*node, s.key, name);
    } else if (node != nullptr) {
      FailAt(name, node->source(),
             fmt::format("experiment {}: {} is only for kind = \"{}\", not \"{}\"", number, s.key,
                         ExperimentKindToString(s.kind), kind_text));
    }
  }

  const toml::node* file = t.get("file");
  if (file == nullptr) FailAt(name, t.source(), fmt::format("experiment {}: missing key 'file'", number));
  e.file = detail::StringValue(*file, "file", name);
  if (e.file.empty()) FailAt(name, file->source(), fmt::format("experiment {}: file is empty", number));
  // A NUL byte would end the path for the operating system: "a.csv\0b"
  // would read a.csv, another file than the one written.
  if (const auto nul = e.file.find('\0'); nul != std::string::npos) {
    FailAt(name, file->source(),
           fmt::format("experiment {}: file contains a NUL byte (\\u0000 at character {}); a path cannot hold one",
                       number, nul + 1));
  }
  const std::filesystem::path file_path(e.file);
  e.resolved_file = file_path.is_absolute() || base.empty() ? e.file : (base / file_path).string();
  return e;
}

// The keys an importer adds to [ground_truth] (`import rosbag2 --scan`,
// docs/formats.md): checked for their type, not used by the computations.
void CheckImportedGroundTruthKeys(const toml::table& gt, const std::string& path) {
  for (const char* key : {"source", "scan_pose_from"})
    if (const toml::node* n = gt.get(key)) detail::StringValue(*n, key, path);
  for (const char* key : {"scan_pose_x_m", "scan_pose_y_m", "scan_pose_yaw_rad", "scan_time_offset_s", "gyro_bias_rad_s",
                          "gyro_scale"}) {
    if (const toml::node* n = gt.get(key)) {
      const double v = detail::NumberValue(*n, key, path);
      if (!std::isfinite(v)) FailAt(path, n->source(), fmt::format("{} = {} must be finite", key, v));
    }
  }
}

}  // namespace

Manifest ParseManifest(std::string_view text, const std::string& path) {
  const toml::table root = detail::ParseTomlText(text, path);
  detail::RejectUnknownKeys(root, {"robot", "experiment", "ground_truth"}, "the manifest", path);

  Manifest m;
  m.path = path;
  m.robot = RobotFromTable(RequireTable(root, "robot", path), path);

  const toml::node* experiments = root.get("experiment");
  if (experiments == nullptr) throw InputError(path, "no [[experiment]] tables");
  const toml::array* list = experiments->as_array();
  if (list == nullptr) {
    FailAt(path, experiments->source(),
           fmt::format("experiment must be an array of tables ([[experiment]]), not {}", detail::TypeName(*experiments)));
  }
  if (list->empty()) FailAt(path, experiments->source(), "no experiments in the experiment array");
  const std::filesystem::path base = std::filesystem::path(path).parent_path();
  std::size_t number = 0;
  for (const toml::node& node : *list) {
    ++number;
    const toml::table* t = node.as_table();
    if (t == nullptr) {
      FailAt(path, node.source(), fmt::format("experiment {} must be a table, not {}", number, detail::TypeName(node)));
    }
    m.experiments.push_back(ReadExperiment(*t, number, base, path));
  }

  if (root.contains("ground_truth")) {
    const toml::table& gt = RequireTable(root, "ground_truth", path);
    detail::RejectUnknownKeys(gt, {"sigma_xy_m", "sigma_theta_rad", "source", "scan_pose_x_m", "scan_pose_y_m",
                                   "scan_pose_yaw_rad", "scan_pose_from", "scan_time_offset_s", "gyro_bias_rad_s",
                                   "gyro_scale"},
                              "[ground_truth]", path);
    CheckImportedGroundTruthKeys(gt, path);
    GroundTruthNoise noise;
    const struct {
      const char* key;
      double* target;
    } sigmas[] = {{"sigma_xy_m", &noise.sigma_xy_m}, {"sigma_theta_rad", &noise.sigma_theta_rad}};
    for (const auto& s : sigmas) {
      // Both are required when the table is given: a silent 0 for the other
      // would claim noise-free ground truth.
      const toml::node* node = gt.get(s.key);
      if (node == nullptr) FailAt(path, gt.source(), fmt::format("[ground_truth]: missing key '{}'", s.key));
      *s.target = detail::NumberValue(*node, s.key, path);
      if (*s.target < 0.0) FailAt(path, node->source(), fmt::format("{} = {} must be >= 0", s.key, *s.target));
      // Ground truth off by more than a metre or a radian is no ground truth
      // (1e308 would make every simulated pose infinite).
      if (*s.target > 1.0)
        FailAt(path, node->source(), fmt::format("{} = {:g} is more than 1 (metre or radian): no ground truth is that "
                                                 "noisy; give it in metres and radians",
                                                 s.key, *s.target));
    }
    m.ground_truth = noise;
  }
  return m;
}

Manifest ReadManifest(const std::string& path) { return ParseManifest(ReadWholeFile(path), path); }

std::string ReadGroundTruthSource(const std::string& path) {
  const toml::table root = detail::ParseTomlText(ReadWholeFile(path), path);
  const toml::table* gt = root.get_as<toml::table>("ground_truth");
  const toml::node* n = gt ? gt->get("source") : nullptr;
  return n ? detail::StringValue(*n, "source", path) : std::string();
}

bool IsManifestPath(const std::string& path) {
  return path.size() >= 5 && path.compare(path.size() - 5, 5, ".toml") == 0;
}

}  // namespace umbmark::io
