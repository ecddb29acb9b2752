// Data files -> fit-noise runs; see wheel_noise_fit_data.hpp.
#include "error_models/wheel_noise_fit_data.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "error_models/path_covariance.hpp"
#include "error_models/second_order.hpp"
#include "error_models/trajectory_covariance.hpp"
#include "kinematics/diff_drive.hpp"
#include "kinematics/odometry.hpp"

#include <Eigen/Cholesky>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/tools/minima.hpp>
#include <optional>
#include <limits>
#include <stdexcept>
#include <Eigen/LU>

namespace umbmark {

std::vector<WheelNoiseFitRun> NoiseRunsFromEndpoints(const EndpointData& data, const std::vector<PathSegment>& path,
                                                double wheelbase_m, const std::string& group_prefix,
                                                const NoiseFitInputOptions& options) {
  const std::vector<WheelSegment> wheels = ToWheelSegments(path, wheelbase_m);
  // The path the true robot drove (see NoiseFitInputOptions::systematic).
  const SystematicErrors& e = options.systematic;
  std::vector<WheelSegment> true_wheels = wheels;
  for (auto& w : true_wheels) w = {e.c_L * w.left_m, e.c_R * w.right_m};
  const double true_wheelbase = e.E_b * wheelbase_m;
  const PathCovarianceSummary pc =
      PredictPathCovariance(true_wheels, true_wheelbase, WheelNoise{}, PoseCovariance::Zero());
  SecondOrderBasis q2;
  if (options.second_order) q2 = SecondOrderHeadingBasis(true_wheels, true_wheelbase);
  const PoseCovariance M = MeasurementCovariance(options.sigma_xy_m, options.sigma_theta_rad, pc.mean);
  std::vector<WheelNoiseFitRun> out;
  for (const ReturnError& r : data.runs) {
    WheelNoiseFitRun f;
    f.group = group_prefix + r.direction;
    f.run = r.run;
    f.has_theta = r.etheta_rad.has_value();
    f.error = Eigen::Vector3d(r.ex_m, r.ey_m, f.has_theta ? WrapAngle(*r.etheta_rad) : 0.0);
    f.basis = pc.motion;
    f.second_order = q2;
    f.measurement = M;
    f.odometry_travel = wheels;
    f.recorded_wheelbase_m = wheelbase_m;
    out.push_back(f);
  }
  return out;
}

std::vector<WheelNoiseFitRun> NoiseRunsFromTrajectories(const TrajectoryData& data, const RobotParams& robot,
                                                   const std::string& group_prefix,
                                                   const NoiseFitInputOptions& options, int* skipped) {
  std::vector<WheelNoiseFitRun> out;
  int skip = 0;
  for (const TrajectoryRun& run : data.runs) {
    const std::size_t n = run.size();
    if (n < 2 || !run.HasGroundTruth(0) || !run.HasGroundTruth(n - 1)) {
      ++skip;
      continue;
    }
    WheelTravel travel;
    try {
      travel = ComputeWheelTravel(run, robot, robot);
    } catch (const InputError& e) {
      throw InputError(data.path, run.lines.empty() ? 0 : run.lines.front(), 0, e.message());
    }
    // The true robot's travel and wheelbase (NoiseFitInputOptions::systematic).
    const SystematicErrors& sys = options.systematic;
    WheelTravel true_travel = travel;
    for (double& v : true_travel.left_m) v *= sys.c_L;
    for (double& v : true_travel.right_m) v *= sys.c_R;
    const double true_wheelbase = sys.E_b * robot.wheelbase_m;
    const TrajectoryCovarianceSummary kelly = TrajectoryCovariance(true_travel, true_wheelbase);
    const Pose2 odo = IntegrateOdometry(travel, robot.wheelbase_m, Pose2{}).back();
    const Pose2 gt = RelativeTo(run.GroundTruth(0), run.GroundTruth(n - 1));  // contract: GT in its first frame
    WheelNoiseFitRun f;
    f.group = group_prefix + run.direction;
    // Runs without a cw/ccw label (e.g. circles both ways imported as one
    // `free` experiment) are grouped by the way they turn: opposite
    // directions have opposite systematic means, pooling them around one
    // mean would read the difference as noise.
    if (run.direction != "cw" && run.direction != "ccw" && std::abs(odo.theta) > 1.0) {
      f.group += odo.theta < 0.0 ? ":cw" : ":ccw";
    }
    f.run = run.run;
    f.error = Eigen::Vector3d(gt.x - odo.x, gt.y - odo.y, WrapAngle(gt.theta - odo.theta));
    f.basis = kelly.motion;
    if (options.second_order) f.second_order = SecondOrderHeadingBasis(true_travel, true_wheelbase);
    f.measurement = MeasurementCovariance(options.sigma_xy_m, options.sigma_theta_rad, odo);
    for (std::size_t i = 1; i < travel.left_m.size(); ++i) {
      f.odometry_travel.push_back({travel.left_m[i] - travel.left_m[i - 1], travel.right_m[i] - travel.right_m[i - 1]});
    }
    f.recorded_wheelbase_m = robot.wheelbase_m;
    out.push_back(f);
  }
  if (skipped) *skipped = skip;
  return out;
}

namespace {

/// Noise-free return error e = true - odometry of a run whose odometry
/// measured `travel` (wheelbase b), for a robot with systematic errors x =
/// [E_b, c_L, c_R] (exact arc steps: each piece has constant curvature).
Eigen::Vector3d SystematicReturnError(const std::vector<WheelSegment>& travel, double b, const Eigen::Vector3d& x) {
  Pose2 truth, odo;
  for (const WheelSegment& w : travel) {
    truth = DiffDriveStep(truth, x(1) * w.left_m, x(2) * w.right_m, x(0) * b, Integrator::kArc);
    odo = DiffDriveStep(odo, w.left_m, w.right_m, b, Integrator::kArc);
  }
  return {truth.x - odo.x, truth.y - odo.y, truth.theta - odo.theta};
}

}  // namespace

SystematicErrors EstimateSystematicErrors(const std::vector<WheelNoiseFitRun>& runs,
                                          const WheelNoiseFitSummary& fit) {
  // Per group: its fitted mean, the information of that mean (sum of the
  // runs' inverse covariances; heading dropped for runs without it) and the
  // runs that can predict it.
  const std::size_t G = fit.groups.size();
  std::vector<Eigen::Matrix3d> info(G, Eigen::Matrix3d::Zero());
  std::vector<std::vector<std::size_t>> members(G);
  for (std::size_t i = 0; i < runs.size() && i < fit.predicted_run_covariance.size(); ++i) {
    if (runs[i].odometry_travel.empty()) continue;
    const auto g = static_cast<std::size_t>(
        std::find(fit.groups.begin(), fit.groups.end(), runs[i].group) - fit.groups.begin());
    if (g >= G) continue;
    Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
    const PoseCovariance& S = fit.predicted_run_covariance[i];
    if (runs[i].has_theta) {
      W = S.inverse();
    } else {
      W.topLeftCorner<2, 2>() = S.topLeftCorner<2, 2>().inverse();
    }
    info[g] += W;
    members[g].push_back(i);
  }
  auto model = [&](std::size_t g, const Eigen::Vector3d& x) {
    Eigen::Vector3d m = Eigen::Vector3d::Zero();
    for (std::size_t i : members[g]) m += SystematicReturnError(runs[i].odometry_travel, runs[i].recorded_wheelbase_m, x);
    return Eigen::Vector3d(m / static_cast<double>(members[g].size()));
  };
  // Gauss-Newton with a weak prior (sigma 0.05) towards 1, central
  // differences for the 3 x 3 Jacobian of each group's mean.
  constexpr double kPriorSigma = 0.05;
  Eigen::Vector3d x(1.0, 1.0, 1.0);
  bool any = false;
  for (std::size_t g = 0; g < G; ++g) any = any || !members[g].empty();
  if (!any) return {};
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Identity() / (kPriorSigma * kPriorSigma);
    Eigen::Vector3d grad = (x - Eigen::Vector3d::Ones()) / (kPriorSigma * kPriorSigma);
    for (std::size_t g = 0; g < G; ++g) {
      if (members[g].empty()) continue;
      const Eigen::Vector3d r = model(g, x) - fit.group_means[g];
      Eigen::Matrix3d J;
      for (int k = 0; k < 3; ++k) {
        const double h = 1e-6;
        Eigen::Vector3d xp = x, xm = x;
        xp(k) += h;
        xm(k) -= h;
        J.col(k) = (model(g, xp) - model(g, xm)) / (2.0 * h);
      }
      H += J.transpose() * info[g] * J;
      grad += J.transpose() * info[g] * r;
    }
    const Eigen::Vector3d step = H.ldlt().solve(grad);
    x -= step;
    if (!x.allFinite()) return {};
    if (step.norm() < 1e-10) break;
  }
  return {x(0), x(1), x(2)};
}

