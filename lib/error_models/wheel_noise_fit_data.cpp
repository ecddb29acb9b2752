// Data files -> fit-noise runs; see wheel_noise_fit_data.hpp.
#include "error_models/wheel_noise_fit_data.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

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

void RebuildNoiseRun(WheelNoiseFitRun& r, const SystematicErrors& x) {
  if (r.odometry_travel.empty()) return;
  r.systematic = SystematicReturnError(r.odometry_travel, r.recorded_wheelbase_m, Eigen::Vector3d(x.E_b, x.c_L, x.c_R));
  const double b = x.E_b * r.recorded_wheelbase_m;
  if (r.kelly_basis) {
    // Cumulative true wheel travel at every sample.
    WheelTravel t;
    t.left_m.reserve(r.odometry_travel.size() + 1);
    t.right_m.reserve(r.odometry_travel.size() + 1);
    double L = 0.0, R = 0.0;
    t.left_m.push_back(0.0);
    t.right_m.push_back(0.0);
    for (const WheelSegment& w : r.odometry_travel) {
      L += x.c_L * w.left_m;
      R += x.c_R * w.right_m;
      t.left_m.push_back(L);
      t.right_m.push_back(R);
    }
    r.basis = TrajectoryCovariance(t, b).motion;
    r.second_order = r.with_second_order ? SecondOrderTerms(SecondOrderHeadingBasis(t, b)) : SecondOrderTerms{};
    return;
  }
  std::vector<WheelSegment> wheels = r.odometry_travel;
  for (WheelSegment& w : wheels) w = {x.c_L * w.left_m, x.c_R * w.right_m};
  r.basis = PredictPathCovariance(wheels, b, WheelNoise{}, PoseCovariance::Zero()).motion;
  r.second_order = r.with_second_order ? SecondOrderTerms(SecondOrderHeadingBasis(wheels, b)) : SecondOrderTerms{};
}

std::vector<WheelNoiseFitRun> NoiseRunsFromEndpoints(const EndpointData& data, const std::vector<PathSegment>& path,
                                                double wheelbase_m, const std::string& group_prefix,
                                                const NoiseFitInputOptions& options) {
  // One run template: the odometry's path, the bases along the path the
  // true robot drove (see NoiseFitInputOptions::systematic), the reference
  // noise at the path's end.
  WheelNoiseFitRun t;
  t.odometry_travel = ToWheelSegments(path, wheelbase_m);
  t.recorded_wheelbase_m = wheelbase_m;
  t.with_second_order = options.second_order;
  RebuildNoiseRun(t, options.systematic);
  const Pose2 end = PredictPathCovariance(t.odometry_travel, wheelbase_m, WheelNoise{}, PoseCovariance::Zero()).mean;
  t.measurement = MeasurementCovariance(options.sigma_xy_m, options.sigma_theta_rad, end);
  std::vector<WheelNoiseFitRun> out;
  out.reserve(data.runs.size());
  for (const ReturnError& r : data.runs) {
    WheelNoiseFitRun f = t;
    f.group = group_prefix + r.direction;
    f.run = r.run;
    f.line = r.line;
    f.has_theta = r.etheta_rad.has_value();
    f.error = Eigen::Vector3d(r.ex_m, r.ey_m, f.has_theta ? WrapAngle(*r.etheta_rad) : 0.0);
    out.push_back(std::move(f));
  }
  return out;
}

std::optional<WheelNoiseFitRun> NoiseRunFromTrajectory(const TrajectoryRun& run, const std::string& path,
                                                       const RobotParams& robot, const std::string& group_prefix,
                                                       const NoiseFitInputOptions& options) {
  const std::size_t n = run.size();
  if (n < 2 || !run.HasGroundTruth(0) || !run.HasGroundTruth(n - 1)) return std::nullopt;
  WheelTravel travel;
  try {
    travel = ComputeWheelTravel(run, robot, robot);
  } catch (const InputError& e) {
    throw InputError(path, run.lines.empty() ? 0 : run.lines.front(), 0, e.message());
  }
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
    f.turn_grouped = true;
  }
  f.run = run.run;
  f.line = run.lines.empty() ? 0 : run.lines.front();
  f.error = Eigen::Vector3d(gt.x - odo.x, gt.y - odo.y, WrapAngle(gt.theta - odo.theta));
  f.measurement = MeasurementCovariance(options.sigma_xy_m, options.sigma_theta_rad, odo);
  f.odometry_travel.reserve(travel.left_m.size() - 1);
  for (std::size_t i = 1; i < travel.left_m.size(); ++i) {
    f.odometry_travel.push_back({travel.left_m[i] - travel.left_m[i - 1], travel.right_m[i] - travel.right_m[i - 1]});
  }
  f.recorded_wheelbase_m = robot.wheelbase_m;
  f.kelly_basis = true;
  f.with_second_order = options.second_order;
  // The bases along the path the true robot drove (NoiseFitInputOptions::systematic).
  RebuildNoiseRun(f, options.systematic);
  return f;
}

