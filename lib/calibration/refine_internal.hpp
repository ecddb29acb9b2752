// Internal to the refined calibration (refine*.cpp): the shared driver that
// solves a built problem, checks the solver outcome, assesses
// identifiability, forms the covariance and fills a RefineSummary. Not part
// of the library API.
#pragma once

#include <memory>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <ceres/cost_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include "calibration/refine.hpp"

namespace umbmark::refine_detail {

/// A built least-squares problem over theta. Each entry of `blocks` is one
/// run (the unit that is statistically independent of the others).
struct FitProblem {
  std::unique_ptr<ceres::Problem> problem = std::make_unique<ceres::Problem>();
  double theta[kNumRefineParameters] = {1.0, 1.0, 1.0};
  std::vector<ceres::CostFunction*> blocks;  ///< owned by `problem`
  /// Per block (same order, may be shorter): covariance of its whitened
  /// residual when the weights are not the inverse noise covariance
  /// (identity when absent). kDirect then forms the sandwich
  /// C (sum J_i^T Omega_i J_i) C instead of C.
  std::vector<std::optional<Eigen::MatrixXd>> block_residual_covariance;
  /// Robust fits only (trajectories): per block the same residual without
  /// the loss, 3 residuals per pose, and the loss applied per pose. With
  /// them kRunClustered uses the Hessian of the robust objective as bread.
  std::vector<std::unique_ptr<ceres::CostFunction>> plain_blocks;
  RobustLoss loss = RobustLoss::kNone;
  double loss_scale_m = 0.0;
  bool scale_free = false;
};

/// How the covariance is formed from the Ceres covariance C = (J^T J)^-1.
enum class CovarianceKind {
  kDirect,        ///< weights are inverse noise covariances: C (sandwich where Omega_i given)
  kRunClustered,  ///< cluster-robust sandwich over blocks (TrajectoryCovariance)
  kSolverScaled   ///< C * 2 cost / (m - p)
};

/// The Ceres settings every refined fit solves with: dense QR, the options'
/// iteration cap, tolerances and thread count, no logging.
ceres::Solver::Options SolverOptions(const RefineOptions& options);

/// Solves `fit`, then fills summary->{solver, identifiability, theta
/// covariance, intervals, refined, covariance, final_cost, reduced_chi2,
/// residuals, quantile, dof, covariance_method (unless set)}. `dof`: degrees
/// of freedom behind the covariance for a t quantile (nullopt = normal).
/// Throws RefineError on solver failure, rank deficiency or an undetermined
/// free parameter (the summary inside says which).
void SolveAndAssess(FitProblem& fit, const RefineOptions& options, CovarianceKind kind, std::optional<double> dof,
                    RefineSummary* summary);

}  // namespace umbmark::refine_detail
