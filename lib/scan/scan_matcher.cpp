// Point-to-line ICP with projective association (see scan_matcher.hpp).
#include "scan/scan_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "core/angles.hpp"

namespace umbmark::scan {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kNormalBeams = 3;         // neighbours either side used for a normal
constexpr double kMaxFlatness = 0.08;   // smallest / largest eigenvalue of a line's scatter

// atan2 to about 1e-5 rad (a minimax polynomial of atan on [0, 1]): only
// picks the beam to search around, and libm's atan2 was half the run time.
double FastAtan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double mx = std::max(ax, ay);
  if (mx == 0.0) return 0.0;
  const double a = std::min(ax, ay) / mx, s = a * a;
  double r = ((-0.0464964749 * s + 0.15931422) * s - 0.327622764) * s * a + a;
  if (ay > ax) r = 1.57079637 - r;
  if (x < 0.0) r = 3.14159274 - r;
  return y < 0.0 ? -r : r;
}

Eigen::Matrix3d ToMatrix(const std::array<double, 9>& a) {
  Eigen::Matrix3d m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = a[static_cast<std::size_t>(3 * r + c)];
  return m;
}

// Inverse of a symmetric positive semi-definite 3x3 matrix; directions with
// (almost) no information get a huge variance instead of a failure.
Eigen::Matrix3d SafeInverse(const Eigen::Matrix3d& h) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(h);
  const double top = std::max(es.eigenvalues().maxCoeff(), 1e-300);
  Eigen::Vector3d inv;
  for (int i = 0; i < 3; ++i) inv(i) = 1.0 / std::max(es.eigenvalues()(i), 1e-15 * top + 1e-300);
  return es.eigenvectors() * inv.asDiagonal() * es.eigenvectors().transpose();
}

}  // namespace

std::vector<Point2> ScanPoints(const LaserScan& scan) {
  std::vector<Point2> out;
  out.reserve(scan.ranges.size());
  for (std::size_t i = 0; i < scan.ranges.size(); ++i) {
    if (!scan.Valid(i)) continue;
    const double a = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
    const double r = scan.ranges[i];
    out.push_back({r * std::cos(a), r * std::sin(a)});
  }
  return out;
}

ScanModel::ScanModel(const LaserScan& scan)
    : angle_min_(scan.angle_min), angle_increment_(scan.angle_increment) {
  const std::size_t n = scan.ranges.size();
  full_circle_ = static_cast<double>(n) * std::abs(scan.angle_increment) >= 2.0 * kPi - 1.5 * std::abs(scan.angle_increment);
  points_.assign(n, {kNaN, kNaN});
  normals_.assign(n, {kNaN, kNaN});
  std::vector<double> ranges(n, kNaN);
  shadow_.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (!scan.Valid(i)) continue;
    const double a = scan.angle_min + static_cast<double>(i) * scan.angle_increment;
    points_[i] = {scan.ranges[i] * std::cos(a), scan.ranges[i] * std::sin(a)};
    ranges[i] = scan.ranges[i];
  }
  // Shadow edges: beams beside a beam more than 0.1 m nearer (see MatchOptions).
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isnan(ranges[i])) continue;
    for (long d : {-2L, -1L, 1L, 2L}) {
      long j = static_cast<long>(i) + d;
      if (full_circle_) j = (j % static_cast<long>(n) + static_cast<long>(n)) % static_cast<long>(n);
      if (j < 0 || j >= static_cast<long>(n)) continue;
      if (ranges[static_cast<std::size_t>(j)] < ranges[i] - 0.1) shadow_[i] = 1;
    }
  }
  // A normal from the scatter of the neighbours near the point (a line fit).
  const auto ni = static_cast<long>(n);
  for (long i = 0; i < ni; ++i) {
    const Point2 p = points_[static_cast<std::size_t>(i)];
    if (std::isnan(p.x)) continue;
    const double radius = std::max(0.08, 4.0 * std::hypot(p.x, p.y) * std::abs(angle_increment_));
    double sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    int count = 0;
    for (long k = i - kNormalBeams; k <= i + kNormalBeams; ++k) {
      long j = k;
      if (full_circle_) j = (k % ni + ni) % ni;
      if (j < 0 || j >= ni) continue;
      const Point2 q = points_[static_cast<std::size_t>(j)];
      if (std::isnan(q.x) || std::hypot(q.x - p.x, q.y - p.y) > radius) continue;
      sx += q.x;
      sy += q.y;
      sxx += q.x * q.x;
      sxy += q.x * q.y;
      syy += q.y * q.y;
      ++count;
    }
    if (count < 4) continue;
    const double c = static_cast<double>(count);
    const double cxx = sxx / c - (sx / c) * (sx / c), cxy = sxy / c - (sx / c) * (sy / c), cyy = syy / c - (sy / c) * (sy / c);
    const double tr = cxx + cyy, det = cxx * cyy - cxy * cxy;
    const double disc = std::sqrt(std::max(0.0, 0.25 * tr * tr - det));
    const double lmax = 0.5 * tr + disc, lmin = 0.5 * tr - disc;
    if (!(lmax > 0.0) || lmin > kMaxFlatness * lmax) continue;
    // Eigenvector of lmin: (cxy, lmin - cxx) or (lmin - cyy, cxy).
    double nx = cxy, ny = lmin - cxx;
    if (std::hypot(nx, ny) < 1e-12) {
      nx = lmin - cyy;
      ny = cxy;
    }
    const double norm = std::hypot(nx, ny);
    if (norm < 1e-12) continue;
    normals_[static_cast<std::size_t>(i)] = {nx / norm, ny / norm};
    ++usable_;
  }
}