std::vector<WheelNoiseFitRun> NoiseRunsFromTrajectories(const TrajectoryData& data, const RobotParams& robot,
                                                   const std::string& group_prefix,
                                                   const NoiseFitInputOptions& options, int* skipped) {
  std::vector<WheelNoiseFitRun> out;
  int skip = 0;
  for (const TrajectoryRun& run : data.runs) {
    if (auto f = NoiseRunFromTrajectory(run, data.path, robot, group_prefix, options)) {
      out.push_back(std::move(*f));
    } else {
      ++skip;
    }
  }
  if (skipped) *skipped = skip;
  MergeLoneTurnGroups(out);
  return out;
}

void MergeLoneTurnGroups(std::vector<WheelNoiseFitRun>& runs) {
  // Per experiment group (the name before the split): the runs of each part
  // (not turning, ":cw", ":ccw"); a part with one run undoes the split.
  auto base = [](const WheelNoiseFitRun& r) { return r.turn_grouped ? r.group.substr(0, r.group.rfind(':')) : r.group; };
  std::map<std::string, bool> split_anywhere;
  for (const WheelNoiseFitRun& r : runs)
    if (r.turn_grouped) split_anywhere[base(r)] = true;
  if (split_anywhere.empty()) return;
  std::map<std::string, int> count;
  for (const WheelNoiseFitRun& r : runs)
    if (split_anywhere.count(base(r))) ++count[r.group];
  std::map<std::string, bool> undo;
  for (const WheelNoiseFitRun& r : runs)
    if (split_anywhere.count(base(r)) && count[r.group] < 2) undo[base(r)] = true;
  for (WheelNoiseFitRun& r : runs) {
    if (!r.turn_grouped || !undo.count(base(r))) continue;
    r.group = base(r);
    r.turn_grouped = false;
  }
}


SystematicErrors EstimateSystematicErrors(const std::vector<WheelNoiseFitRun>& runs,
                                          const WheelNoiseFitSummary& fit) {
  return EstimateSystematicErrorsWithSe(runs, fit).value;
}

namespace {

/// Range of the odometry's heading along a run's travel [rad].
double HeadingSweep(const std::vector<WheelSegment>& travel, double b) {
  double th = 0.0, lo = 0.0, hi = 0.0;
  for (const WheelSegment& w : travel) {
    th += (w.right_m - w.left_m) / b;
    lo = std::min(lo, th);
    hi = std::max(hi, th);
  }
  return hi - lo;
}

}  // namespace

