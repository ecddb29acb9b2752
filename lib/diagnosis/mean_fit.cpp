// Mean-model fit (see mean_fit.hpp).
#include "diagnosis/mean_fit.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <ceres/ceres.h>
#include <fmt/format.h>

namespace umbmark::diag {

namespace {

/// The whitened piece residuals W_j eps_j as one Ceres cost over the free
/// mean-model parameters `params` (the others held at `base`); the
/// Jacobian is the model's forward differences, whitened.
class WhitenedPieceCost final : public ceres::CostFunction {
 public:
  WhitenedPieceCost(const MeanModel& model, const ParamVector& base, const std::vector<int>& params,
                    const std::vector<Eigen::Matrix3d>& W)
      : model_(model), base_(base), params_(params), W_(W) {
    set_num_residuals(static_cast<int>(3 * W.size()));
    mutable_parameter_block_sizes()->push_back(static_cast<int>(params.size()));
  }

  bool Evaluate(double const* const* x, double* residuals, double** jacobians) const override {
    ParamVector p = base_;
    for (std::size_t k = 0; k < params_.size(); ++k) p[params_[k]] = x[0][k];
    std::vector<double> eps;
    model_.Residuals(p, eps);
    for (double v : eps)
      if (!std::isfinite(v)) return false;
    const std::size_t n = W_.size(), np = params_.size();
    for (std::size_t j = 0; j < n; ++j) {
      const Eigen::Vector3d r = W_[j] * Eigen::Vector3d(eps[3 * j], eps[3 * j + 1], eps[3 * j + 2]);
      for (int c = 0; c < 3; ++c) residuals[3 * j + static_cast<std::size_t>(c)] = r[c];
    }
    if (jacobians && jacobians[0]) {
      const Eigen::MatrixXd D = model_.Jacobian(p, params_, eps);
      if (!D.allFinite()) return false;
      for (std::size_t j = 0; j < n; ++j) {
        const Eigen::MatrixXd Jj = W_[j] * D.middleRows(static_cast<Eigen::Index>(3 * j), 3);
        for (int c = 0; c < 3; ++c)
          for (std::size_t k = 0; k < np; ++k)
            jacobians[0][(3 * j + static_cast<std::size_t>(c)) * np + k] = Jj(c, static_cast<Eigen::Index>(k));
      }
    }
    return true;
  }

 private:
  const MeanModel& model_;
  ParamVector base_;
  std::vector<int> params_;
  const std::vector<Eigen::Matrix3d>& W_;
};

/// The clock offset's start: the best of a grid over [-clock_scan_s,
/// clock_scan_s] (the others at `start`), or start's own value when no grid
/// value is better. A clock's cost is not convex in tau: the pose at t - tau
/// is interpolated between samples whose wheel rates jump from one interval
/// to the next (and at every start from standstill), so its slope at one tau
/// says little about where the minimum lies, and a local fit from tau = 0
/// stops in whichever dip lies nearest (a -60 ms clock injected into a real
/// recording was fitted at +31.6 ms that way).
double ClockStart(const MeanModel& model, const ParamVector& start, const std::vector<Eigen::Matrix3d>& W,
                  const MeanFitOptions& o) {
  const int n = static_cast<int>(std::ceil(o.clock_scan_s / o.clock_step_s));
  std::vector<double> taus{start[kParamTau]};
  for (int k = -n; k <= n; ++k) taus.push_back(k * o.clock_step_s);
  std::vector<std::vector<double>> eps;
  model.ResidualsAtClocks(start, taus, eps);
  std::size_t best = 0;
  double best_cost = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < taus.size(); ++k) {
    double cost = 0.0;
    for (std::size_t j = 0; j < W.size(); ++j)
      cost += (W[j] * Eigen::Vector3d(eps[k][3 * j], eps[k][3 * j + 1], eps[k][3 * j + 2])).squaredNorm();
    if (std::isfinite(cost) && cost < best_cost) {
      best_cost = cost;
      best = k;
    }
  }
  return taus[best];
}

}  // namespace

std::string MeanFitOptions::Check() const {
  if (iterations < 0) return fmt::format("iterations = {} must be >= 0", iterations);
  if (!(clock_scan_s >= 0.0 && clock_scan_s <= 10.0)) return fmt::format("clock_scan_s = {} must be in [0, 10] s", clock_scan_s);
  if (!(clock_step_s > 0.0) || (clock_scan_s > 0.0 && clock_scan_s / clock_step_s > 1000.0))
    return fmt::format("clock_step_s = {} must be > 0 and at least clock_scan_s / 1000", clock_step_s);
  return {};
}

