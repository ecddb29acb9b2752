// Joint wheel + lidar mount + scan clock fit (see lidar_joint.hpp).
#include "calibration/lidar_joint.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <Eigen/Dense>
#include <ceres/autodiff_cost_function.h>
#include <ceres/ceres.h>
#include <fmt/format.h>

#include "calibration/refine_params.hpp"
#include "core/angles.hpp"
#include "core/errors.hpp"

namespace umbmark::calibration {

namespace {

using Mat3 = Eigen::Matrix3d;
using Vec7 = Eigen::Matrix<double, kLidarParams, 1>;
using Mat7 = Eigen::Matrix<double, kLidarParams, kLidarParams>;

// The wheel samples with times in seconds from the first.
struct WheelTrack {
  std::int64_t t0_ns = 0;
  std::vector<double> t, left, right;
  explicit WheelTrack(const std::vector<WheelTravelSample>& w) {
    t0_ns = w.empty() ? 0 : w.front().t_ns;
    for (const auto& s : w) {
      t.push_back(static_cast<double>(s.t_ns - t0_ns) * 1e-9);
      left.push_back(s.left_m);
      right.push_back(s.right_m);
    }
  }
  double Seconds(std::int64_t ns) const { return static_cast<double>(ns - t0_ns) * 1e-9; }
};

// Travel at time tau (linear between samples, constant beyond the ends) and
// the index k of the sample at or before it.
template <typename T>
void TravelAt(const WheelTrack& w, const T& tau, std::size_t& k, T& left, T& right) {
  const double ts = ScalarPart(tau);
  const std::size_t n = w.t.size();
  if (ts <= w.t.front()) {
    k = 0;
    left = T(w.left.front());
    right = T(w.right.front());
    return;
  }
  if (ts >= w.t.back()) {
    k = n - 1;
    left = T(w.left.back());
    right = T(w.right.back());
    return;
  }
  k = static_cast<std::size_t>(std::upper_bound(w.t.begin(), w.t.end(), ts) - w.t.begin()) - 1;
  const T u = (tau - w.t[k]) / (w.t[k + 1] - w.t[k]);
  left = w.left[k] + u * (w.left[k + 1] - w.left[k]);
  right = w.right[k] + u * (w.right[k + 1] - w.right[k]);
}

template <typename T>
T SincOf(const T& x) {
  using std::sin;
  if (std::abs(ScalarPart(x)) < 1e-4) return T(1.0) - x * x / 6.0;
  return sin(x) / x;
}

// robot_a_T_robot_b: the arcs of the scaled wheel travel over [tau_a, tau_b].
template <typename T>
Pose2T<T> RobotMotion(const WheelTrack& w, const T& tau_a, const T& tau_b, const T& cl, const T& cr, const T& b) {
  using std::cos;
  using std::sin;
  std::size_t ka = 0, kb = 0;
  T la, ra, lb, rb;
  TravelAt(w, tau_a, ka, la, ra);
  TravelAt(w, tau_b, kb, lb, rb);
  Pose2T<T> p;
  auto step = [&](const T& dl_nominal, const T& dr_nominal) {
    const T dl = cl * dl_nominal, dr = cr * dr_nominal;
    const T ds = 0.5 * (dl + dr), dth = (dr - dl) / b, h = 0.5 * dth;
    const T chord = ds * SincOf(h);
    p.x += chord * cos(p.theta + h);
    p.y += chord * sin(p.theta + h);
    p.theta += dth;
  };
  T pl = la, pr = ra;
  for (std::size_t k = ka + 1; k <= kb && kb > ka; ++k) {
    step(T(w.left[k]) - pl, T(w.right[k]) - pr);
    pl = T(w.left[k]);
    pr = T(w.right[k]);
  }
  step(lb - pl, rb - pr);
  return p;
}

template <typename T>
Pose2T<T> LidarMotion(const WheelTrack& w, double ta, double tb, const T* p) {
  const Pose2T<T> robot = RobotMotion(w, T(ta) - p[kTimeOffset], T(tb) - p[kTimeOffset], p[kCLeft], p[kCRight], p[kWheelbase]);
  const Pose2T<T> mount{p[kMountX], p[kMountY], p[kMountYaw]};
  return Compose(Inverse(mount), Compose(robot, mount));
}

// r = sqrt(W) (z - prediction), sqrt(W) upper triangular (U^T U = W).
struct PairResidual {
  const WheelTrack* wheels;
  double ta, tb;
  Pose2 z;
  std::array<double, 9> sqrt_w;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    const Pose2T<T> pred = LidarMotion(*wheels, ta, tb, p);
    T e[3] = {T(z.x) - pred.x, T(z.y) - pred.y, T(z.theta) - pred.theta};
    e[2] -= T(2.0 * kPi * std::round(ScalarPart(e[2]) / (2.0 * kPi)));
    for (int i = 0; i < 3; ++i) {
      r[i] = T(0.0);
      for (int j = 0; j < 3; ++j) r[i] += sqrt_w[static_cast<std::size_t>(3 * i + j)] * e[j];
    }
    return true;
  }
};

struct PriorResidual {
  Vec7 mean, inv_sd;
  template <typename T>
  bool operator()(const T* p, T* r) const {
    for (int i = 0; i < kLidarParams; ++i) r[i] = (p[i] - mean(i)) * inv_sd(i);
    return true;
  }
};

Mat3 ToMat3(const std::array<double, 9>& a) {
  Mat3 m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = a[static_cast<std::size_t>(3 * r + c)];
  return m;
}

// Covariance of the predicted lidar motion from wheel travel noise of
// variance |d| per metre on each wheel (k = 1), propagated along the arcs
// (the Chong-Kleeman model), then moved into the lidar frame.
Mat3 WheelNoiseCovariance(const WheelTrack& w, double ta, double tb, const LidarJointParams& prm) {
  const double b = prm.wheelbase_m;
  std::size_t ka = 0, kb = 0;
  double la, ra, lb, rb;
  TravelAt(w, ta - prm.time_offset_s, ka, la, ra);
  TravelAt(w, tb - prm.time_offset_s, kb, lb, rb);
  Pose2 p;
  Mat3 cov = Mat3::Zero();
  auto step = [&](double dl_nominal, double dr_nominal) {
    const double dl = prm.c_left * dl_nominal, dr = prm.c_right * dr_nominal;
    const double ds = 0.5 * (dl + dr), dth = (dr - dl) / b, h = 0.5 * dth, a = p.theta + h;
    const double chord = ds * SincOf(h);
    Mat3 f = Mat3::Identity();
    f(0, 2) = -chord * std::sin(a);
    f(1, 2) = chord * std::cos(a);
    Eigen::Matrix<double, 3, 2> g;
    g << 0.5 * std::cos(a) + ds * std::sin(a) / (2 * b), 0.5 * std::cos(a) - ds * std::sin(a) / (2 * b),
        0.5 * std::sin(a) - ds * std::cos(a) / (2 * b), 0.5 * std::sin(a) + ds * std::cos(a) / (2 * b), -1.0 / b, 1.0 / b;
    const Eigen::Vector2d q(std::abs(dl), std::abs(dr));
    cov = f * cov * f.transpose() + g * q.asDiagonal() * g.transpose();
    p = {p.x + chord * std::cos(a), p.y + chord * std::sin(a), p.theta + dth};
  };
  double pl = la, pr = ra;
  for (std::size_t k = ka + 1; k <= kb && kb > ka; ++k) {
    step(w.left[k] - pl, w.right[k] - pr);
    pl = w.left[k];
    pr = w.right[k];
  }
  step(lb - pl, rb - pr);
  // lidar motion = M^-1 D M: d(t) = Rm^T (dt_D + dtheta_D * J R_D m), d(theta) = dtheta_D.
  const double cm = std::cos(prm.mount.theta), sm = std::sin(prm.mount.theta);
  const double cd = std::cos(p.theta), sd = std::sin(p.theta);
  const Eigen::Vector2d rdm(cd * prm.mount.x - sd * prm.mount.y, sd * prm.mount.x + cd * prm.mount.y);
  Eigen::Matrix2d rmt;
  rmt << cm, sm, -sm, cm;
  Mat3 jz = Mat3::Zero();
  jz.topLeftCorner<2, 2>() = rmt;
  jz.block<2, 1>(0, 2) = rmt * Eigen::Vector2d(-rdm.y(), rdm.x());
  jz(2, 2) = 1.0;
  return jz * cov * jz.transpose();
}

// One measurement inside the fit.
struct Term {
  std::size_t pair = 0;
  double ta = 0.0, tb = 0.0;
  Mat3 a = Mat3::Zero(), b = Mat3::Zero();  // registration covariance, wheel-noise covariance (k = 1)
  Eigen::Vector3d e = Eigen::Vector3d::Zero();  // residual at the current parameters
  bool outlier = false;
};

Eigen::Vector3d Residual(const WheelTrack& w, const Term& t, const Pose2& z, const LidarJointParams& prm) {
  const auto v = prm.Vector();
  const Pose2 pred = LidarMotion(w, t.ta, t.tb, v.data());
  return {z.x - pred.x, z.y - pred.y, WrapAngle(z.theta - pred.theta)};
}

Mat3 Combined(const Term& t, double s2, double k2) { return s2 * t.a + k2 * t.b + 1e-14 * Mat3::Identity(); }

// -2 log likelihood of the residuals under C = s2 A + k2 B.
double VarianceCost(const std::vector<Term>& terms, double s2, double k2) {
  double f = 0.0;
  for (const Term& t : terms) {
    if (t.outlier) continue;
    const Eigen::LLT<Mat3> llt(Combined(t, s2, k2));
    if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
    const Mat3 l = llt.matrixL();
    f += 2.0 * (l.diagonal().array().log().sum()) + t.e.dot(llt.solve(t.e));
  }
  return f;
}

// Golden-section minimum of f over [lo, hi].
template <typename F>
double GoldenMin(F f, double lo, double hi) {
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = lo, b = hi, c = b - g * (b - a), d = a + g * (b - a);
  double fc = f(c), fd = f(d);
  for (int i = 0; i < 40; ++i) {
    if (fc < fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - g * (b - a);
      fc = f(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + g * (b - a);
      fd = f(d);
    }
  }
  return 0.5 * (a + b);
}

// Maximum-likelihood variance components (s^2, k^2), coordinate-wise in logs.
void EstimateVarianceComponents(const std::vector<Term>& terms, double& s2, double& k2) {
  double u = std::log(s2), v = std::log(std::max(k2, 1e-12));
  for (int sweep = 0; sweep < 4; ++sweep) {
    u = GoldenMin([&](double x) { return VarianceCost(terms, std::exp(x), std::exp(v)); }, -12.0, 12.0);
    v = GoldenMin([&](double x) { return VarianceCost(terms, std::exp(u), std::exp(x)); }, -28.0, 0.0);
  }
  s2 = std::exp(u);
  k2 = std::exp(v);
}

std::array<double, 9> SqrtInformation(const Mat3& c) {
  const Eigen::LLT<Mat3> llt(c.inverse());
  const Mat3 u = llt.matrixU();
  std::array<double, 9> out{};
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) out[static_cast<std::size_t>(3 * r + k)] = u(r, k);
  return out;
}

}  // namespace

