// Benchmark of `import rosbag2`: imports one recording (JointState wheels on
// /joint_states, PoseStamped ground truth on /mocap/pose) and prints input
// MB/s and decoded messages/s. bench/rosbag2_bench.sh generates a >= 1 GB
// recording and runs this next to the Node reader (@mcap/core +
// @foxglove/rosmsg2-serialization) decoding the same two topics.
//   bench_rosbag2 BAG ROBOT.toml
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/errors.hpp"
#include "formats/robot_toml.hpp"
#include "import/rosbag2_import.hpp"

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: bench_rosbag2 BAG ROBOT.toml\n");
    return 2;
  }
  using namespace umbmark;
  try {
    const RobotParams robot = io::ReadRobotToml(argv[2]);
    io::rosbag2::Rosbag2ImportOptions o;
    o.kind = ExperimentKind::kFree;
    o.wheels_topic = "/joint_states";
    o.ground_truth_topic = "/mocap/pose";
    const auto t0 = std::chrono::steady_clock::now();
    const auto r = io::rosbag2::ImportRosbag2({argv[1]}, robot, o);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double mb = static_cast<double>(std::filesystem::file_size(argv[1])) / 1e6;
    std::size_t msgs = 0, samples = 0;
    for (const auto& rec : r.recordings) msgs += rec.wheel_messages + rec.ground_truth_messages;
    for (const auto& run : r.runs.runs) samples += run.size();
    std::printf("umbmark: %.1f MB in %.3f s = %.1f MB/s, %zu messages decoded = %.0f messages/s, %zu runs, %zu samples\n",
                mb, s, mb / s, msgs, static_cast<double>(msgs) / s, r.runs.runs.size(), samples);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
