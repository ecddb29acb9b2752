// `umbmark import optiodom DIR --out OUTDIR`: converts one OptiOdom dataset
// folder into the contract's campaign manifest (OUTDIR/campaign.toml) and
// trajectory CSV (OUTDIR/runs.csv).
// `umbmark import rosbag2 BAG... --out OUTDIR ...` does the same for ROS 2
// recordings (contract section "ROS 2 recordings"); `--list` shows topics.
#include <cmath>
#include <filesystem>
#include <memory>
#include <set>

#include <fmt/format.h>

#include "api/import.hpp"
#include "commands.hpp"
#include "common.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"
#include "import/optiodom.hpp"
#include "import/rosbag2_import.hpp"
#include "import/wheel_checks.hpp"

namespace umbmark::cli {

namespace {

struct ImportOptions {
  std::string dir;
  std::string out;
  std::string category;
  bool force = false;
  JsonFlag json;
};

// Registers an import's inputs (each path, and every file of a folder) and
// its output folder OUTDIR (runs.csv and campaign.toml; new or empty unless
// --force) plus --json with CommandOutputs(), and checks them (and takes the
// writer lock) before anything is read or written.
struct CampaignPaths {
  std::string runs, manifest;
};
CampaignPaths CheckImportOutputs(const std::vector<std::string>& inputs, const std::string& out, const JsonFlag& json,
                                 bool force) {
  namespace fs = std::filesystem;
  io::OutputSet& outs = CommandOutputs();
  for (const auto& in : inputs) {
    outs.AddInput(in);
    std::error_code ec;
    if (fs::is_directory(in, ec))
      for (const auto& entry : fs::directory_iterator(in, ec)) outs.AddInput(entry.path().string());
  }
  CampaignPaths p{(fs::path(out) / "runs.csv").string(), (fs::path(out) / "campaign.toml").string()};
  outs.AddOutputDirectory("--out", out, {"runs.csv", "campaign.toml"}, force);
  outs.AddOutput("--json", json.path);
  outs.Check();
  return p;
}

int RunImportOptiOdom(const ImportOptions& o) {
  // The output folder must not hold the dataset; the two files it gets must
  // not be other outputs.
  const auto [runs_path, manifest_path] = CheckImportOutputs({o.dir}, o.out, o.json, o.force);
  const api::ImportOptiOdomResult r = api::ImportOptiOdom({o.dir, o.category, o.out, o.force});
  const io::OptiOdomDataset& ds = r.imported;
  if (o.json.PrintText()) {
    std::size_t samples = 0;
    for (const auto& run : ds.runs.runs) samples += run.size();
    fmt::print("Imported OptiOdom dataset {} ({}): {} runs, {} samples\n", ds.id, ds.category, ds.runs.runs.size(),
               samples);
    fmt::print("  robot: wheelbase {} m, D_L {} m, D_R {} m, {} ticks/rev\n", ds.robot.wheelbase_m,
               ds.robot.wheel_diameter_left_m, ds.robot.wheel_diameter_right_m, *ds.robot.ticks_per_rev);
    if (ds.experiment.kind == ExperimentKind::kSquare) fmt::print("  experiment: square, side {} m\n", ds.experiment.side_m);
    for (const auto& run : ds.runs.runs) fmt::print("  run {:>3}  {:<9} {} samples\n", run.run, run.direction, run.size());
    for (const auto& w : r.warnings) fmt::print(stderr, "warning: {}\n", w);
    fmt::print("  wrote {}\n  wrote {}\n", manifest_path, runs_path);
  } else {
    for (const auto& w : r.warnings) fmt::print(stderr, "warning: {}\n", w);
  }
  o.json.Emit(api::ToJson(r));
  return 0;
}

struct Rosbag2Options {
  std::vector<std::string> bags;
  std::string out;
  bool list = false;
  std::string experiment;
  std::optional<double> side_m, distance_m;
  std::string integrator = "arc";
  std::string time = "header";
  std::string scan_pose;  ///< --scan-pose X,Y,YAW
  io::rosbag2::Rosbag2ImportOptions import;
  bool force = false;
  RobotFlags robot;
  JsonFlag json;
};

// --scan-pose X,Y,YAW (metres, metres, radians).
Pose2 ParseScanPose(const std::string& text) {
  std::vector<double> v;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    const std::string item = text.substr(pos, comma - pos);
    std::size_t used = 0;
    double x = 0.0;
    try {
      x = std::stod(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != item.size() || !std::isfinite(x))
      throw InvalidOptions(fmt::format("--scan-pose '{}': '{}' is not a number (expected X,Y,YAW in m, m, rad)", text, item));
    v.push_back(x);
    pos = comma + 1;
  }
  if (v.size() != 3) throw InvalidOptions(fmt::format("--scan-pose '{}': expected three numbers X,Y,YAW (m, m, rad)", text));
  return {v[0], v[1], v[2]};
}

// What the lidar and gyro gave: per recording the lidar pose and gyro, per
// run the registration (readable summary of `import rosbag2 --scan`).
void PrintScanSummary(const io::rosbag2::Rosbag2Import& r) {
  if (!r.ground_truth || r.scan.empty()) return;
  const GroundTruthNoise& g = *r.ground_truth;
  for (const auto& rec : r.scan) {
    fmt::print("  lidar {}: {} scans; pose in the robot frame x {:.4f} m, y {:.4f} m, yaw {:.4f} rad ({})\n",
               rec.scan_frame, rec.scans, rec.mount.x, rec.mount.y, rec.mount.theta, rec.mount_source);
    const auto& me = rec.mount_estimate;
    if (me.pairs > 0)
      fmt::print("  mount as the scans and the wheels see it: yaw {:.4f} rad{} ({} stretches, {:.1f} m, {:.1f} rad)\n",
                 me.yaw_rad, me.position_determined ? fmt::format(", x {:.3f} m, y {:.3f} m", me.x_m, me.y_m) : std::string(),
                 me.pairs, me.straight_m, me.turned_rad);
    if (rec.clock_determined)
      fmt::print("  scan clock: header.stamp minus first ray {:+.3f} s (the scans' range changes follow the wheels with "
                 "correlation {:.2f})\n", rec.scan_time_offset_s, rec.clock_correlation);
    if (rec.gyro)
      fmt::print("  gyro: bias {:.6f} rad/s (+- {:.1e}, {} still readings), scale {:.5f} (measured / true yaw rate)\n",
                 rec.gyro->bias_rad_s, rec.gyro->bias_sd_rad_s, rec.gyro->still_samples, rec.gyro->scale);
    for (const auto& run : rec.runs) {
      const auto& t = run.track;
      fmt::print("  run {:>3}  scans: {} still before, {} after, {} chained ({} keyframes); end {} the start: "
                 "x {:+.4f} m, y {:+.4f} m, heading {:+.5f} rad (sd {:.2f} mm, {:.3f} mrad){}\n",
                 run.run, t.still_before, t.still_after, t.chained, t.keyframes, t.end_direct ? "registered on" : "chained to",
                 t.end.x, t.end.y, t.end.theta, 1e3 * std::sqrt(0.5 * (t.end_covariance[0] + t.end_covariance[4])),
                 1e3 * std::sqrt(t.end_covariance[8]),
                 std::isnan(run.gyro_heading_change_rad) ? std::string()
                                                         : fmt::format("; gyro {:+.5f} rad", run.gyro_heading_change_rad));
    }
  }
  fmt::print("  ground truth from the scans: noise per pose {:.2f} mm, {:.3f} mrad (in the manifest's [ground_truth])\n",
             1e3 * g.sigma_xy_m, 1e3 * g.sigma_theta_rad);
}

// One topic row of --list, and below a TFMessage topic its frames (parent,
// rate, whether the odometry frame is in its chain): enough to choose every
// flag of the import from the listing alone.
void PrintListedTopic(const io::rosbag2::TopicListing& l) {
  constexpr std::size_t kMaxFrames = 60;
  std::string use;
  if (l.wheels) use = l.topic.type == "sensor_msgs/msg/JointState" ? "--wheels" : "--odometry";
  if (l.ground_truth) use += use.empty() ? "--ground-truth" : ", --ground-truth";
  if (l.robot_odometry) use += fmt::format(" (frame {}: the robot's own odometry, not ground truth)", l.frame_id);
  if (l.scan) use = "--scan (the lidar as ground truth)";
  if (l.scan && l.mount)
    use += fmt::format("; mount x {:.3f} m, y {:.3f} m, yaw {:.3f} rad{} ({} -> {})", l.mount->pose.x, l.mount->pose.y,
                       l.mount->pose.theta, l.mount->upside_down ? ", upside down" : "", l.mount->base_frame, l.frame_id);
  else if (l.scan)
    use += fmt::format("; frame {} has no static transform: give --scan-pose X,Y,YAW", l.frame_id);
  if (l.imu) use = "--imu (gyro, with --scan)";
  if (l.static_transforms) use = "the lidar's mount (--tf-static)";
  if (!l.joints.empty()) use += fmt::format(" (joints: {})", io::rosbag2::TrimmedList(l.joints, 30));
  if (!l.tf.empty() && !l.static_transforms) use += " with --ground-truth-frame FRAME:";
  const std::string lag = l.header_minus_receive_s ? fmt::format("{:+.3f}", *l.header_minus_receive_s) : std::string();
  const std::string topic_rate = l.static_transforms ? std::string("static") : fmt::format("{:.1f}", l.topic.RateHz());
  fmt::print("  {:<28} {:<44} {:>9} {:>9} {:>12}  {}\n", l.topic.name, l.topic.type, l.topic.count, topic_rate, lag, use);
  for (std::size_t i = 0; i < l.tf.size() && i < kMaxFrames; ++i) {
    const auto& f = l.tf[i];
    const std::string rate = f.edge.is_static ? std::string("static") : fmt::format("{:.1f} Hz", f.edge.RateHz());
    fmt::print("      frame {:<24} parent {:<20} {:>10}  {}\n", f.edge.child, f.edge.parent, rate,
               !f.through_odometry.empty()
                   ? fmt::format("odometry (chain runs through '{}'): not ground truth", f.through_odometry)
               : f.edge.is_static ? std::string("fixed offset (composed when chosen)")
                                  : std::string("ground-truth candidate"));
  }
  if (l.tf.size() > kMaxFrames) fmt::print("      ... and {} more frames (--json lists them all)\n", l.tf.size() - kMaxFrames);
}

// Usable topics first (at most 200), then the others (at most 40), so
// that 200,000 camera topics do not bury the wheel and ground-truth ones.
int RunRosbag2List(const Rosbag2Options& o) {
  constexpr std::size_t kMaxUsable = 200, kMaxOther = 40;
  io::OutputSet& outs = CommandOutputs();
  for (const auto& bag : o.bags) outs.AddInput(bag);
  outs.AddOutput("--json", o.json.path);
  outs.Check();
  nlohmann::json bags = nlohmann::json::array();
  std::vector<std::string> warnings;
  for (const auto& path : o.bags) {
    const auto listing = io::rosbag2::ListRosbag2(path, warnings);
    nlohmann::json topics = nlohmann::json::array();
    if (o.json.PrintText()) {
      fmt::print("{} ({} storage file{}: {})\n", path, listing.files.size(), listing.files.size() == 1 ? "" : "s",
                 io::rosbag2::TrimmedList(listing.files, 10));
      fmt::print("  {:<28} {:<44} {:>9} {:>9} {:>12}  use as\n", "topic", "type", "messages", "rate Hz", "stamp-recv s");
    }
    std::size_t usable = 0, other = 0, omitted = 0;
    for (const bool want_usable : {true, false})
      for (const auto& l : listing.topics) {
        const bool is_usable = l.wheels || l.ground_truth || l.scan || l.imu || l.static_transforms;
        if (is_usable != want_usable) continue;
        if (is_usable ? usable++ >= kMaxUsable : other++ >= kMaxOther) {
          ++omitted;
          continue;
        }
        if (o.json.PrintText()) PrintListedTopic(l);
        topics.push_back(api::ToJson(l));
      }
    if (omitted > 0 && o.json.PrintText())
      fmt::print("  ... and {} more topics not listed ({} usable as wheels or ground truth)\n", omitted,
                 usable > kMaxUsable ? usable - kMaxUsable : 0);
    bags.push_back({{"path", path}, {"files", listing.files}, {"topics", topics}, {"topics_not_listed", omitted}});
  }
  if (o.json.PrintText()) {
    for (const auto& w : warnings) fmt::print(stderr, "warning: {}\n", w);
    fmt::print("stamp-recv: header stamp minus receive time of the first message; topics far apart were stamped by "
               "different clocks (--time WHEELS,GROUND_TRUTH)\n");
    fmt::print("Next: umbmark import rosbag2 BAG --out DIR --experiment square --side S --robot R.toml "
               "--wheels TOPIC [--left-joint J --right-joint J] --ground-truth TOPIC [--ground-truth-frame FRAME]\n"
               "  or, without motion capture: ... --wheels TOPIC --scan TOPIC [--imu TOPIC] [--tf-static TOPIC] "
               "(docs/ros2.md, \"Recording a calibration bag without motion capture\")\n");
  }
  o.json.Emit({{"bags", bags}, {"warnings", warnings}});
  return 0;
}

// Options to the library's, output checks, import, write, then the text and
// JSON summaries of what was read (long only because of the printing).
int RunRosbag2(Rosbag2Options o) {
  if (o.list) return RunRosbag2List(o);
  if (o.out.empty()) throw InvalidOptions("--out OUTDIR is required (or --list to see the topics)");
  if (o.experiment.empty()) throw InvalidOptions("--experiment square|back_and_forth|free is required");
  auto& opt = o.import;
  opt.kind = o.experiment == "square" ? ExperimentKind::kSquare
             : o.experiment == "back_and_forth" ? ExperimentKind::kBackAndForth
                                                : ExperimentKind::kFree;
  opt.side_m = o.side_m.value_or(0.0);
  opt.distance_m = o.distance_m.value_or(0.0);
  opt.integrator = *IntegratorFromString(o.integrator);
  // --time header|log for both streams, or WHEELS,GROUND_TRUTH.
  const auto comma = o.time.find(',');
  auto stamp = [](const std::string& s) {
    return s == "log" ? io::rosbag2::StampSource::kLog : io::rosbag2::StampSource::kHeader;
  };
  opt.time = stamp(o.time.substr(0, comma));
  if (comma != std::string::npos) opt.ground_truth_time = stamp(o.time.substr(comma + 1));
  if (!o.scan_pose.empty()) opt.scan_pose = ParseScanPose(o.scan_pose);
  const RobotParams robot = o.robot.Resolve();
  // The recordings (and every file of a bag folder) are inputs; the two
  // files written must not be one of them or another output.
  const auto [runs_path, manifest_path] = CheckImportOutputs(o.bags, o.out, o.json, o.force);
  const api::ImportRosbag2Result imported = api::ImportRosbag2({o.bags, opt, robot, o.out, o.force});
  const io::rosbag2::Rosbag2Import& result = imported.imported;
  if (o.json.PrintText()) {
    for (const auto& r : result.recordings) {
      fmt::print("{}: {} wheel messages, {} ground-truth poses, {:.1f} s, {} run(s){}\n", r.path, r.wheel_messages,
                 r.ground_truth_messages, r.duration_s, r.runs,
                 r.left_joint.empty() ? "" : fmt::format(" (joints {} / {})", r.left_joint, r.right_joint));
    }
    for (const auto& r : result.runs.runs)
      fmt::print("  run {:>3}  {:<14} {:>6} samples  t {:8.2f} .. {:8.2f} s  travel L {:7.3f} m  R {:7.3f} m\n", r.run,
                 r.direction, r.size(), r.t_s.front(), r.t_s.back(), r.dist_left_m.back(), r.dist_right_m.back());
    PrintScanSummary(result);
    for (const auto& w : imported.warnings) fmt::print(stderr, "warning: {}\n", w);
    fmt::print("  wrote {}\n  wrote {}\nNext: umbmark calibrate {} (squares) or umbmark fit-noise {}\n", manifest_path,
               runs_path, manifest_path, manifest_path);
  }
  o.json.Emit(api::ToJson(imported));
  return 0;
}

// --time: header, log, or WHEELS,GROUND_TRUTH of those two (the help shows
// the choices as written, not CLI11's expansion of a member list).
CLI::Validator TimeChoice() {
  return CLI::Validator(
      [](std::string& v) -> std::string {
        static const std::set<std::string> ok = {"header", "log", "header,log", "log,header", "header,header", "log,log"};
        return ok.count(v) > 0 ? std::string()
                               : fmt::format("--time '{}': expected header, log, or WHEELS,GROUND_TRUTH (e.g. header,log)", v);
      },
      "header|log|WHEELS,GROUND_TRUTH");
}

}  // namespace

Command SetupImport(CLI::App& parent) {
  auto* imp = parent.add_subcommand("import", "Convert external datasets to the umbmark formats");
  imp->require_subcommand(1);
  auto opts = std::make_shared<ImportOptions>();
  auto* od = imp->add_subcommand("optiodom", "Convert one OptiOdom dataset folder to OUTDIR/campaign.toml + runs.csv");
  od->add_option("DIR", opts->dir, "Dataset folder (<id>_metadata.csv + <id>_run-NN.csv)")
      ->required()
      ->check(CLI::ExistingDirectory);
  od->add_option("--out", opts->out, "Output directory")->required();
  od->add_option("--category", opts->category,
                 "Dataset category (square|circular|ivanjko|free); default: the parent folder's name")
      ->check(CLI::IsMember({"square", "circular", "ivanjko", "free"}));
  od->add_flag("--force", opts->force, "Replace a non-empty --out folder (and everything in it)");
  opts->json.Bind(*od);

  auto ro = std::make_shared<Rosbag2Options>();
  auto* rb = imp->add_subcommand("rosbag2", "Convert ROS 2 recordings (rosbag2: MCAP or SQLite3) to OUTDIR/campaign.toml + "
                                            "runs.csv, or --list their topics");
  rb->add_option("BAG", ro->bags, "rosbag2 folder (metadata.yaml + .mcap/.db3 files) or a single .mcap/.db3 file; "
                                  "several are read in order, runs numbered across them")
      ->required();
  rb->add_flag("--list", ro->list, "Print every topic with type, message count and rate, and what it can serve as; write nothing");
  rb->add_option("--out", ro->out, "Output directory");
  rb->add_flag("--force", ro->force, "Replace a non-empty --out folder (and everything in it)");
  rb->add_option("--experiment", ro->experiment, "Experiment kind")->check(CLI::IsMember({"square", "back_and_forth", "free"}));
  rb->add_option("--side", ro->side_m, "Square side [m] (square)")->check(Plausible("side_m"));
  rb->add_option("--distance", ro->distance_m, "Leg length [m] (back_and_forth)")->check(Plausible("distance_m"));
  auto* wheels = rb->add_option("--wheels", ro->import.wheels_topic, "sensor_msgs/msg/JointState topic with the wheel positions [rad]");
  auto* odom = rb->add_option("--odometry", ro->import.odometry_topic,
                              "nav_msgs/msg/Odometry topic as the robot computed it (inverted with the wheelbase)");
  wheels->excludes(odom);
  rb->add_option("--left-joint", ro->import.left_joint, "Left wheel joint (default: the only joint named *left*)")->needs(wheels);
  rb->add_option("--right-joint", ro->import.right_joint, "Right wheel joint (default: the only joint named *right*)")->needs(wheels);
  rb->add_option("--ground-truth", ro->import.ground_truth_topic,
                 "Ground-truth pose topic: PoseStamped, PoseWithCovarianceStamped, Odometry or TFMessage");
  rb->add_option("--ground-truth-frame", ro->import.ground_truth_frame, "TFMessage: the child_frame_id to follow");
  auto* scan = rb->add_option("--scan", ro->import.scan_topic,
                              "Ground truth from the robot's lidar instead: sensor_msgs/msg/LaserScan topic (scan registration)");
  rb->add_option("--scan-pose", ro->scan_pose,
                 "The lidar's pose in the robot frame X,Y,YAW [m, m, rad] when /tf_static does not give it")->needs(scan);
  rb->add_flag("--scan-upside-down", ro->import.scan_upside_down,
               "The lidar is mounted upside down (its beam angles run mirrored), when /tf_static does not say so")
      ->needs(scan);
  rb->add_option("--tf-static", ro->import.tf_static_topic,
                 "tf2_msgs/msg/TFMessage topic with the lidar's mounting transform (default /tf_static, or the only "
                 "topic named .../tf_static, e.g. /robot1/tf_static)")
      ->needs(scan);
  rb->add_option("--imu", ro->import.imu_topic,
                 "sensor_msgs/msg/Imu topic: gyro bias and scale against the scans, a second heading reference")->needs(scan);
  scan->excludes(rb->get_option("--ground-truth"));
  rb->add_option("--time", ro->time,
                 "Time stamps: header (header.stamp) or log (receive time), for both streams; or WHEELS,GROUND_TRUTH "
                 "(e.g. header,log: the wheels by header stamp, the ground truth by receive time)")
      ->capture_default_str()
      ->check(TimeChoice());
  rb->add_option("--integrator", ro->integrator, "Integrator the robot's /odom used (for --odometry)")
      ->capture_default_str()
      ->check(CLI::IsMember({"arc", "midpoint"}));
  rb->add_option("--pause", ro->import.pause_s, "Split runs where both wheels stand still this long [s]; 0 = one run per recording")
      ->capture_default_str()
      ->check(NonNegative());
  rb->add_option("--max-gt-gap", ro->import.max_gt_gap_s,
                 "Interpolate ground truth only between poses at most this far from the sample [s]")
      ->capture_default_str()
      ->check(Positive());
  ro->robot.Bind(*rb);
  ro->json.Bind(*rb);
  return {imp, [opts, ro, rb] {
            if (rb->parsed()) return RunRosbag2(*ro);
            return RunImportOptiOdom(*opts);
          }};
}

}  // namespace umbmark::cli