// Gauss-Newton on sum_i (e_i - s_i(x))^T S_i^-1 (e_i - s_i(x)) + |x - 1|^2 /
// 0.05^2 over x = (E_b, c_L, c_R), s_i(x) run i's noise-free return error
// along its own odometry travel (SystematicReturnError), S_i the run's
// covariance at the fit. For the runs of a group that all drove one path
// this is the fit of the group's mean; runs of different paths (free paths)
// each count with their own prediction.
SystematicEstimate EstimateSystematicErrorsWithSe(const std::vector<WheelNoiseFitRun>& runs,
                                                  const WheelNoiseFitSummary& fit) {
  // The runs that can predict their error; their weights S_i^-1 (heading
  // dropped for runs without it), computed where used (no per-run copy:
  // memory with 10^6 runs).
  std::vector<std::size_t> members;
  for (std::size_t i = 0; i < runs.size() && i < fit.predicted_run_covariance.size(); ++i)
    if (!runs[i].odometry_travel.empty()) members.push_back(i);
  auto weight = [&](std::size_t i) {
    Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
    const PoseCovariance& S = fit.predicted_run_covariance[i];
    if (runs[i].has_theta) {
      W = S.inverse();
    } else {
      W.topLeftCorner<2, 2>() = S.topLeftCorner<2, 2>().inverse();
    }
    return W;
  };
  constexpr double kPriorSigma = 0.05;
  SystematicEstimate out;
  for (const WheelNoiseFitRun& r : runs)
    if (!out.turns && r.recorded_wheelbase_m > 0.0 && HeadingSweep(r.odometry_travel, r.recorded_wheelbase_m) > kTurnRad)
      out.turns = true;
  if (members.empty()) {
    out.E_b_se = kPriorSigma;
    out.E_d_se_means = kPriorSigma;
    out.E_b_determined = false;
    return out;
  }
  auto predict = [&](std::size_t i, const Eigen::Vector3d& x) {
    return SystematicReturnError(runs[i].odometry_travel, runs[i].recorded_wheelbase_m, x);
  };
  Eigen::Vector3d x(1.0, 1.0, 1.0);
  Eigen::Matrix3d H_last = Eigen::Matrix3d::Identity() / (kPriorSigma * kPriorSigma);
  for (int it = 0; it < 20; ++it) {
    Eigen::Matrix3d H = Eigen::Matrix3d::Identity() / (kPriorSigma * kPriorSigma);
    Eigen::Vector3d grad = (x - Eigen::Vector3d::Ones()) / (kPriorSigma * kPriorSigma);
    for (const std::size_t i : members) {
      const Eigen::Matrix3d W = weight(i);
      Eigen::Vector3d r = predict(i, x) - runs[i].error;
      r(2) = WrapAngle(r(2));
      Eigen::Matrix3d J;
      for (int k = 0; k < 3; ++k) {  // central differences
        const double h = 1e-6;
        Eigen::Vector3d xp = x, xm = x;
        xp(k) += h;
        xm(k) -= h;
        J.col(k) = (predict(i, xp) - predict(i, xm)) / (2.0 * h);
      }
      H += J.transpose() * W * J;
      grad += J.transpose() * W * r;
    }
    const Eigen::Vector3d step = H.ldlt().solve(grad);
    x -= step;
    H_last = H;
    if (!x.allFinite()) return {};
    if (step.norm() < 1e-9) break;  // far below any standard error of x (1e-6 with 10^6 runs)
  }
  out.value = {x(0), x(1), x(2)};
  // Posterior standard deviations: near the prior's, the runs do not show it.
  const Eigen::Matrix3d C = H_last.inverse();
  out.E_b_se = std::sqrt(std::max(C(0, 0), 0.0));
  out.E_b_determined = out.E_b_se < 0.5 * kPriorSigma;
  const Eigen::Vector3d g(0.0, -x(2) / (x(1) * x(1)), 1.0 / x(1));  // d(c_R / c_L) / dx
  out.E_d_se_means = std::sqrt(std::max(g.dot(C * g), 0.0));
  return out;
}

namespace {

/// Per-run sensitivities of the first-order bases to E_d
/// (WheelNoiseRunSensitivity) by central differences of rebuilds at
/// `lo` and `hi` (E_d0 -+ h) of each run built at E_d0: one run's copy at a
/// time, so memory stays at one set of runs.
std::vector<WheelNoiseRunSensitivity> Sensitivities(const std::vector<WheelNoiseFitRun>& centre,
                                                    const SystematicErrors& lo, const SystematicErrors& hi, double h) {
  std::vector<WheelNoiseRunSensitivity> s(centre.size());
  WheelNoiseFitRun side;
  for (std::size_t i = 0; i < centre.size(); ++i) {
    const WheelNoiseFitRun& c = centre[i];
    WheelNoiseRunSensitivity& d = s[i];
    side.odometry_travel = c.odometry_travel;
    side.recorded_wheelbase_m = c.recorded_wheelbase_m;
    side.kelly_basis = c.kelly_basis;
    side.with_second_order = false;  // only the first-order bases move (WheelNoiseRunSensitivity)
    PoseCovariance d1L = PoseCovariance::Zero(), d1R = d1L, d2L = d1L, d2R = d1L;
    for (const double sign : {-1.0, 1.0}) {
      RebuildNoiseRun(side, sign < 0.0 ? lo : hi);
      d1L += sign / (2.0 * h) * side.basis.A_L;  // (f+ - f-) / 2h
      d1R += sign / (2.0 * h) * side.basis.A_R;
      d2L += (side.basis.A_L - c.basis.A_L) / (2.0 * h * h);  // (f+ - 2 f0 + f-) / 2h^2
      d2R += (side.basis.A_R - c.basis.A_R) / (2.0 * h * h);
    }
    d.d1_L = d1L.cast<float>();
    d.d1_R = d1R.cast<float>();
    d.d2_L = d2L.cast<float>();
    d.d2_R = d2R.cast<float>();
  }
  return s;
}

void RebuildAll(std::vector<WheelNoiseFitRun>& runs, const SystematicErrors& x) {
  for (WheelNoiseFitRun& r : runs) RebuildNoiseRun(r, x);
}

}  // namespace

