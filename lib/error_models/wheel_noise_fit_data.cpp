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

#include <stdexcept>

#include <Eigen/Cholesky>
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
    f.line = r.line;
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
    f.line = run.lines.empty() ? 0 : run.lines.front();
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
  return EstimateSystematicErrorsWithSe(runs, fit).value;
}

SystematicEstimate EstimateSystematicErrorsWithSe(const std::vector<WheelNoiseFitRun>& runs,
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
  SystematicEstimate out;
  if (!any) {
    out.E_b_se = kPriorSigma;
    out.E_b_determined = false;
    return out;
  }
  Eigen::Matrix3d H_last = Eigen::Matrix3d::Identity() / (kPriorSigma * kPriorSigma);
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
    H_last = H;
    if (!x.allFinite()) return {};
    if (step.norm() < 1e-10) break;
  }
  out.value = {x(0), x(1), x(2)};
  // Posterior standard deviation of E_b: near the prior's, the means do not see it.
  out.E_b_se = std::sqrt(std::max(H_last.inverse()(0, 0), 0.0));
  out.E_b_determined = out.E_b_se < 0.5 * kPriorSigma;
  return out;
}

namespace {

/// Per-run sensitivities of the bases to E_d (WheelNoiseRunSensitivity) by
/// central differences of builds at E0 - h and E0 + h about `centre` (built
/// at E0); one extra build is alive at a time.
std::vector<WheelNoiseRunSensitivity> Sensitivities(const std::vector<WheelNoiseFitRun>& centre,
                                                    const std::function<std::vector<WheelNoiseFitRun>(double)>& at,
                                                    double E0, double h) {
  std::vector<WheelNoiseRunSensitivity> s(centre.size());
  for (const double sign : {-1.0, 1.0}) {
    const std::vector<WheelNoiseFitRun> side = at(E0 + sign * h);
    if (side.size() != centre.size()) throw std::logic_error("fit-noise: builds differ in their runs");
    for (std::size_t i = 0; i < side.size(); ++i) {
      const WheelNoiseFitRun &c = centre[i], &r = side[i];
      WheelNoiseRunSensitivity& d = s[i];
      auto add = [&](PoseCovariance& d1, PoseCovariance& d2, const PoseCovariance& v, const PoseCovariance& v0) {
        d1 += sign / (2.0 * h) * v;                        // (f+ - f-) / 2h
        d2 += (v - v0) / (2.0 * h * h);                    // (f+ - 2 f0 + f-) / 2h^2
      };
      add(d.d1.A_L, d.d2.A_L, r.basis.A_L, c.basis.A_L);
      add(d.d1.A_R, d.d2.A_R, r.basis.A_R, c.basis.A_R);
      add(d.q1.LL, d.q2.LL, r.second_order.LL, c.second_order.LL);
      add(d.q1.LR, d.q2.LR, r.second_order.LR, c.second_order.LR);
      add(d.q1.RR, d.q2.RR, r.second_order.RR, c.second_order.RR);
    }
  }
  return s;
}

}  // namespace

// Steps: (1) E_b and the scale from the group means (EstimateSystematicErrors);
// (2) the bases at E_d0 and their sensitivities, E_d fitted jointly with k
// by Fisher scoring; recentred at the fitted E_d until the offset is under a
// quarter of the difference step (the quadratic expansion is then exact to
// far below the noise); (3) the final fit with E_d profiled in the intervals.
WheelNoiseFitSummary FitWheelNoiseWithSystematics(
    const std::function<std::vector<WheelNoiseFitRun>(const SystematicErrors&)>& build,
    const WheelNoiseFitOptions& options, SystematicEstimate* estimated) {
  WheelNoiseFitOptions quick = options;
  quick.intervals = false;
  quick.progress = nullptr;  // only the final fit reports (its stages are the long part)
  SystematicEstimate from_means;
  {
    const std::vector<WheelNoiseFitRun> runs0 = build(SystematicErrors{});
    from_means = EstimateSystematicErrorsWithSe(runs0, FitWheelNoise(runs0, quick));
  }
  const SystematicErrors& m = from_means.value;
  const double scale = 0.5 * (m.c_L + m.c_R), E_means = m.c_R / m.c_L;
  auto with_ed = [&](double E_d) {
    return SystematicErrors{m.E_b, 2.0 * scale / (E_d + 1.0), 2.0 * scale * E_d / (E_d + 1.0)};
  };
  auto at = [&](double E_d) { return build(with_ed(E_d)); };
  constexpr double kStep = 0.004;  // difference step in E_d
  double E0 = E_means;
  WheelNoiseFitSummary out;
  bool determined = true;
  for (int pass = 0;; ++pass) {
    const std::vector<WheelNoiseFitRun> runs = at(E0);
    const std::vector<WheelNoiseRunSensitivity> sens = Sensitivities(runs, at, E0, kStep);
    WheelNoiseFitOptions o = quick;
    o.E_d_prior_centre = E_means - E0;
    const WheelNoiseFitSummary f = FitWheelNoise(runs, o, &sens);
    if (std::abs(E0 + f.E_d_offset - E_means) > kMaxJointEdShift) {
      determined = false;  // keep the means' E_d (see SystematicEstimate::E_d_determined)
      E0 = E_means;
      break;
    }
    if (std::abs(f.E_d_offset) > 0.25 * kStep && pass < 4) {
      E0 += f.E_d_offset;
      continue;
    }
    o.intervals = options.intervals;
    o.progress = options.progress;
    out = options.intervals ? FitWheelNoise(runs, o, &sens) : f;
    out.likelihood_passes += options.intervals ? f.likelihood_passes : 0;
    break;
  }
  if (!determined) out = FitWheelNoise(at(E_means), options);
  if (estimated) {
    *estimated = from_means;
    estimated->value = with_ed(E0 + out.E_d_offset);
    estimated->E_d_se = out.E_d_offset_se;
    estimated->E_d_determined = determined;
  }
  return out;
}

}  // namespace umbmark
