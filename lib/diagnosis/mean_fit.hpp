// Stage "mean-model fit" of the diagnosis: weighted least squares of the
// mean model's parameters (model.hpp: E_d, E_b and the effects' parameters)
// on the whitened piece residuals W_j eps_j, W_j the inverse Cholesky factor
// of piece j's covariance (piece_noise.hpp), by Ceres' Levenberg-Marquardt.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "diagnosis/model.hpp"
#include "diagnosis/piece_noise.hpp"
#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

/// Inverse Cholesky factors W_j (scores = W_j eps_j, order heading, x, y) of
/// every piece's covariance (the mixture's mean covariance for bumps).
std::vector<Eigen::Matrix3d> Whiteners(const std::vector<PieceBases>& bases, const std::vector<Piece>& pieces,
                                       const NoiseParams& n);

/// Whitened residual vector and Jacobian (3 rows per piece) of eps and
/// D = d eps / d params.
void Whiten(const std::vector<Eigen::Matrix3d>& W, const std::vector<double>& eps, const Eigen::MatrixXd& D,
            Eigen::VectorXd& rw, Eigen::MatrixXd& Jw);

struct MeanFitOptions {
  /// Levenberg-Marquardt iterations at most. Default 10.
  int iterations = 10;
  /// When time_offset.tau is among the fitted parameters, its start is the
  /// best of a grid tau = k clock_step_s, |tau| <= clock_scan_s, the other
  /// parameters at their start (a clock's cost is not convex in tau: a
  /// local fit from tau = 0 stops in the nearest dip). Defaults 0.3 s
  /// (four times the largest clock of the injection-recovery sessions; a
  /// clock beyond is a run fault's size) in steps of 25 ms (half a 20 Hz
  /// sample interval; the dips seen on the June recordings are 60 ms or
  /// more wide); 0 scans nothing.
  double clock_scan_s = 0.3;
  double clock_step_s = 0.025;
  /// "" when valid, else what is wrong, naming the field.
  std::string Check() const;
};

struct MeanFit {
  ParamVector p{};
  std::vector<double> eps;
  Eigen::MatrixXd D;    ///< d eps / d params at p (unwhitened)
  Eigen::MatrixXd cov;  ///< (Jw^T Jw)^-1 at p
  bool converged = false;
};

/// Weighted least squares on the whitened piece residuals over `params`
/// (the others held at `start`'s values), weights W; converged when the
/// cost changes by less than 1e-10 of itself (a step of about 1e-3
/// standard errors).
MeanFit FitMean(const MeanModel& model, const ParamVector& start, const std::vector<int>& params,
                const std::vector<Eigen::Matrix3d>& W, const MeanFitOptions& options);

}  // namespace umbmark::diag