const char* LidarParamName(int i) {
  static const char* names[kLidarParams] = {"c_left", "c_right", "wheelbase_m", "mount_x_m", "mount_y_m", "mount_yaw_rad",
                                            "scan_time_offset_s"};
  return i >= 0 && i < kLidarParams ? names[i] : "?";
}

std::array<double, kLidarParams> LidarJointParams::Vector() const {
  return {c_left, c_right, wheelbase_m, mount.x, mount.y, mount.theta, time_offset_s};
}

LidarJointParams LidarJointParams::FromVector(const double* p) {
  LidarJointParams out;
  out.c_left = p[kCLeft];
  out.c_right = p[kCRight];
  out.wheelbase_m = p[kWheelbase];
  out.mount = {p[kMountX], p[kMountY], WrapAngle(p[kMountYaw])};
  out.time_offset_s = p[kTimeOffset];
  return out;
}

double LidarJointFit::Sd(int i) const {
  return std::sqrt(std::max(0.0, covariance[static_cast<std::size_t>(i * kLidarParams + i)]));
}

std::string LidarJointOptions::Validate() const {
  for (const auto& [name, v] : {std::pair{"prior_wheel_sd", prior_wheel_sd}, std::pair{"prior_mount_sd_m", prior_mount_sd_m},
                                std::pair{"prior_yaw_sd_rad", prior_yaw_sd_rad}, std::pair{"prior_offset_sd_s", prior_offset_sd_s},
                                std::pair{"max_offset_s", max_offset_s}, std::pair{"outlier_chi2", outlier_chi2}})
    if (!(v > 0.0) || !std::isfinite(v)) return fmt::format("{} = {}: must be a finite number > 0", name, v);
  if (!(registration_scale_sd >= 0.0 && registration_scale_sd < 0.1))
    return fmt::format("registration_scale_sd = {}: must be in [0, 0.1)", registration_scale_sd);
  if (!(registration_rotation_sd >= 0.0 && registration_rotation_sd < 0.1))
    return fmt::format("registration_rotation_sd = {}: must be in [0, 0.1)", registration_rotation_sd);
  if (rounds < 1) return fmt::format("rounds = {}: must be >= 1", rounds);
  if (max_iterations < 1) return fmt::format("max_iterations = {}: must be >= 1", max_iterations);
  return {};
}