// Steps: (1) E_b and the scale from the group means (EstimateSystematicErrors);
// (2) the bases at E_d0 and their sensitivities, E_d fitted jointly with k
// by Fisher scoring; recentred at the fitted E_d until the offset is under a
// quarter of the difference step (the quadratic expansion is then exact to
// far below the noise); (3) the final fit with E_d profiled in the intervals.
WheelNoiseFitSummary FitWheelNoiseWithSystematics(std::vector<WheelNoiseFitRun>& runs,
                                                  const WheelNoiseFitOptions& options, SystematicEstimate* estimated) {
  WheelNoiseFitOptions quick = options;
  quick.intervals = false;
  quick.progress = nullptr;  // only the final fit reports (its stages are the long part)
  const SystematicEstimate from_means = EstimateSystematicErrorsWithSe(runs, FitWheelNoise(runs, quick));
  const SystematicErrors& m = from_means.value;
  const double scale = 0.5 * (m.c_L + m.c_R), E_means = m.c_R / m.c_L;
  auto with_ed = [&](double E_d) {
    return SystematicErrors{m.E_b, 2.0 * scale / (E_d + 1.0), 2.0 * scale * E_d / (E_d + 1.0)};
  };
  constexpr double kStep = 0.004;  // difference step in E_d
  double E0 = E_means;
  WheelNoiseFitSummary out;
  bool determined = true;
  for (int pass = 0;; ++pass) {
    RebuildAll(runs, with_ed(E0));
    const std::vector<WheelNoiseRunSensitivity> sens = Sensitivities(runs, with_ed(E0 - kStep), with_ed(E0 + kStep), kStep);
    WheelNoiseFitOptions o = quick;
    // The prior on E_d is what the runs' means say about it (its standard
    // error, at most the weak default): the scatter refines E_d only where
    // the means leave it open (a path that retraces itself).
    o.E_d_prior_centre = E_means - E0;
    o.E_d_prior_sigma = std::min(options.E_d_prior_sigma, std::max(from_means.E_d_se_means, 1e-6));
    WheelNoiseFitSummary f = FitWheelNoise(runs, o, &sens);
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
    if (f.k_L > 0.0 && f.k_R > 0.0) o.start = Eigen::Vector3d(std::log(f.k_L), std::log(f.k_R), f.E_d_offset);
    if (options.intervals) {  // f's per-run vectors are not needed by the final fit (memory with 10^6 runs)
      std::vector<Eigen::Vector3d>().swap(f.residuals);
      std::vector<PoseCovariance>().swap(f.predicted_run_covariance);
    }
    out = options.intervals ? FitWheelNoise(runs, o, &sens) : f;
    out.likelihood_passes += options.intervals ? f.likelihood_passes : 0;
    break;
  }
  if (!determined) {
    RebuildAll(runs, with_ed(E_means));
    out = FitWheelNoise(runs, options);
  }
  if (estimated) {
    *estimated = from_means;
    estimated->value = with_ed(E0 + out.E_d_offset);
    estimated->E_d_se = out.E_d_offset_se;
    estimated->E_d_determined = determined;
  }
  return out;
}

WheelNoiseFitSummary FitWheelNoiseWithSystematics(
    const std::function<std::vector<WheelNoiseFitRun>(const SystematicErrors&)>& build,
    const WheelNoiseFitOptions& options, SystematicEstimate* estimated) {
  std::vector<WheelNoiseFitRun> runs = build(SystematicErrors{});
  return FitWheelNoiseWithSystematics(runs, options, estimated);
}

}  // namespace umbmark