std::vector<Eigen::Matrix3d> Whiteners(const std::vector<PieceBases>& bases, const std::vector<Piece>& pieces,
                                       const NoiseParams& n) {
  std::vector<Eigen::Matrix3d> W(pieces.size(), Eigen::Matrix3d::Zero());
  for (std::size_t j = 0; j < pieces.size(); ++j) {
    Eigen::Matrix3d C = PieceCovariance(bases[j], n);
    if (n.bump_rate > 0.0 && n.bump_s2 > 0.0) {
      const BumpMixture m = PieceMixture(bases[j], n);
      C.setZero();
      for (int k = 0; k < m.components; ++k) C += m.weight[k] * m.cov[k];
    }
    if (pieces[j].components == 2) {
      const Eigen::Matrix2d L = C.topLeftCorner<2, 2>().llt().matrixL();
      const Eigen::Matrix2d Li = L.inverse();
      W[j].block<2, 2>(1, 0) = Li;
      continue;
    }
    // Permutation P: (x, y, theta) -> (theta, x, y).
    Eigen::Matrix3d P = Eigen::Matrix3d::Zero();
    P(0, 2) = P(1, 0) = P(2, 1) = 1.0;
    const Eigen::Matrix3d Cp = P * C * P.transpose();
    const Eigen::Matrix3d L = Cp.llt().matrixL();
    W[j] = L.inverse() * P;
  }
  return W;
}

void Whiten(const std::vector<Eigen::Matrix3d>& W, const std::vector<double>& eps, const Eigen::MatrixXd& D,
            Eigen::VectorXd& rw, Eigen::MatrixXd& Jw) {
  const std::size_t n = W.size();
  rw.resize(static_cast<Eigen::Index>(3 * n));
  Jw.resize(static_cast<Eigen::Index>(3 * n), D.cols());
  for (std::size_t j = 0; j < n; ++j) {
    const auto J3 = static_cast<Eigen::Index>(3 * j);
    rw.segment<3>(J3) = W[j] * Eigen::Vector3d(eps[3 * j], eps[3 * j + 1], eps[3 * j + 2]);
    if (D.cols() > 0) Jw.middleRows(J3, 3) = W[j] * D.middleRows(J3, 3);
  }
}

MeanFit FitMean(const MeanModel& model, const ParamVector& start, const std::vector<int>& params,
                const std::vector<Eigen::Matrix3d>& W, const MeanFitOptions& options) {
  MeanFit f;
  f.p = start;
  if (!params.empty()) {
    std::vector<double> x(params.size());
    for (std::size_t k = 0; k < params.size(); ++k) x[k] = start[params[k]];
    if (options.clock_scan_s > 0.0)
      for (std::size_t k = 0; k < params.size(); ++k)
        if (params[k] == kParamTau) x[k] = ClockStart(model, start, W, options);
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::TAKE_OWNERSHIP;
    ceres::Problem problem(po);
    problem.AddResidualBlock(new WhitenedPieceCost(model, start, params, W), nullptr, x.data());
    ceres::Solver::Options so;
    so.linear_solver_type = ceres::DENSE_QR;
    so.max_num_iterations = options.iterations;
    so.function_tolerance = 1e-10;
    so.num_threads = 1;  // the candidates already run in parallel
    so.logging_type = ceres::SILENT;
    so.minimizer_progress_to_stdout = false;
    ceres::Solver::Summary summary;
    ceres::Solve(so, &problem, &summary);
    if (summary.IsSolutionUsable())
      for (std::size_t k = 0; k < params.size(); ++k) f.p[params[k]] = x[k];
    f.converged = summary.termination_type == ceres::CONVERGENCE;
  }
  model.Residuals(f.p, f.eps);
  if (params.empty()) return f;
  f.D = model.Jacobian(f.p, params, f.eps);
  Eigen::VectorXd rw;
  Eigen::MatrixXd Jw;
  Whiten(W, f.eps, f.D, rw, Jw);
  Eigen::MatrixXd A = Jw.transpose() * Jw;
  for (Eigen::Index k = 0; k < A.rows(); ++k) A(k, k) *= 1.0 + 1e-12;
  f.cov = A.ldlt().solve(Eigen::MatrixXd::Identity(A.rows(), A.cols()));
  return f;
}

}  // namespace umbmark::diag