ScanPair MirrorPair(const ScanPair& p) {
  ScanPair m = p;
  m.lidar_a_T_lidar_b = {p.lidar_a_T_lidar_b.x, -p.lidar_a_T_lidar_b.y, -p.lidar_a_T_lidar_b.theta};
  const double s[3] = {1.0, -1.0, -1.0};
  for (std::size_t r = 0; r < 3; ++r)
    for (std::size_t c = 0; c < 3; ++c) m.covariance[3 * r + c] = s[r] * s[c] * p.covariance[3 * r + c];
  m.lidar0_T_lidar_a = {p.lidar0_T_lidar_a.x, -p.lidar0_T_lidar_a.y, -p.lidar0_T_lidar_a.theta};
  return m;
}

Pose2 PredictLidarMotion(const std::vector<WheelTravelSample>& wheels, std::int64_t t_a_ns, std::int64_t t_b_ns,
                         const LidarJointParams& p) {
  const WheelTrack w(wheels);
  const auto v = p.Vector();
  return LidarMotion(w, w.Seconds(t_a_ns), w.Seconds(t_b_ns), v.data());
}

LinearStart LinearCalibration(const std::vector<WheelTravelSample>& wheels, const std::vector<ScanPair>& pairs,
                              double nominal_wheelbase_m) {
  LinearStart out;
  const WheelTrack w(wheels);
  Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
  Eigen::Vector2d atb = Eigen::Vector2d::Zero();
  double st = 0.0, ss = 0.0, ys = 0.0, yc = 0.0;
  struct Travel {
    double dl, dr;
  };
  std::vector<Travel> travel;
  for (const ScanPair& p : pairs) {
    std::size_t k = 0;
    double la, ra, lb, rb;
    TravelAt(w, w.Seconds(p.t_a_ns), k, la, ra);
    TravelAt(w, w.Seconds(p.t_b_ns), k, lb, rb);
    const double dl = lb - la, dr = rb - ra, ds = 0.5 * (dl + dr);
    travel.push_back({dl, dr});
    const Pose2& z = p.lidar_a_T_lidar_b;
    const Eigen::Vector2d row(dl, dr);
    ata += row * row.transpose();
    atb += row * z.theta;
    out.turned_rad += std::abs(z.theta);
    if (std::abs(z.theta) < 0.1 && std::abs(ds) > 0.05) {
      out.straight_m += std::abs(ds);
      st += std::hypot(z.x, z.y) * std::abs(ds);
      ss += ds * ds;
      const double phi = std::atan2(z.y, z.x) + (ds < 0 ? kPi : 0.0);
      ys += std::abs(ds) * std::sin(phi);
      yc += std::abs(ds) * std::cos(phi);
    }
  }
  LidarJointParams& prm = out.params;
  prm.wheelbase_m = nominal_wheelbase_m;
  const double c0 = ss > 0.0 && out.straight_m > 0.2 ? st / ss : 1.0;
  prm.c_left = prm.c_right = c0;
  if (ata.determinant() > 1e-12 * std::max(1.0, ata.squaredNorm())) {
    const Eigen::Vector2d j = ata.ldlt().solve(atb);
    out.j21 = j(0);
    out.j22 = j(1);
    if (out.turned_rad > 2.0 && j(1) - j(0) > 0.0 && j(0) < 0.0 && j(1) > 0.0) {
      prm.wheelbase_m = 2.0 * c0 / (j(1) - j(0));
      prm.c_left = -j(0) * prm.wheelbase_m;
      prm.c_right = j(1) * prm.wheelbase_m;
    }
  }
  if (ys != 0.0 || yc != 0.0) prm.mount.theta = -std::atan2(ys, yc);
  // Position: R_m z.t - t_D = (R_D - I) m, stacked over the turning measurements.
  Eigen::Matrix2d mtm = Eigen::Matrix2d::Zero();
  Eigen::Vector2d mty = Eigen::Vector2d::Zero();
  const double cm = std::cos(prm.mount.theta), sm = std::sin(prm.mount.theta);
  for (const ScanPair& p : pairs) {
    const auto v = prm.Vector();
    double zero_mount[kLidarParams];
    std::copy(v.begin(), v.end(), zero_mount);
    zero_mount[kMountX] = zero_mount[kMountY] = zero_mount[kMountYaw] = 0.0;
    const Pose2 d = LidarMotion(w, w.Seconds(p.t_a_ns), w.Seconds(p.t_b_ns), zero_mount);
    if (std::abs(d.theta) < 0.05) continue;
    const Pose2& z = p.lidar_a_T_lidar_b;
    Eigen::Matrix2d a;
    a << std::cos(d.theta) - 1.0, -std::sin(d.theta), std::sin(d.theta), std::cos(d.theta) - 1.0;
    const Eigen::Vector2d y(cm * z.x - sm * z.y - d.x, sm * z.x + cm * z.y - d.y);
    mtm += a.transpose() * a;
    mty += a.transpose() * y;
  }
  if (mtm.determinant() > 1e-9) {
    const Eigen::Vector2d m = mtm.ldlt().solve(mty);
    if (m.norm() < 2.0) prm.mount = {m(0), m(1), prm.mount.theta};
  }
  return out;
}