std::string MatchOptions::Validate() const {
  if (max_iterations < 1) return fmt::format("max_iterations = {}: must be >= 1", max_iterations);
  if (search_beams < 0) return fmt::format("search_beams = {}: must be >= 0", search_beams);
  if (!(max_pair_distance_m > 0.0)) return fmt::format("max_pair_distance_m = {}: must be > 0", max_pair_distance_m);
  if (!(initial_gate_m > 0.0)) return fmt::format("initial_gate_m = {}: must be > 0", initial_gate_m);
  if (!(min_gate_m > 0.0) || min_gate_m > initial_gate_m)
    return fmt::format("min_gate_m = {}: must be > 0 and <= initial_gate_m", min_gate_m);
  if (!(huber_k > 0.0)) return fmt::format("huber_k = {}: must be > 0", huber_k);
  if (!(min_noise_m > 0.0)) return fmt::format("min_noise_m = {}: must be > 0", min_noise_m);
  if (!(tolerance_m > 0.0)) return fmt::format("tolerance_m = {}: must be > 0", tolerance_m);
  return {};
}

std::array<double, 9> MatchResult::Covariance() const {
  const Eigen::Matrix3d c = residual_sd_m * residual_sd_m * SafeInverse(ToMatrix(information));
  std::array<double, 9> out{};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(3 * r + k)] = c(r, k);
  return out;
}

// The pairing and Gauss-Newton steps; a struct so it may read ScanModel's
// per-beam arrays.
struct MatchKernel {
  struct Pair {
    Point2 q;  // scan point moved into the model frame
    Point2 m, n;
    double r;
  };

  // The nearest model point with a normal among the beams around q's bearing.
  static bool Pair1(const ScanModel& model, const Point2& q, int search, double max_d, Point2& m, Point2& n,
                    const MatchOptions& o) {
    const auto nb = static_cast<long>(model.points_.size());
    const double bearing = FastAtan2(q.y, q.x);
    double rel = bearing - model.angle_min_;
    if (model.full_circle_) {  // into [-pi, pi) without libm's remainder (a tenth of the run time)
      while (rel >= kPi) rel -= 2.0 * kPi;
      while (rel < -kPi) rel += 2.0 * kPi;
    }
    long centre = std::lround(rel / model.angle_increment_);
    if (model.full_circle_) {
      if (centre < 0) centre += nb;
      else if (centre >= nb) centre -= nb;
      if (centre < 0 || centre >= nb) centre = (centre % nb + nb) % nb;
    }
    double best = max_d * max_d;
    long found = -1;
    // The neighbours of a full circle wrap around; centre is in [0, nb), so
    // one add or subtract of nb does it while the search is under a circle
    // (an integer division per candidate was a third of the matching time).
    const bool wrap = model.full_circle_ && 2L * search < nb;
    for (long k = centre - search; k <= centre + search; ++k) {
      long j = k;
      if (wrap) j = j < 0 ? j + nb : (j >= nb ? j - nb : j);
      else if (model.full_circle_) j = (k % nb + nb) % nb;
      if (j < 0 || j >= nb) continue;
      const Point2& p = model.points_[static_cast<std::size_t>(j)];
      if (std::isnan(model.normals_[static_cast<std::size_t>(j)].x)) continue;
      if (o.skip_shadow_edges && model.shadow_[static_cast<std::size_t>(j)]) continue;
      const double d2 = (p.x - q.x) * (p.x - q.x) + (p.y - q.y) * (p.y - q.y);
      if (d2 < best) {
        best = d2;
        found = j;
      }
    }
    if (found < 0) return false;
    m = model.points_[static_cast<std::size_t>(found)];
    n = model.normals_[static_cast<std::size_t>(found)];
    return true;
  }

