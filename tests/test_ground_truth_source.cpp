// The ground-truth sources' one interface (lib/ground_truth/source.hpp): a
// source that exists in this test file only, registered here, drives the
// rosbag2 importer end to end without any library file knowing of it. Its
// ground truth is a pose moving at constant velocity and turn rate, which
// linear interpolation reproduces exactly, so every imported ground-truth
// sample has a closed form to check against.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "formats/robot_toml.hpp"
#include "ground_truth/source.hpp"
#include "import/rosbag2_import.hpp"

using namespace umbmark;
using namespace umbmark::io::rosbag2;
namespace fs = std::filesystem;

namespace {

const fs::path kBags = fs::path(UMBMARK_SOURCE_DIR) / "tests/data/rosbag2";

// The test pose at tau seconds after a run's first wheel sample: starts at
// (1 m, 2 m, 0.5 rad), moves (0.3, -0.1) m/s and turns one full turn
// counter-clockwise over the run.
constexpr double kX0 = 1.0, kY0 = 2.0, kYaw0 = 0.5, kVx = 0.3, kVy = -0.1;

// What the importer hands the source, for the test to look at.
struct Seen {
  std::size_t messages = 0, recordings = 0, runs = 0;
  std::string topic;
};

class LinearSource : public GroundTruthSource {
 public:
  LinearSource(const GroundTruthOptions& o, Seen& seen) : topic_(o.topic), seen_(seen) {}

  std::string Name() const override { return "the test's linear source"; }
  bool CheckAgainstOdometry() const override { return false; }
  // Asks for the --ground-truth topic in the importer's pass, only to count
  // what it is handed.
  std::vector<std::size_t> Open(const Bag& bag, std::size_t) override {
    const auto idx = bag.FindTopic(topic_);
    if (!idx) throw InputError(bag.path(), "no topic " + topic_);
    return {*idx};
  }
  void OnMessage(CdrReader&, const BagMessage&, const TopicInfo& topic, std::size_t index) override {
    ++messages_;
    seen_.topic = topic.name;
    CHECK(index == messages_);  // numbered 1, 2, ... in recording order
  }
  void EndOfPass(const Bag&, const std::string&, std::vector<std::string>&) override {}
  void ReadRuns(const Bag&, const RecordingRuns& runs, std::vector<std::string>& warnings) override {
    for (const auto& [a, b] : runs.spans) {
      const std::int64_t ta = runs.wheels[a].t_ns, tb = runs.wheels[b].t_ns;
      const double omega = 2.0 * kPi / (static_cast<double>(tb - ta) * 1e-9);
      std::vector<GroundTruthSample> s;
      for (std::int64_t t = ta - 1'000'000'000; t <= tb + 1'000'000'000; t += 5'000'000) {
        const double tau = static_cast<double>(t - ta) * 1e-9;
        s.push_back({t, kX0 + kVx * tau, kY0 + kVy * tau, kYaw0 + omega * tau});
      }
      runs_.push_back(std::move(s));
    }
    seen_.runs += runs.spans.size();
    warnings.push_back("the test source was here");
  }
  RunGroundTruth Run(std::size_t k) const override { return {&runs_.at(k), 6'000'000}; }
  std::size_t Messages() const override { return messages_; }
  void EndRecording() override {
    ++seen_.recordings;
    seen_.messages += messages_;
    messages_ = 0;
    runs_.clear();
  }
  GroundTruthExtras Finish() override {
    GroundTruthExtras x;
    x.noise = GroundTruthNoise{0.001, 0.002};
    x.manifest_keys = {{"source", std::string("linear_test")}};
    return x;
  }
 private:
  std::string topic_;
  Seen& seen_;
  std::size_t messages_ = 0;
  std::vector<std::vector<GroundTruthSample>> runs_;
};

Rosbag2ImportOptions Options() {
  Rosbag2ImportOptions o;
  o.kind = ExperimentKind::kSquare;
  o.side_m = 0.75;
  o.wheels_topic = "/joint_states";
  o.ground_truth_topic = "/mocap/pose";
  o.pause_s = 0.0;
  return o;
}

}  // namespace

