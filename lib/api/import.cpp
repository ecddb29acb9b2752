// `import` as library calls (see import.hpp).
#include "api/import.hpp"

#include <cmath>
#include <filesystem>
#include <variant>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "api/json.hpp"
#include "core/errors.hpp"
#include "evaluation/data_warnings.hpp"
#include "formats/campaign_writer.hpp"

namespace umbmark::api {

namespace {

// The imported campaign as the folder `out`, written into a staging folder
// and renamed into place as a whole (io::WriteCampaign): a reader or an
// interrupted import sees the complete old folder or the complete new one,
// and with force no file of the previous campaign stays beside the new ones.
void WriteImportedCampaign(const RobotParams& robot, const Experiment& experiment, TrajectoryData runs,
                           const std::string& out, const std::vector<std::string>& comment, bool force,
                           const std::optional<GroundTruthNoise>& ground_truth = std::nullopt,
                           const std::vector<io::ManifestKey>& ground_truth_keys = {}) {
  Manifest m;
  m.robot = robot;
  m.experiments.push_back(experiment);
  m.ground_truth = ground_truth;
  io::WriteCampaign(m, {ExperimentData(std::move(runs))}, out, comment, {}, force, ground_truth_keys);
}

std::string CampaignFile(const std::string& out, const char* name) {
  return (std::filesystem::path(out) / name).string();
}

// --time as given: header|log, or WHEELS,GROUND_TRUTH when the two differ
// or were given apart.
std::string TimeText(const io::rosbag2::Rosbag2ImportOptions& o) {
  auto text = [](io::rosbag2::StampSource s) { return s == io::rosbag2::StampSource::kLog ? "log" : "header"; };
  return o.ground_truth_time ? fmt::format("{},{}", text(o.time), text(*o.ground_truth_time)) : text(o.time);
}

// The manifest's comment lines: where the campaign came from.
std::vector<std::string> Rosbag2Comment(const ImportRosbag2Options& options) {
  const io::rosbag2::Rosbag2ImportOptions& opt = options.import;
  const std::string time = TimeText(opt);
  std::vector<std::string> comment = {
      fmt::format("ROS 2 recording(s) {}, imported by umbmark import rosbag2", fmt::join(options.bags, ", ")),
      fmt::format("wheels: {} {}; ground truth: {}; time: {}", opt.wheels_topic.empty() ? "--odometry" : "--wheels",
                  opt.wheels_topic.empty() ? opt.odometry_topic : opt.wheels_topic,
                  opt.ground_truth_topic.empty() ? "none" : opt.ground_truth_topic, time)};
  if (!opt.scan_topic.empty()) comment[1] = fmt::format("wheels: {} {}; ground truth: lidar {} (scan registration){}; time: {}",
                                                        opt.wheels_topic.empty() ? "--odometry" : "--wheels",
                                                        opt.wheels_topic.empty() ? opt.odometry_topic : opt.wheels_topic,
                                                        opt.scan_topic, opt.imu_topic.empty() ? "" : ", gyro " + opt.imu_topic, time);
  return comment;
}

// The lidar's part of the JSON (with --scan).
nlohmann::json ScanJson(const io::rosbag2::Rosbag2Import& r) {
  const GroundTruthNoise& g = *r.ground_truth;
  nlohmann::json j = {{"sigma_xy_m", JsonNumber(g.sigma_xy_m)}, {"sigma_theta_rad", JsonNumber(g.sigma_theta_rad)}};
  for (const auto& k : io::rosbag2::ScanManifestKeys(r.scan)) {
    if (const double* v = std::get_if<double>(&k.value)) j[k.key] = JsonNumber(*v);
    else j[k.key] = std::get<std::string>(k.value);
  }
  nlohmann::json recs = nlohmann::json::array();
  for (const auto& rec : r.scan) {
    nlohmann::json runs = nlohmann::json::array();
    for (const auto& run : rec.runs) {
      const auto& t = run.track;
      nlohmann::json jr = {{"run", run.run},
                           {"still_scans_before", t.still_before},
                           {"still_scans_after", t.still_after},
                           {"chained_scans", t.chained},
                           {"keyframes", t.keyframes},
                           {"end_registered_on_start", t.end_direct},
                           {"end", {JsonNumber(t.end.x), JsonNumber(t.end.y), JsonNumber(t.end.theta)}},
                           {"end_sd", {JsonNumber(std::sqrt(t.end_covariance[0])), JsonNumber(std::sqrt(t.end_covariance[4])),
                                       JsonNumber(std::sqrt(t.end_covariance[8]))}},
                           {"still_scan_sd_xy_m", JsonNumber(t.still_sd_xy_m)},
                           {"still_scan_sd_theta_rad", JsonNumber(t.still_sd_theta_rad)},
                           {"moved_while_still", t.still_moved},
                           {"max_residual_sd_m", JsonNumber(t.max_residual_sd_m)}};
      if (!std::isnan(run.gyro_heading_change_rad)) jr["gyro_heading_change_rad"] = JsonNumber(run.gyro_heading_change_rad);
      runs.push_back(jr);
    }
    nlohmann::json jrec = {{"scan_frame", rec.scan_frame},
                           {"scans", rec.scans},
                           {"scan_pose", {JsonNumber(rec.mount.x), JsonNumber(rec.mount.y), JsonNumber(rec.mount.theta)}},
                           {"scan_pose_from", rec.mount_source},
                           {"scan_upside_down", rec.upside_down},
                           {"scan_time_offset_s", JsonNumber(rec.scan_time_offset_s)},
                           {"scan_clock_determined", rec.clock_determined},
                           {"runs", runs}};
    if (rec.mount_estimate.pairs > 0) {
      const auto& me = rec.mount_estimate;
      jrec["scan_pose_from_motion"] = {{"yaw_rad", JsonNumber(me.yaw_rad)},
                                       {"x_m", me.position_determined ? JsonNumber(me.x_m) : nlohmann::json()},
                                       {"y_m", me.position_determined ? JsonNumber(me.y_m) : nlohmann::json()},
                                       {"stretches", me.pairs}};
    }
    if (rec.gyro) {
      jrec["gyro_bias_rad_s"] = JsonNumber(rec.gyro->bias_rad_s);
      jrec["gyro_scale"] = JsonNumber(rec.gyro->scale);
      jrec["imu_messages"] = rec.imu_messages;
    }
    recs.push_back(jrec);
  }
  j["recordings"] = recs;
  return j;
}

}  // namespace

std::string ImportRosbag2Options::Check() const {
  if (bags.empty()) return "bags: give at least one recording (BAG)";
  if (out.empty()) return "--out OUTDIR is required (or --list to see the topics)";
  if (std::string err = import.Validate(); !err.empty()) return err;
  if (std::string err = robot.Check(); !err.empty()) return "robot parameters: " + err;
  return {};
}

ImportRosbag2Result ImportRosbag2(const ImportRosbag2Options& options) {
  if (const std::string err = options.Check(); !err.empty()) throw InvalidOptions(err);
  ImportRosbag2Result r;
  r.imported = io::rosbag2::ImportRosbag2(options.bags, options.robot, options.import);
  r.robot = options.robot;
  r.manifest = CampaignFile(options.out, "campaign.toml");
  r.runs_csv = CampaignFile(options.out, "runs.csv");
  const io::rosbag2::Rosbag2Import& imp = r.imported;
  WriteImportedCampaign(options.robot, imp.experiment, imp.runs, options.out, Rosbag2Comment(options), options.force,
                        imp.ground_truth, imp.ground_truth_keys);
  // Degenerate data (evaluation/data_warnings.hpp) join the importer's own warnings.
  r.warnings = imp.warnings;
  TrajectoryDataCheck check(options.robot);
  for (const auto& run : imp.runs.runs) check.Add(run);
  for (auto& w : check.Warnings(r.runs_csv)) r.warnings.push_back(std::move(w));
  return r;
}

nlohmann::json ToJson(const ImportRosbag2Result& result) {
  const io::rosbag2::Rosbag2Import& imp = result.imported;
  nlohmann::json recordings = nlohmann::json::array();
  for (const auto& r : imp.recordings)
    recordings.push_back({{"path", r.path},
                          {"runs_dropped", r.runs_dropped},
                          {"wheel_messages", r.wheel_messages},
                          {"ground_truth_messages", r.ground_truth_messages},
                          {"runs", r.runs},
                          {"left_joint", r.left_joint},
                          {"right_joint", r.right_joint},
                          {"duration_s", JsonNumber(r.duration_s)}});
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& r : imp.runs.runs) {
    std::size_t with_gt = 0;
    for (std::size_t i = 0; i < r.size(); ++i) with_gt += r.HasGroundTruth(i) ? 1 : 0;
    runs.push_back({{"run", r.run},
                    {"direction", r.direction},
                    {"samples", r.size()},
                    {"ground_truth_samples", with_gt},
                    {"t_start_s", JsonNumber(r.t_s.front())},
                    {"t_end_s", JsonNumber(r.t_s.back())},
                    {"dist_left_m", JsonNumber(r.dist_left_m.back())},
                    {"dist_right_m", JsonNumber(r.dist_right_m.back())}});
  }
  nlohmann::json j = {{"manifest", result.manifest},
                      {"runs_csv", result.runs_csv},
                      {"robot", JsonParams(result.robot)},
                      {"experiment", ExperimentKindToString(imp.experiment.kind)},
                      {"recordings", recordings},
                      {"runs", runs},
                      {"warnings", result.warnings}};
  if (!imp.scan.empty()) j["ground_truth"] = ScanJson(imp);
  return j;
}

