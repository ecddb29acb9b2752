// Side-by-side comparison of 2-D scan registrations on the same scan pairs:
// umbmark's point-to-line ICP (lib/scan), MRPT's CICP (icpClassic and
// icpLevenbergMarquardt, mrpt-slam) and Open3D's ICP (point-to-point, and
// point-to-plane with the 2-D normals given). Not part of the build or CI
// (MRPT and Open3D are large); bench/scan_compare/run.sh builds and runs it.
// Pairs from a recording with exact poses (/mocap/pose, scan_gen.mjs):
//   still  the averaged still scans after each run against those before it
//          (what a run's return error is made of);
//   chain  each scan while moving against the scan 0.5 s before it.
// Every method starts from the truth moved by (dx, dy, dtheta) = (4 cm,
// -3 cm, 0.04 rad). Prints per method and pair kind: RMS position and
// heading error, failures (error > 5 cm or 0.05 rad), microseconds per pair.
//   scan_compare BAG X,Y,YAW(lidar mount)
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPosePDF.h>
#include <mrpt/slam/CICP.h>
#include <open3d/Open3D.h>

#include "ros2/bag.hpp"
#include "ros2/messages.hpp"
#include "ros2/scan_messages.hpp"
#include "scan/scan_matcher.hpp"

using namespace umbmark;
using umbmark::scan::LaserScan;
using umbmark::scan::Point2;

namespace {

struct Pair {
  std::string kind;
  LaserScan model, scan;
  Pose2 truth;  // model_T_scan (lidar frames)
};

struct Stamped {
  std::int64_t t;
  Pose2 p;
};

Pose2 At(const std::vector<Stamped>& g, std::int64_t t) {
  std::size_t k = 1;
  while (k + 1 < g.size() && g[k].t < t) ++k;
  const double u = static_cast<double>(t - g[k - 1].t) / static_cast<double>(g[k].t - g[k - 1].t);
  const Pose2& a = g[k - 1].p;
  const Pose2& b = g[k].p;
  return {a.x + u * (b.x - a.x), a.y + u * (b.y - a.y), a.theta + u * WrapAngle(b.theta - a.theta)};
}

// Scans, mocap and still stretches (the wheels' pauses are where the mocap stands still).
std::vector<Pair> ReadPairs(const std::string& path, const Pose2& mount) {
  std::vector<std::string> w;
  const auto bag = io::rosbag2::Bag::Open(path, w);
  std::vector<bool> wanted(bag.topics().size(), false);
  const auto scan_t = *bag.FindTopic("/scan"), gt_t = *bag.FindTopic("/mocap/pose");
  wanted[scan_t] = wanted[gt_t] = true;
  std::vector<LaserScan> scans;
  std::vector<Stamped> gt;
  bag.Read(wanted, [&](const io::rosbag2::BagMessage& m) {
    io::rosbag2::CdrReader r(m.data, m.size);
    if (m.topic == scan_t) {
      LaserScan s;
      std::string_view f;
      io::rosbag2::DecodeLaserScan(r, s, f);
      scans.push_back(s);
    } else {
      const auto p = io::rosbag2::DecodePoseStamped(r);
      gt.push_back({p.header.stamp_ns, {p.x, p.y, p.Yaw()}});
    }
  });
  std::vector<Pose2> lidar;
  std::vector<bool> still;
  for (const auto& s : scans) {
    lidar.push_back(Compose(At(gt, s.t_ns), mount));
    const Pose2 a = At(gt, s.t_ns - 150000000), b = At(gt, s.t_ns + 150000000);
    still.push_back(std::hypot(a.x - b.x, a.y - b.y) < 1e-6 && std::abs(a.theta - b.theta) < 1e-6);
  }
  std::vector<Pair> pairs;
  // Still groups: consecutive still scans at one pose.
  std::vector<std::vector<std::size_t>> groups;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    if (!still[i]) continue;
    if (groups.empty() || i != groups.back().back() + 1) groups.emplace_back();
    groups.back().push_back(i);
  }
  for (std::size_t g = 1; g < groups.size(); ++g) {
    std::vector<const LaserScan*> a, b;
    for (auto i : groups[g - 1]) a.push_back(&scans[i]);
    for (auto i : groups[g]) b.push_back(&scans[i]);
    pairs.push_back({"still", scan::AverageScans(a), scan::AverageScans(b),
                     RelativeTo(lidar[groups[g - 1][0]], lidar[groups[g][0]])});
  }
  for (std::size_t i = 5; i < scans.size(); ++i)
    if (!still[i] && !still[i - 5]) pairs.push_back({"chain", scans[i - 5], scans[i], RelativeTo(lidar[i - 5], lidar[i])});
  return pairs;
}

using Method = std::function<Pose2(const Pair&, const Pose2& guess)>;

