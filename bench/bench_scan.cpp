// Benchmark and accuracy table of `import rosbag2 --scan`: imports one
// recording twice, with the exact pose (/mocap/pose) and with the lidar
// (/scan, optional /imu), calibrates both on the same runs (UMBmark) and
// prints the largest return-error difference, the E_d / E_b differences,
// the gyro's bias and scale, and the scan import's CPU time and scans/s.
// bench/scan_bench.sh runs it on a generated 10-minute recording (6,000
// scans at 10 Hz) under /usr/bin/time -v for the peak memory.
//   bench_scan BAG ROBOT.toml SIDE [IMU_TOPIC|-] [X,Y,YAW]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <string>
#include <vector>

#include "calibration/umbmark.hpp"
#include "core/errors.hpp"
#include "evaluation/return_error.hpp"
#include "formats/robot_toml.hpp"
#include "import/rosbag2_import.hpp"

namespace {

double CpuSeconds() { return static_cast<double>(std::clock()) / CLOCKS_PER_SEC; }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: bench_scan BAG ROBOT.toml SIDE [IMU_TOPIC|-] [X,Y,YAW]\n");
    return 2;
  }
  using namespace umbmark;
  try {
    const RobotParams robot = io::ReadRobotToml(argv[2]);
    io::rosbag2::Rosbag2ImportOptions o;
    o.side_m = std::stod(argv[3]);
    o.wheels_topic = "/joint_states";
    o.ground_truth_topic = "/mocap/pose";
    const auto exact = io::rosbag2::ImportRosbag2({argv[1]}, robot, o);
    o.ground_truth_topic.clear();
    o.scan_topic = "/scan";
    if (argc > 4 && std::string(argv[4]) != "-") o.imu_topic = argv[4];
    if (argc > 5) {
      double x = 0, y = 0, t = 0;
      if (std::sscanf(argv[5], "%lf,%lf,%lf", &x, &y, &t) != 3) throw InvalidOptions("X,Y,YAW expected");
      o.scan_pose = Pose2{x, y, t};
    }
    const double cpu0 = CpuSeconds();
    const auto t0 = std::chrono::steady_clock::now();
    const auto lidar = io::rosbag2::ImportRosbag2({argv[1]}, robot, o);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const double cpu = CpuSeconds() - cpu0;
    std::size_t scans = 0;
    for (const auto& r : lidar.scan) scans += r.scans;
    std::printf("scan import: %zu scans, %zu runs, CPU %.2f s (%.0f scans/s), wall %.2f s\n", scans,
                lidar.runs.runs.size(), cpu, static_cast<double>(scans) / cpu, wall);
    const auto ea = ReturnErrorsFromTrajectories(exact.runs, robot, robot, Integrator::kArc);
    const auto eb = ReturnErrorsFromTrajectories(lidar.runs, robot, robot, Integrator::kArc);
    double dxy = 0.0, dth = 0.0;
    for (std::size_t k = 0; k < ea.size() && k < eb.size(); ++k) {
      dxy = std::max({dxy, std::abs(eb[k].ex_m - ea[k].ex_m), std::abs(eb[k].ey_m - ea[k].ey_m)});
      dth = std::max(dth, std::abs(*eb[k].etheta_rad - *ea[k].etheta_rad));
    }
    UmbmarkOptions uo;
    uo.side_m = o.side_m;
    const auto ca = CalibrateUmbmark(ea, robot, uo), cb = CalibrateUmbmark(eb, robot, uo);
    std::printf("runs %zu; max |return error difference| %.2f mm, %.3f mrad; E_d %.6f vs exact %.6f (diff %.1e); "
                "E_b %.6f vs exact %.6f (diff %.1e); sigma_xy %.2f mm, sigma_theta %.3f mrad\n",
                ea.size(), 1e3 * dxy, 1e3 * dth, cb.selected.E_d, ca.selected.E_d, cb.selected.E_d - ca.selected.E_d,
                cb.selected.E_b, ca.selected.E_b, cb.selected.E_b - ca.selected.E_b, 1e3 * lidar.ground_truth->sigma_xy_m,
                1e3 * lidar.ground_truth->sigma_theta_rad);
    for (const auto& r : lidar.scan)
      if (r.gyro) std::printf("gyro: bias %.6f rad/s, scale %.5f\n", r.gyro->bias_rad_s, r.gyro->scale);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
  return 0;
}