nlohmann::json ToJson(const io::rosbag2::TopicListing& l) {
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& f : l.tf)
    frames.push_back({{"frame", f.edge.child},
                      {"parent", f.edge.parent},
                      {"static", f.edge.is_static},
                      {"messages", f.edge.count},
                      {"rate_hz", JsonNumber(f.edge.RateHz())},
                      {"through_odometry", f.through_odometry}});
  return {{"name", l.topic.name},
          {"type", l.topic.type},
          {"messages", l.topic.count},
          {"rate_hz", JsonNumber(l.topic.RateHz())},
          {"wheels", l.wheels},
          {"ground_truth", l.ground_truth},
          {"robot_odometry", l.robot_odometry},
          {"scan", l.scan},
          {"imu", l.imu},
          {"static", l.static_transforms},
          {"scan_pose", l.mount ? nlohmann::json{{"x_m", JsonNumber(l.mount->pose.x)}, {"y_m", JsonNumber(l.mount->pose.y)},
                                                 {"yaw_rad", JsonNumber(l.mount->pose.theta)},
                                                 {"upside_down", l.mount->upside_down},
                                                 {"base_frame", l.mount->base_frame}}
                                : nlohmann::json()},
          {"joints", l.joints},
          {"child_frames", l.frames},
          {"header_minus_receive_s", l.header_minus_receive_s ? JsonNumber(*l.header_minus_receive_s) : nlohmann::json()},
          {"frames", frames}};
}