TEST_CASE("A source registered from outside the library gives the imported runs their ground truth",
          "[ground_truth][rosbag2]") {
  Seen seen;
  LinearSource* made = nullptr;
  RegisterGroundTruthSource("linear_test", [&](const GroundTruthOptions& o) -> std::unique_ptr<GroundTruthSource> {
    auto s = std::make_unique<LinearSource>(o, seen);
    made = s.get();
    return s;
  });
  const auto names = GroundTruthSourceNames();
  CHECK(names == std::vector<std::string>{"linear_test", "scan", "topic"});

  const std::vector<std::string> bags = {(kBags / "square_run1.mcap").string(), (kBags / "square_run4.mcap").string()};
  const RobotParams robot = io::ReadRobotToml((kBags / "robot.toml").string());
  Rosbag2ImportOptions o = Options();
  o.ground_truth_source = "linear_test";
  const Rosbag2Import imp = ImportRosbag2(bags, robot, o);
  REQUIRE(made != nullptr);

  // The same runs as the motion capture gives (the wheels decide them); run 1
  // is clockwise and run 4 counter-clockwise by the motion capture, both
  // counter-clockwise by the test source.
  const Rosbag2Import mocap = ImportRosbag2(bags, robot, Options());
  REQUIRE(imp.runs.runs.size() == 2);
  REQUIRE(mocap.runs.runs.size() == 2);
  CHECK(mocap.runs.runs[0].direction == "cw");
  CHECK(mocap.runs.runs[1].direction == "ccw");
  for (std::size_t r = 0; r < 2; ++r) {
    const TrajectoryRun& run = imp.runs.runs[r];
    CHECK(run.direction == "ccw");
    REQUIRE(run.size() == mocap.runs.runs[r].size());
    CHECK(run.dist_left_m == mocap.runs.runs[r].dist_left_m);
    // Each sample: the closed form of the pose relative to the run's first,
    // in the first pose's frame.
    double worst = 0.0;
    const double w = 2.0 * kPi / (run.t_s.back() - run.t_s.front());
    for (std::size_t i = 0; i < run.size(); ++i) {
      const double tau = run.t_s[i] - run.t_s.front();
      const double dx = kVx * tau, dy = kVy * tau;
      const double ex = std::cos(kYaw0) * dx + std::sin(kYaw0) * dy;
      const double ey = -std::sin(kYaw0) * dx + std::cos(kYaw0) * dy;
      worst = std::max({worst, std::abs(run.gt_x_m[i] - ex), std::abs(run.gt_y_m[i] - ey),
                        std::abs(run.gt_theta_rad[i] - w * tau)});
    }
    CHECK(worst < 1e-9);
  }
  // Every message of the topic it asked for was handed to it, once per recording.
  CHECK(seen.topic == "/mocap/pose");
  CHECK(seen.recordings == 2);
  CHECK(seen.runs == 2);
  CHECK(seen.messages == mocap.recordings[0].ground_truth_messages + mocap.recordings[1].ground_truth_messages);
  CHECK(imp.recordings[0].ground_truth_messages == mocap.recordings[0].ground_truth_messages);
  // What it adds besides the poses reaches the result (and from there the manifest).
  REQUIRE(imp.ground_truth);
  CHECK(imp.ground_truth->sigma_xy_m == 0.001);
  CHECK(imp.ground_truth->sigma_theta_rad == 0.002);
  REQUIRE(imp.ground_truth_keys.size() == 1);
  CHECK(imp.ground_truth_keys[0].key == "source");
  CHECK(std::count(imp.warnings.begin(), imp.warnings.end(), "the test source was here") == 2);

  // Once unregistered, the name is refused, naming the field and what is registered.
  CHECK(UnregisterGroundTruthSource("linear_test"));
  CHECK_FALSE(UnregisterGroundTruthSource("linear_test"));
  try {
    ImportRosbag2(bags, robot, o);
    FAIL("an unregistered source was accepted");
  } catch (const InvalidOptions& e) {
    CHECK_THAT(e.what(), Catch::Contains("ground_truth_source = 'linear_test'") && Catch::Contains("scan, topic"));
  }
}