  static MatchResult Run(const ScanModel& model, const std::vector<Point2>& pts, const Pose2& guess, const MatchOptions& o) {
    MatchResult res;
    res.pose = guess;
    res.points = pts.size();
    double gate = o.initial_gate_m;
    std::vector<Pair> pairs;
    pairs.reserve(pts.size());
    std::vector<double> abs_r;
    for (int it = 0; it < o.max_iterations; ++it) {
      res.iterations = it + 1;
      const double c = std::cos(res.pose.theta), s = std::sin(res.pose.theta);
      pairs.clear();
      for (const Point2& p : pts) {
        const Point2 q{res.pose.x + c * p.x - s * p.y, res.pose.y + s * p.x + c * p.y};
        Point2 m, n;
        if (!Pair1(model, q, o.search_beams, o.max_pair_distance_m, m, n, o)) continue;
        const double r = n.x * (q.x - m.x) + n.y * (q.y - m.y);
        if (std::abs(r) <= gate) pairs.push_back({q, m, n, r});
      }
      if (pairs.size() < 3) {
        res.pairs = pairs.size();
        return res;
      }
      // Robust scale from the median absolute residual.
      abs_r.clear();
      for (const Pair& pr : pairs) abs_r.push_back(std::abs(pr.r));
      auto mid = abs_r.begin() + static_cast<long>(abs_r.size() / 2);
      std::nth_element(abs_r.begin(), mid, abs_r.end());
      const double sigma = std::max(o.min_noise_m, 1.4826 * *mid);
      const double huber = o.huber_k * sigma;
      Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      for (const Pair& pr : pairs) {
        // d r / d(tx, ty, theta): n, n . perp(q - t)
        const double lx = pr.q.x - res.pose.x, ly = pr.q.y - res.pose.y;
        const Eigen::Vector3d j(pr.n.x, pr.n.y, pr.n.x * -ly + pr.n.y * lx);
        const double w = std::abs(pr.r) <= huber ? 1.0 : huber / std::abs(pr.r);
        h += w * j * j.transpose();
        g += w * j * pr.r;
      }
      const Eigen::Vector3d step = -SafeInverse(h) * g;
      res.pose.x += step(0);
      res.pose.y += step(1);
      res.pose.theta += step(2);
      gate = std::max({o.min_gate_m, 6.0 * sigma, 0.6 * gate});
      if (std::abs(step(0)) + std::abs(step(1)) + std::abs(step(2)) < o.tolerance_m && gate <= std::max(o.min_gate_m, 6.0 * sigma)) {
        res.converged = true;
        break;
      }
    }
    Finish(model, pts, o, gate, res);
    return res;
  }

  // Information and residual scale at the final pose over the final pairs.
  static void Finish(const ScanModel& model, const std::vector<Point2>& pts, const MatchOptions& o, double gate,
                     MatchResult& res) {
    const double c = std::cos(res.pose.theta), s = std::sin(res.pose.theta);
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    double ss = 0.0;
    std::size_t count = 0;
    for (const Point2& p : pts) {
      const Point2 q{res.pose.x + c * p.x - s * p.y, res.pose.y + s * p.x + c * p.y};
      Point2 m, n;
      if (!Pair1(model, q, o.search_beams, o.max_pair_distance_m, m, n, o)) continue;
      const double r = n.x * (q.x - m.x) + n.y * (q.y - m.y);
      if (std::abs(r) > gate) continue;
      const double lx = q.x - res.pose.x, ly = q.y - res.pose.y;
      const Eigen::Vector3d j(n.x, n.y, n.x * -ly + n.y * lx);
      h += j * j.transpose();
      ss += r * r;
      ++count;
    }
    res.pairs = count;
    res.residual_sd_m = count > 3 ? std::sqrt(ss / static_cast<double>(count - 3)) : 0.0;
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) res.information[static_cast<std::size_t>(3 * r + k)] = h(r, k);
  }
};

MatchResult MatchScan(const ScanModel& model, const std::vector<Point2>& points, const Pose2& guess,
                      const MatchOptions& options) {
  return MatchKernel::Run(model, points, guess, options);
}

std::vector<std::string> UndeterminedDirections(const std::array<double, 9>& information, std::size_t pairs,
                                                double frame_yaw, double max_dilution) {
  // Information in the robot frame: the sensor's x, y rotated by frame_yaw.
  Eigen::Matrix3d g = Eigen::Matrix3d::Identity();
  g.topLeftCorner<2, 2>() << std::cos(frame_yaw), -std::sin(frame_yaw), std::sin(frame_yaw), std::cos(frame_yaw);
  const Eigen::Matrix3d cov = g * SafeInverse(ToMatrix(information)) * g.transpose();
  const double half = std::max(1.0, 0.5 * static_cast<double>(pairs));
  const char* names[3] = {"along x", "along y", "heading"};
  std::vector<std::pair<double, std::string>> bad;
  for (int i = 0; i < 3; ++i) {
    const double dilution = std::sqrt(std::max(0.0, cov(i, i)) * half);
    if (!(dilution <= max_dilution)) bad.emplace_back(dilution, names[i]);
  }
  std::sort(bad.begin(), bad.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<std::string> out;
  for (auto& b : bad) out.push_back(b.second);
  return out;
}

}  // namespace umbmark::scan