WheelNoiseFitSummary FitWheelNoiseWithSystematics(
    const std::function<std::vector<WheelNoiseFitRun>(const SystematicErrors&)>& build,
    const WheelNoiseFitOptions& options, SystematicErrors* estimated) {
  WheelNoiseFitOptions quick = options;
  quick.intervals = false;
  quick.progress = nullptr;  // only the final fit reports (its stages are the long part)
  const std::vector<WheelNoiseFitRun> runs0 = build(SystematicErrors{});
  const SystematicErrors from_means = EstimateSystematicErrors(runs0, FitWheelNoise(runs0, quick));
  // E_d by profile likelihood, the mean diameter factor and E_b kept.
  const double scale = 0.5 * (from_means.c_L + from_means.c_R);
  auto with_ed = [&](double E_d) {
    return SystematicErrors{from_means.E_b, 2.0 * scale / (E_d + 1.0), 2.0 * scale * E_d / (E_d + 1.0)};
  };
  auto quick_fit = [&](double E_d) -> std::optional<WheelNoiseFitSummary> {
    try {
      return FitWheelNoise(build(with_ed(E_d)), quick);
    } catch (const std::runtime_error&) {  // a fit that fails is not the optimum
      return std::nullopt;
    }
  };
  auto nll = [&](double E_d) {
    const auto f = quick_fit(E_d);
    return f ? f->neg_log_likelihood : std::numeric_limits<double>::infinity();
  };
  const double ed0 = from_means.c_R / from_means.c_L;
  std::uintmax_t iterations = 30;
  const auto best = boost::math::tools::brent_find_minima(nll, ed0 - 0.03, ed0 + 0.03, 20, iterations);
  const SystematicErrors chosen = with_ed(best.first);
  if (estimated) *estimated = chosen;
  WheelNoiseFitSummary out = FitWheelNoise(build(chosen), options);
  if (!options.intervals) return out;
  // The intervals above hold E_d at its estimate. Its uncertainty (from the
  // curvature of the profile likelihood in E_d) moves k by dk/dE_d; each
  // interval end is widened by the delta method,
  //   half width * sqrt(1 + (dk/dE_d sigma_E_d / sigma_k)^2),
  // sigma_k the interval's own width / (2 z).
  const double h = 0.002;
  const auto lo = quick_fit(best.first - h), hi = quick_fit(best.first + h);
  if (!lo || !hi) return out;
  const double curvature = (lo->neg_log_likelihood + hi->neg_log_likelihood - 2.0 * best.second) / (h * h);
  if (!(curvature > 0.0)) return out;
  const double sigma_ed = 1.0 / std::sqrt(curvature);
  const double z = boost::math::quantile(boost::math::normal(), 0.5 + 0.5 * options.confidence);
  auto widen = [&](double k, std::array<double, 2>& ci, double dk) {
    if (!std::isfinite(ci[0]) || !std::isfinite(ci[1]) || !(ci[1] > ci[0])) return;
    const double sigma_k = (ci[1] - ci[0]) / (2.0 * z);
    const double factor = std::sqrt(1.0 + std::pow(dk * sigma_ed / sigma_k, 2));
    ci[0] = std::max(0.0, k - (k - ci[0]) * factor);
    ci[1] = k + (ci[1] - k) * factor;
  };
  widen(out.k_L, out.k_L_ci, (hi->k_L - lo->k_L) / (2.0 * h));
  widen(out.k_R, out.k_R_ci, (hi->k_R - lo->k_R) / (2.0 * h));
  return out;
}

}  // namespace umbmark