std::string ImportOptiOdomOptions::Check() const {
  if (dir.empty()) return "dir: the OptiOdom dataset folder (DIR) is required";
  if (out.empty()) return "--out OUTDIR is required";
  if (!category.empty() && category != "square" && category != "circular" && category != "ivanjko" && category != "free")
    return fmt::format("category = '{}': --category must be square, circular, ivanjko or free", category);
  return {};
}

ImportOptiOdomResult ImportOptiOdom(const ImportOptiOdomOptions& options) {
  if (const std::string err = options.Check(); !err.empty()) throw InvalidOptions(err);
  std::optional<std::string> category;
  if (!options.category.empty()) category = options.category;
  ImportOptiOdomResult r;
  r.imported = io::ImportOptiOdom(options.dir, category);
  r.manifest = CampaignFile(options.out, "campaign.toml");
  r.runs_csv = CampaignFile(options.out, "runs.csv");
  const io::OptiOdomDataset& ds = r.imported;
  const std::string source = fmt::format("OptiOdom dataset {} ({}), imported by umbmark import optiodom", ds.id,
                                         ds.category);
  WriteImportedCampaign(ds.robot, ds.experiment, ds.runs, options.out, {source}, options.force);
  TrajectoryDataCheck check(ds.robot);
  for (const auto& run : ds.runs.runs) check.Add(run);
  r.warnings = check.Warnings(r.runs_csv);
  return r;
}

nlohmann::json ToJson(const ImportOptiOdomResult& result) {
  const io::OptiOdomDataset& ds = result.imported;
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& r : ds.runs.runs) runs.push_back({{"run", r.run}, {"direction", r.direction}, {"samples", r.size()}});
  return {{"dataset", ds.id},
          {"category", ds.category},
          {"manifest", result.manifest},
          {"runs_csv", result.runs_csv},
          {"robot", JsonParams(ds.robot)},
          {"experiment", {{"kind", ExperimentKindToString(ds.experiment.kind)}, {"side_m", ds.experiment.side_m}}},
          {"runs", runs},
          {"warnings", result.warnings}};
}

}  // namespace umbmark::api