// Rounds of: weights from the current variance components, Gauss-Newton,
// variance components and outliers from the residuals; then the sandwich
// covariance at the final parameters. One function so the round structure
// reads in one place (108 lines with its lambdas).
LidarJointFit FitLidarJoint(const std::vector<WheelTravelSample>& wheels, const std::vector<ScanPair>& pairs,
                            const LidarJointParams& start, const LidarJointOptions& o) {
  if (const std::string err = o.Validate(); !err.empty()) throw InvalidOptions(err);
  if (!(start.wheelbase_m > 0.0)) throw InvalidOptions(fmt::format("start.wheelbase_m = {}: must be > 0", start.wheelbase_m));
  LidarJointFit fit;
  const WheelTrack w(wheels);
  std::vector<Term> terms;
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    Term t;
    t.pair = i;
    t.ta = w.Seconds(pairs[i].t_a_ns);
    t.tb = w.Seconds(pairs[i].t_b_ns);
    if (w.t.size() < 2 || t.ta - o.max_offset_s < w.t.front() || t.tb + o.max_offset_s > w.t.back()) {
      ++fit.unusable;
      continue;
    }
    t.a = ToMat3(pairs[i].covariance);
    terms.push_back(t);
  }
  if (terms.size() < 10)
    throw QualityGateError(fmt::format("{} scan measurement(s) fall inside the wheel data (at least 10 are needed): the "
                                       "recording is too short; drive for a few minutes",
                                       terms.size()));
  const auto v0 = start.Vector();
  Vec7 p = Eigen::Map<const Vec7>(v0.data());
  const Vec7 prior_mean = p;
  Vec7 prior_sd;
  prior_sd << o.prior_wheel_sd * start.c_left, o.prior_wheel_sd * start.c_right, o.prior_wheel_sd * start.wheelbase_m,
      o.prior_mount_sd_m, o.prior_mount_sd_m, o.prior_yaw_sd_rad, o.prior_offset_sd_s;
  for (int i = 0; i < kLidarParams; ++i) fit.prior_sd[static_cast<std::size_t>(i)] = prior_sd(i);
  double s2 = 1.0, k2 = 0.0;
  std::vector<std::pair<std::size_t, ceres::CostFunction*>> costs;  // owned by the last problem
  std::unique_ptr<ceres::Problem> problem;
  auto solve = [&]() {
    const LidarJointParams prm = LidarJointParams::FromVector(p.data());
    ceres::Problem::Options po;
    problem = std::make_unique<ceres::Problem>(po);
    costs.clear();
    for (std::size_t i = 0; i < terms.size(); ++i) {
      Term& t = terms[i];
      t.b = WheelNoiseCovariance(w, t.ta, t.tb, prm);
      if (t.outlier) continue;
      auto* cost = new ceres::AutoDiffCostFunction<PairResidual, 3, kLidarParams>(
          new PairResidual{&w, t.ta, t.tb, pairs[t.pair].lidar_a_T_lidar_b, SqrtInformation(Combined(t, s2, k2))});
      problem->AddResidualBlock(cost, nullptr, p.data());
      costs.emplace_back(i, cost);
    }
    problem->AddResidualBlock(new ceres::AutoDiffCostFunction<PriorResidual, kLidarParams, kLidarParams>(
                                  new PriorResidual{prior_mean, prior_sd.cwiseInverse()}),
                              nullptr, p.data());
    ceres::Solver::Options so;
    so.max_num_iterations = o.max_iterations;
    so.linear_solver_type = ceres::DENSE_QR;
    so.num_threads = 1;
    so.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(so, problem.get(), &summary);
    fit.converged = summary.termination_type == ceres::CONVERGENCE;
    fit.final_cost = summary.final_cost;
  };
  for (int round = 0; round < o.rounds; ++round) {
    solve();
    const LidarJointParams prm = LidarJointParams::FromVector(p.data());
    for (Term& t : terms) t.e = Residual(w, t, pairs[t.pair].lidar_a_T_lidar_b, prm);
    if (round + 1 == o.rounds) break;
    for (Term& t : terms) t.outlier = false;
    EstimateVarianceComponents(terms, s2, k2);
    for (Term& t : terms) t.outlier = t.e.dot(Combined(t, s2, k2).ldlt().solve(t.e)) > o.outlier_chi2;
    EstimateVarianceComponents(terms, s2, k2);
  }
  fit.params = LidarJointParams::FromVector(p.data());
  fit.registration_scale = std::sqrt(s2);
  fit.wheel_noise_k = std::sqrt(k2);
  // Sandwich covariance: H^-1 (S + prior information) H^-1.
  Mat7 h = prior_sd.array().inverse().square().matrix().asDiagonal();
  Mat7 meat = h;
  std::vector<Vec7> scores;
  std::vector<std::size_t> which;
  for (const auto& [i, cost] : costs) {
    double r[3];
    Eigen::Matrix<double, 3, kLidarParams, Eigen::RowMajor> j;
    double* jac[1] = {j.data()};
    const double* params[1] = {p.data()};
    cost->Evaluate(params, r, jac);
    h += j.transpose() * j;
    scores.push_back(j.transpose() * Eigen::Map<Eigen::Vector3d>(r));
    which.push_back(terms[i].pair);
  }
  for (std::size_t i = 0; i < scores.size(); ++i) {
    meat += scores[i] * scores[i].transpose();
    if (i + 1 < scores.size() && pairs[which[i]].t_b_ns == pairs[which[i + 1]].t_a_ns)
      meat += scores[i] * scores[i + 1].transpose() + scores[i + 1] * scores[i].transpose();
  }
  Eigen::SelfAdjointEigenSolver<Mat7> es(meat);
  meat = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() * es.eigenvectors().transpose();
  const Mat7 hinv = h.inverse();
  Mat7 cov = hinv * meat * hinv;
  // Model error: a common scale error e of the registrations moves every
  // length by e times itself (the clock and the yaw are scale-free).
  Vec7 lengths = Vec7::Zero();
  for (const int i : {kCLeft, kCRight, kWheelbase, kMountX, kMountY}) lengths(i) = p(i);
  cov += o.registration_scale_sd * o.registration_scale_sd * lengths * lengths.transpose();
  // A common rotation r of the registrations' translations moves the yaw by -r alone.
  cov(kMountYaw, kMountYaw) += o.registration_rotation_sd * o.registration_rotation_sd;
  for (int r = 0; r < kLidarParams; ++r)
    for (int c = 0; c < kLidarParams; ++c) fit.covariance[static_cast<std::size_t>(r * kLidarParams + c)] = cov(r, c);
  fit.measurements = costs.size();
  fit.outliers = terms.size() - costs.size();
  return fit;
}

}  // namespace umbmark::calibration
