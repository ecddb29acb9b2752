// Refined calibration: option checks, enum names and the shared driver that
// solves, checks the solver, assesses identifiability and forms covariance
// and intervals (see refine.hpp, refine_internal.hpp).
#include "calibration/refine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <ceres/cost_function.h>
#include <ceres/covariance.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/solver.h>
#include <fmt/format.h>

#include "calibration/refine_internal.hpp"
#include "stats/distributions.hpp"

namespace umbmark {

const char* RobustLossToString(RobustLoss l) {
  switch (l) {
    case RobustLoss::kNone: return "none";
    case RobustLoss::kHuber: return "huber";
    case RobustLoss::kCauchy: return "cauchy";
  }
  return "?";
}

std::optional<RobustLoss> RobustLossFromString(std::string_view s) {
  if (s == "none") return RobustLoss::kNone;
  if (s == "huber") return RobustLoss::kHuber;
  if (s == "cauchy") return RobustLoss::kCauchy;
  return std::nullopt;
}

const char* ScaleModeToString(ScaleMode m) {
  switch (m) {
    case ScaleMode::kAuto: return "auto";
    case ScaleMode::kFixed: return "fixed";
    case ScaleMode::kFree: return "free";
  }
  return "?";
}

std::optional<ScaleMode> ScaleModeFromString(std::string_view s) {
  if (s == "auto") return ScaleMode::kAuto;
  if (s == "fixed") return ScaleMode::kFixed;
  if (s == "free") return ScaleMode::kFree;
  return std::nullopt;
}

const char* TrajectoryCovarianceToString(TrajectoryCovariance c) {
  return c == TrajectoryCovariance::kRunClustered ? "run_clustered" : "solver_scaled";
}

std::optional<TrajectoryCovariance> TrajectoryCovarianceFromString(std::string_view s) {
  if (s == "run_clustered") return TrajectoryCovariance::kRunClustered;
  if (s == "solver_scaled") return TrajectoryCovariance::kSolverScaled;
  return std::nullopt;
}

const char* PoseSamplingToString(PoseSampling s) {
  return s == PoseSampling::kPerRun ? "per_run" : "every_sample";
}

std::optional<PoseSampling> PoseSamplingFromString(std::string_view s) {
  if (s == "per_run") return PoseSampling::kPerRun;
  if (s == "every_sample") return PoseSampling::kEverySample;
  return std::nullopt;
}

const char* StartPoseToString(StartPose s) {
  switch (s) {
    case StartPose::kFirstSample: return "first_sample";
    case StartPose::kStandstillMean: return "standstill_mean";
    case StartPose::kFitted: return "fitted";
    case StartPose::kSessionFrame: return "session_frame";
  }
  return "?";
}

std::optional<StartPose> StartPoseFromString(std::string_view s) {
  if (s == "first_sample") return StartPose::kFirstSample;
  if (s == "standstill_mean") return StartPose::kStandstillMean;
  if (s == "fitted") return StartPose::kFitted;
  if (s == "session_frame") return StartPose::kSessionFrame;
  return std::nullopt;
}

const char* RefineInputKindToString(RefineInputKind k) {
  return k == RefineInputKind::kReturnErrors ? "return_errors" : "trajectories";
}

std::optional<RefineInputKind> RefineInputKindFromString(std::string_view s) {
  if (s == "return_errors") return RefineInputKind::kReturnErrors;
  if (s == "trajectories") return RefineInputKind::kTrajectories;
  return std::nullopt;
}

std::string RefineOptions::Check() const {
  auto positive = [](const char* name, double v) -> std::string {
    if (!std::isfinite(v) || !(v > 0.0)) return fmt::format("{} = {} must be a finite number > 0", name, v);
    return {};
  };
  auto non_negative = [](const char* name, double v) -> std::string {
    if (!std::isfinite(v) || v < 0.0) return fmt::format("{} = {} must be a finite number >= 0", name, v);
    return {};
  };
  for (auto e : {positive("start.E_b", start.E_b), positive("start.E_d", start.E_d),
                 positive("start.E_s", start.E_s)}) {
    if (!e.empty()) return e;
  }
  if (!(confidence > 0.0 && confidence < 1.0)) return fmt::format("confidence = {} must be in (0, 1)", confidence);
  if (auto e = positive("max_relative_sigma", max_relative_sigma); !e.empty()) return e;
  if (!(max_condition_number > 1.0)) {
    return fmt::format("max_condition_number = {} must be > 1", max_condition_number);
  }
  if (max_num_iterations < 1) return fmt::format("max_num_iterations = {} must be >= 1", max_num_iterations);
  for (auto e : {non_negative("function_tolerance", function_tolerance),
                 non_negative("gradient_tolerance", gradient_tolerance),
                 non_negative("parameter_tolerance", parameter_tolerance)}) {
    if (!e.empty()) return e;
  }
  if (num_threads < 1) return fmt::format("num_threads = {} must be >= 1", num_threads);
  if (min_runs_for_group_covariance < 2) {
    return fmt::format("min_runs_for_group_covariance = {} must be >= 2", min_runs_for_group_covariance);
  }
  for (auto e : {non_negative("sigma_floor_xy_m", sigma_floor_xy_m),
                 non_negative("sigma_floor_theta_rad", sigma_floor_theta_rad),
                 positive("prior_sigma_xy_m", prior_sigma_xy_m),
                 positive("prior_sigma_theta_rad", prior_sigma_theta_rad)}) {
    if (!e.empty()) return e;
  }
  if (samples_per_run < 1) return fmt::format("samples_per_run = {} must be >= 1", samples_per_run);
  if (!std::isfinite(heading_length_m)) {
    return fmt::format("heading_length_m = {} must be finite (<= 0 selects the wheelbase)", heading_length_m);
  }
  if (!std::isfinite(heading_weight) || heading_weight < 0.0) {
    return fmt::format("heading_weight = {} must be a finite number >= 0", heading_weight);
  }
  if (loss != RobustLoss::kNone) {
    if (auto e = positive("loss_scale_m", loss_scale_m); !e.empty()) return e;
  }
  return {};
}

RefineOptions PlainLeastSquaresOptions() {
  RefineOptions o;
  o.heading_weight = 0.0;
  o.loss = RobustLoss::kNone;
  o.sampling = PoseSampling::kEverySample;
  o.start_pose = StartPose::kFirstSample;
  o.scale = ScaleMode::kFree;
  return o;
}

RobotParams ApplyRefinedFactors(const RobotParams& reference, double E_b, double E_d, double E_s) {
  const double theta[kNumRefineParameters] = {E_b, E_d, E_s};
  double c_L = 0.0, c_R = 0.0;
  WheelFactors(theta, &c_L, &c_R);
  RobotParams p = reference;
  p.wheelbase_m = E_b * reference.wheelbase_m;                       // eq. 4.26
  p.wheel_diameter_left_m = c_L * reference.wheel_diameter_left_m;    // eqs. 4.29, 4.31 (times E_s)
  p.wheel_diameter_right_m = c_R * reference.wheel_diameter_right_m;  // eqs. 4.30, 4.32 (times E_s)
  return p;
}

namespace refine_detail {

namespace {

constexpr const char* kThetaNames[kNumRefineParameters] = {"E_b", "E_d", "E_s"};

std::vector<int> FreeIndices(bool scale_free) {
  return scale_free ? std::vector<int>{kIndexEb, kIndexEd, kIndexEs} : std::vector<int>{kIndexEb, kIndexEd};
}

RefineInterval Interval(double value, const Eigen::Vector3d& gradient, const Eigen::Matrix3d& theta_cov,
                        double quantile) {
  RefineInterval iv;
  iv.value = value;
  iv.sigma = std::sqrt(std::max(0.0, gradient.dot(theta_cov * gradient)));
  iv.low = value - quantile * iv.sigma;
  iv.high = value + quantile * iv.sigma;
  return iv;
}

[[noreturn]] void Fail(const std::string& what, RefineSummary* summary) { throw RefineError(what, *summary); }

using BlockJacobian = Eigen::Matrix<double, Eigen::Dynamic, kNumRefineParameters, Eigen::RowMajor>;

/// Step 1: solves the problem (E_s held by a subset manifold unless free),
/// fills the solver report, E_b, E_d, E_s and the free / fixed names; fails
/// when the solution is not usable.
ceres::Solver::Summary Solve(FitProblem& fit, const RefineOptions& options, RefineSummary* summary) {
  ceres::Problem& problem = *fit.problem;
  summary->scale_free = fit.scale_free;
  // Gauge: without E_s free, the overall scale is held at its start value
  // (1 = the reference mean diameter factor) by a subset manifold.
  if (!fit.scale_free) problem.SetManifold(fit.theta, new ceres::SubsetManifold(kNumRefineParameters, {kIndexEs}));
  const ceres::Solver::Options so = SolverOptions(options);
  ceres::Solver::Summary cs;
  ceres::Solve(so, &problem, &cs);

  RefineSolverReport& sr = summary->solver;
  sr.termination_type = ceres::TerminationTypeToString(cs.termination_type);
  sr.message = cs.message;
  sr.brief_report = cs.BriefReport();
  sr.iterations = static_cast<int>(cs.iterations.size());
  sr.initial_cost = cs.initial_cost;
  sr.final_cost = cs.final_cost;
  sr.residual_evaluations = cs.num_residual_evaluations;
  sr.jacobian_evaluations = cs.num_jacobian_evaluations;
  sr.solve_time_s = cs.total_time_in_seconds;
  const bool positive = std::all_of(std::begin(fit.theta), std::end(fit.theta),
                                    [](double v) { return std::isfinite(v) && v > 0.0; });
  sr.usable = cs.IsSolutionUsable() && cs.termination_type == ceres::CONVERGENCE && positive;
  summary->final_cost = cs.final_cost;
  summary->E_b = fit.theta[kIndexEb];
  summary->E_d = fit.theta[kIndexEd];
  summary->E_s = fit.theta[kIndexEs];

  const std::vector<int> free = FreeIndices(fit.scale_free);
  RefineIdentifiability& id = summary->identifiability;
  id = {};
  for (int i = 0; i < kNumRefineParameters; ++i) {
    const bool is_free = std::find(free.begin(), free.end(), i) != free.end();
    (is_free ? id.free_parameters : id.fixed_parameters).emplace_back(kThetaNames[i]);
  }
  if (!sr.usable) {
    std::string why = cs.termination_type == ceres::NO_CONVERGENCE
                          ? fmt::format("no convergence within max_num_iterations = {}", options.max_num_iterations)
                          : cs.message;
    if (cs.termination_type == ceres::CONVERGENCE && !positive) {
      why = fmt::format("converged to a non-physical point (E_b = {}, E_d = {}, E_s = {})", fit.theta[0],
                        fit.theta[1], fit.theta[2]);
    }
    Fail(fmt::format("refine: the solver failed ({}): {}", sr.termination_type, why), summary);
  }
  return cs;
}

/// Step 2: the weighted Jacobian and residuals at the solution, per block
/// and stacked, and sum J_i^T Omega_i J_i.
struct SolutionJacobian {
  Eigen::MatrixXd J;
  std::vector<BlockJacobian> block_jacobians;
  std::vector<Eigen::VectorXd> block_residuals;
  Eigen::Matrix3d omega_meat = Eigen::Matrix3d::Zero();
  bool any_omega = false;
};

SolutionJacobian EvaluateAtSolution(const FitProblem& fit, RefineSummary* summary) {
  SolutionJacobian out;
  int m = 0;
  for (const auto* cost : fit.blocks) m += cost->num_residuals();
  summary->residuals = m;
  out.J.resize(m, kNumRefineParameters);
  int row = 0;
  const double* params[] = {fit.theta};
  for (const auto* cost : fit.blocks) {
    const int nb = cost->num_residuals();
    BlockJacobian jb(nb, kNumRefineParameters);
    Eigen::VectorXd rb(nb);
    double* jacobians[] = {jb.data()};
    if (!cost->Evaluate(params, rb.data(), jacobians)) {
      Fail("refine: a residual could not be evaluated at the solution", summary);
    }
    out.J.middleRows(row, nb) = jb;
    const std::size_t bi = out.block_jacobians.size();
    if (bi < fit.block_residual_covariance.size() && fit.block_residual_covariance[bi]) {
      out.omega_meat += jb.transpose() * (*fit.block_residual_covariance[bi]) * jb;
      out.any_omega = true;
    } else {
      out.omega_meat += jb.transpose() * jb;
    }
    out.block_jacobians.push_back(std::move(jb));
    out.block_residuals.push_back(std::move(rb));
    row += nb;
  }
  return out;
}

/// Step 3: identifiability. The unknowns are dimensionless factors near 1,
/// so the Jacobian's columns are comparable as they stand (singular values
/// reported); collinearity is judged on the column-normalised Jacobian
/// (Belsley's condition number). Fails when it is rank deficient.
void CheckIdentifiability(const Eigen::MatrixXd& J, const std::vector<int>& free, const FitProblem& fit,
                          const RefineOptions& options, RefineSummary* summary) {
  RefineIdentifiability& id = summary->identifiability;
  const int m = static_cast<int>(J.rows());
  const int p = static_cast<int>(free.size());
  Eigen::MatrixXd Jf(m, p);
  for (int k = 0; k < p; ++k) Jf.col(k) = J.col(free[static_cast<std::size_t>(k)]);
  const Eigen::VectorXd sv = Jf.jacobiSvd().singularValues();
  for (int k = 0; k < sv.size(); ++k) id.singular_values.push_back(sv(k));
  const Eigen::VectorXd norms = Jf.colwise().norm().transpose();
  const bool too_few = m < p;
  bool zero_column = false;
  Eigen::MatrixXd Jn = Jf;
  for (int k = 0; k < p; ++k) {
    if (norms(k) > 0.0) {
      Jn.col(k) /= norms(k);
    } else {
      zero_column = true;
    }
  }
  const double inf = std::numeric_limits<double>::infinity();
  id.condition_number = inf;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd_n;
  if (!too_few && !zero_column) {
    svd_n.compute(Jn, Eigen::ComputeThinV);
    const Eigen::VectorXd sn = svd_n.singularValues();
    if (sn(p - 1) > 0.0) id.condition_number = sn(0) / sn(p - 1);
  }
  if (id.condition_number <= options.max_condition_number) return;
  id.rank_deficient = true;
  // Parameters taking part in a direction the data do not see: a zero
  // column, or a large component of a weak right singular vector.
  for (int k = 0; k < p; ++k) {
    bool weak = too_few || !(norms(k) > 0.0);
    if (!weak && !zero_column) {
      const Eigen::VectorXd sn = svd_n.singularValues();
      for (int j = 0; j < p; ++j) {
        const bool weak_direction = !(sn(j) * options.max_condition_number >= sn(0));
        if (weak_direction && std::abs(svd_n.matrixV()(k, j)) > 0.1) weak = true;
      }
    }
    (weak ? id.undetermined : id.determined).emplace_back(kThetaNames[free[static_cast<std::size_t>(k)]]);
  }
  id.message = fmt::format(
      "rank deficient: condition number {:.3g} of the normalised Jacobian exceeds max_condition_number = {:.3g}; "
      "the data do not determine {}{}",
      id.condition_number, options.max_condition_number, fmt::join(id.undetermined, ", "),
      fit.scale_free ? " (the overall scale E_s is free: fix it)" : "");
  Fail("refine: " + id.message, summary);
}

/// Cluster-robust sandwich over runs g (runs are independent, poses
/// within a run are not): A^-1 (sum_g g_g g_g^T) A^-1 * R / (R - p),
/// g_g the gradient of run g's cost, A the Hessian of the objective.
/// Without a loss A^-1 is the Ceres covariance C. With a loss applied
/// per pose k inside the block, C would be the Gauss-Newton matrix of
/// the reweighted residual, which is not the M-estimator's Hessian, so
/// A is formed per pose from the plain residual r_k, its Jacobian J_k
/// and Ceres' rho', rho'' at s_k = |r_k|^2:
///   A = sum_k rho'_k J_k^T J_k + 2 rho''_k (J_k^T r_k)(r_k^T J_k)
/// (the Hessian Ceres' Triggs correction models; PSD for Huber).
Eigen::Matrix3d RunClusteredCovariance(const FitProblem& fit, const Eigen::Matrix3d& C, const SolutionJacobian& sj,
                                       const std::vector<int>& free, RefineSummary* summary) {
  const int p = static_cast<int>(free.size());
  Eigen::Matrix3d bread_inv = C;
  Eigen::Matrix3d meat = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d mask = Eigen::Matrix3d::Zero();
  for (int i : free) mask(i, i) = 1.0;
  if (!fit.plain_blocks.empty()) {
    std::unique_ptr<ceres::LossFunction> loss;
    if (fit.loss == RobustLoss::kHuber) loss = std::make_unique<ceres::HuberLoss>(fit.loss_scale_m);
    if (fit.loss == RobustLoss::kCauchy) loss = std::make_unique<ceres::CauchyLoss>(fit.loss_scale_m);
    Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
    const double* params[] = {fit.theta};
    for (const auto& plain : fit.plain_blocks) {
      const int nb = plain->num_residuals();
      BlockJacobian jb(nb, kNumRefineParameters);
      Eigen::VectorXd rb(nb);
      double* jacobians[] = {jb.data()};
      if (!plain->Evaluate(params, rb.data(), jacobians)) {
        Fail("refine: a residual could not be evaluated at the solution", summary);
      }
      Eigen::Vector3d g = Eigen::Vector3d::Zero();
      for (int k = 0; k + 3 <= nb; k += 3) {
        const Eigen::Vector3d rk = rb.segment<3>(k);
        const Eigen::Matrix<double, 3, kNumRefineParameters> Jk = jb.middleRows<3>(k);
        double rho[3] = {rk.squaredNorm(), 1.0, 0.0};
        if (loss) loss->Evaluate(rk.squaredNorm(), rho);
        const Eigen::Vector3d Jr = Jk.transpose() * rk;
        A += rho[1] * Jk.transpose() * Jk + 2.0 * rho[2] * Jr * Jr.transpose();
        g += rho[1] * Jr;
      }
      meat += g * g.transpose();
    }
    // Invert A on the free parameters.
    std::vector<int> idx(free.begin(), free.end());
    Eigen::MatrixXd Af(p, p);
    for (int a = 0; a < p; ++a) {
      for (int b = 0; b < p; ++b) Af(a, b) = A(idx[static_cast<std::size_t>(a)], idx[static_cast<std::size_t>(b)]);
    }
    Eigen::LLT<Eigen::MatrixXd> llt(Af);
    if (llt.info() == Eigen::Success) {
      const Eigen::MatrixXd Ai = llt.solve(Eigen::MatrixXd::Identity(p, p));
      bread_inv.setZero();
      for (int a = 0; a < p; ++a) {
        for (int b = 0; b < p; ++b) {
          bread_inv(idx[static_cast<std::size_t>(a)], idx[static_cast<std::size_t>(b)]) = Ai(a, b);
        }
      }
    } else {
      summary->notes.push_back(
          "the robust objective's Hessian is not positive definite at the solution; the run-clustered "
          "covariance uses the Gauss-Newton matrix instead");
    }
  } else {
    for (std::size_t g = 0; g < sj.block_jacobians.size(); ++g) {
      const Eigen::Vector3d gg = sj.block_jacobians[g].transpose() * sj.block_residuals[g];
      meat += gg * gg.transpose();
    }
  }
  const double R = static_cast<double>(fit.blocks.size());
  return bread_inv * (mask * meat * mask) * bread_inv * (R / (R - 1.0));  // CR1 factor R / (R - 1)
}

/// Step 4: covariance of theta (Ceres' inverse information matrix, then as
/// `kind` asks); fails when Ceres cannot invert it.
Eigen::Matrix3d ThetaCovariance(FitProblem& fit, const RefineOptions& options, CovarianceKind kind,
                                const SolutionJacobian& sj, const std::vector<int>& free, RefineSummary* summary) {
  RefineIdentifiability& id = summary->identifiability;
  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  co.num_threads = options.num_threads;
  ceres::Covariance covariance(co);
  std::vector<std::pair<const double*, const double*>> blocks = {{fit.theta, fit.theta}};
  Eigen::Matrix<double, 3, 3, Eigen::RowMajor> C;
  if (!covariance.Compute(blocks, fit.problem.get()) ||
      !covariance.GetCovarianceBlock(fit.theta, fit.theta, C.data())) {
    id.rank_deficient = true;
    id.undetermined = id.free_parameters;
    id.message = "rank deficient: ceres::Covariance could not invert the information matrix";
    Fail("refine: " + id.message, summary);
  }
  Eigen::Matrix3d cov = C;
  switch (kind) {
    case CovarianceKind::kDirect:
      if (sj.any_omega) {
        Eigen::Matrix3d mask = Eigen::Matrix3d::Zero();
        for (int i : free) mask(i, i) = 1.0;
        cov = C * (mask * sj.omega_meat * mask) * C;
      }
      break;
    case CovarianceKind::kSolverScaled:
      cov *= summary->reduced_chi2;
      if (summary->covariance_method.empty()) summary->covariance_method = "solver_scaled";
      break;
    case CovarianceKind::kRunClustered:
      cov = RunClusteredCovariance(fit, C, sj, free, summary);
      if (summary->covariance_method.empty()) summary->covariance_method = "run_clustered";
      break;
  }
  return cov;
}

/// Step 5: every free parameter's standard deviation within
/// max_relative_sigma; fails otherwise.
void CheckDetermined(const Eigen::Matrix3d& cov, const std::vector<int>& free, const FitProblem& fit,
                     const RefineOptions& options, RefineSummary* summary) {
  RefineIdentifiability& id = summary->identifiability;
  bool all_determined = true;
  for (int i : free) {
    const double sigma = std::sqrt(std::max(0.0, cov(i, i)));
    id.sigma.push_back(sigma);
    if (sigma <= options.max_relative_sigma) {
      id.determined.emplace_back(kThetaNames[i]);
    } else {
      id.undetermined.emplace_back(kThetaNames[i]);
      all_determined = false;
    }
  }
  if (!all_determined) {
    id.rank_deficient = true;
    id.message = fmt::format(
        "ill-conditioned: the data do not determine {} (standard deviation above max_relative_sigma = {}){}",
        fmt::join(id.undetermined, ", "), options.max_relative_sigma,
        fit.scale_free ? "; with the overall scale E_s free, consider fixing it" : "");
    Fail("refine: " + id.message, summary);
  }
  id.message = fmt::format("determined: {} (condition number {:.3g}){}", fmt::join(id.determined, ", "),
                           id.condition_number,
                           id.fixed_parameters.empty() ? ""
                                                       : fmt::format("; held fixed: {}", fmt::join(id.fixed_parameters, ", ")));
}

/// Step 6: refined parameters, their covariance in metres and the intervals.
void FillParameters(const FitProblem& fit, const Eigen::Matrix3d& cov, const RefineOptions& options,
                    std::optional<double> dof, RefineSummary* summary) {
  const RobotParams& ref = summary->reference;
  const double Eb = fit.theta[kIndexEb], Ed = fit.theta[kIndexEd], Es = fit.theta[kIndexEs];
  summary->refined = ApplyRefinedFactors(ref, Eb, Ed, Es);
  WheelFactors(fit.theta, &summary->c_L, &summary->c_R);
  // Rows: d[b, D_L, D_R] / d[E_b, E_d, E_s].
  Eigen::Matrix3d G;
  const double q = Ed + 1.0;
  G << ref.wheelbase_m, 0.0, 0.0,                                                             //
      0.0, -2.0 * Es / (q * q) * ref.wheel_diameter_left_m, 2.0 / q * ref.wheel_diameter_left_m,  //
      0.0, 2.0 * Es / (q * q) * ref.wheel_diameter_right_m, 2.0 * Ed / q * ref.wheel_diameter_right_m;
  summary->covariance = G * cov * G.transpose();
  summary->confidence = options.confidence;
  summary->dof = dof;
  const double tail = 0.5 + 0.5 * options.confidence;
  summary->quantile = dof ? StudentTQuantile(tail, *dof) : NormalQuantile(tail);
  const double qt = summary->quantile;
  RefineIntervals& iv = summary->intervals;
  iv.wheelbase_m = Interval(summary->refined.wheelbase_m, G.row(0).transpose(), cov, qt);
  iv.wheel_diameter_left_m = Interval(summary->refined.wheel_diameter_left_m, G.row(1).transpose(), cov, qt);
  iv.wheel_diameter_right_m = Interval(summary->refined.wheel_diameter_right_m, G.row(2).transpose(), cov, qt);
  iv.E_b = Interval(Eb, Eigen::Vector3d::UnitX(), cov, qt);
  iv.E_d = Interval(Ed, Eigen::Vector3d::UnitY(), cov, qt);
  iv.E_s = Interval(Es, Eigen::Vector3d::UnitZ(), cov, qt);
}

}  // namespace

ceres::Solver::Options SolverOptions(const RefineOptions& options) {
  ceres::Solver::Options so;
  so.linear_solver_type = ceres::DENSE_QR;
  so.max_num_iterations = options.max_num_iterations;
  so.function_tolerance = options.function_tolerance;
  so.gradient_tolerance = options.gradient_tolerance;
  so.parameter_tolerance = options.parameter_tolerance;
  so.num_threads = options.num_threads;
  so.logging_type = ceres::SILENT;
  so.minimizer_progress_to_stdout = false;
  return so;
}

void SolveAndAssess(FitProblem& fit, const RefineOptions& options, CovarianceKind kind, std::optional<double> dof,
                    RefineSummary* summary) {
  const ceres::Solver::Summary cs = Solve(fit, options, summary);
  const SolutionJacobian sj = EvaluateAtSolution(fit, summary);
  const std::vector<int> free = FreeIndices(fit.scale_free);
  const int m = static_cast<int>(sj.J.rows()), p = static_cast<int>(free.size());
  summary->reduced_chi2 = m > p ? 2.0 * cs.final_cost / (m - p) : std::numeric_limits<double>::quiet_NaN();
  CheckIdentifiability(sj.J, free, fit, options, summary);
  const Eigen::Matrix3d cov = ThetaCovariance(fit, options, kind, sj, free, summary);
  summary->theta_covariance = cov;
  CheckDetermined(cov, free, fit, options, summary);
  FillParameters(fit, cov, options, dof, summary);
}

}  // namespace refine_detail

}  // namespace umbmark