Pose2 Ours(const Pair& p, const Pose2& guess) {
  const scan::ScanModel model(p.model);
  return scan::MatchScan(model, scan::ScanPoints(p.scan), guess).pose;
}

Method Mrpt(mrpt::slam::TICPAlgorithm algo) {
  return [algo](const Pair& p, const Pose2& guess) {
    mrpt::maps::CSimplePointsMap m1, m2;
    for (const auto& q : scan::ScanPoints(p.model)) m1.insertPoint(static_cast<float>(q.x), static_cast<float>(q.y), 0);
    for (const auto& q : scan::ScanPoints(p.scan)) m2.insertPoint(static_cast<float>(q.x), static_cast<float>(q.y), 0);
    mrpt::slam::CICP icp;
    icp.options.ICP_algorithm = algo;
    icp.options.corresponding_points_decimation = 1;
    icp.options.maxIterations = 100;
    const auto pdf = icp.Align(&m1, &m2, mrpt::poses::CPose2D(guess.x, guess.y, guess.theta));
    const auto mean = pdf->getMeanVal();
    return Pose2{mean.x(), mean.y(), mean.phi()};
  };
}

std::shared_ptr<open3d::geometry::PointCloud> Cloud(const LaserScan& s, bool normals) {
  auto c = std::make_shared<open3d::geometry::PointCloud>();
  const scan::ScanModel model(s);
  for (const auto& q : scan::ScanPoints(s)) c->points_.emplace_back(q.x, q.y, 0.0);
  if (normals) {
    // 2-D normals from the neighbouring points (a line fit), as 3-D with z = 0.
    c->EstimateNormals(open3d::geometry::KDTreeSearchParamKNN(7));
    for (auto& n : c->normals_) {
      n.z() = 0.0;
      if (n.norm() < 1e-6) n = Eigen::Vector3d(1, 0, 0);
      n.normalize();
    }
  }
  return c;
}

Method Open3d(bool plane) {
  return [plane](const Pair& p, const Pose2& guess) {
    using namespace open3d::pipelines::registration;
    auto target = Cloud(p.model, plane), source = Cloud(p.scan, false);
    Eigen::Matrix4d init = Eigen::Matrix4d::Identity();
    init.block<2, 2>(0, 0) << std::cos(guess.theta), -std::sin(guess.theta), std::sin(guess.theta), std::cos(guess.theta);
    init(0, 3) = guess.x;
    init(1, 3) = guess.y;
    RegistrationResult r;
    if (plane)
      r = RegistrationICP(*source, *target, 0.5, init, TransformationEstimationPointToPlane(), ICPConvergenceCriteria(1e-8, 1e-8, 100));
    else
      r = RegistrationICP(*source, *target, 0.5, init, TransformationEstimationPointToPoint(), ICPConvergenceCriteria(1e-8, 1e-8, 100));
    const auto& t = r.transformation_;
    return Pose2{t(0, 3), t(1, 3), std::atan2(t(1, 0), t(0, 0))};
  };
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: scan_compare BAG X,Y,YAW\n");
    return 2;
  }
  Pose2 mount;
  std::sscanf(argv[2], "%lf,%lf,%lf", &mount.x, &mount.y, &mount.theta);
  const auto pairs = ReadPairs(argv[1], mount);
  const std::vector<std::pair<std::string, Method>> methods = {
      {"umbmark PL-ICP", Ours},
      {"MRPT icpClassic", Mrpt(mrpt::slam::icpClassic)},
      {"MRPT icpLevenbergMarquardt", Mrpt(mrpt::slam::icpLevenbergMarquardt)},
      {"Open3D point-to-point", Open3d(false)},
      {"Open3D point-to-plane", Open3d(true)}};
  for (const auto& [name, method] : methods) {
    for (const char* kind : {"still", "chain"}) {
      double se_xy = 0, se_th = 0, us = 0;
      int n = 0, fail = 0;
      for (const auto& p : pairs) {
        if (p.kind != kind) continue;
        const Pose2 guess{p.truth.x + 0.04, p.truth.y - 0.03, p.truth.theta + 0.04};
        const auto t0 = std::chrono::steady_clock::now();
        const Pose2 e = method(p, guess);
        us += std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count();
        const double dxy = std::hypot(e.x - p.truth.x, e.y - p.truth.y), dth = std::abs(WrapAngle(e.theta - p.truth.theta));
        ++n;
        if (!(dxy < 0.05 && dth < 0.05)) {
          ++fail;
          continue;
        }
        se_xy += dxy * dxy;
        se_th += dth * dth;
      }
      const int ok = std::max(1, n - fail);
      std::printf("| %s | %s | %d | %.3f | %.3f | %d | %.0f |\n", name.c_str(), kind, n, 1e3 * std::sqrt(se_xy / ok),
                  1e3 * std::sqrt(se_th / ok), fail, us / std::max(1, n));
    }
  }
  return 0;
}
