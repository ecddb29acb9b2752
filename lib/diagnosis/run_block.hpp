// run_time_offset as a per-run random effect. The contract draws one offset
// per run, tau_i ~ N(0, tau_sd^2), shared by all the run's pieces, so the
// pieces of a run are not independent: they are one block of the likelihood.
//
// Model of run i's stacked residuals e (pieces j of the run, in time order):
//   e_j = u J_j(u) + n_j,   n_j ~ N(0, C0_j) independent,   u = -tau_i ~ N(0, tau_sd^2)
// with C0_j the piece covariance without run_time_offset and J_j(u) the lever
// d eps_j / d tau on u's side (PieceBases::tau_lever_neg for u > 0, i.e. a
// lead, tau_lever_pos for u < 0): a pose is not smooth in time where a
// motion starts or stops, so the residual is linear in tau on either side of
// 0 but with two slopes (first order in tau, exact for constant-speed
// motion). Marginalising u over each half-line in closed form
// (a_s = J_s^T C0^-1 J_s, b_s = J_s^T C0^-1 e summed over the run's pieces,
// P_s = a_s + 1 / tau_sd^2):
//   log p(e) = sum_j log N(e_j; 0, C0_j)
//            + log sum_{s = +-} exp(b_s^2 / (2 P_s)) Phi(b_s / sqrt(P_s)) / sqrt(tau_sd^2 P_s)
// (the matrix determinant lemma and Sherman-Morrison for a rank-one update
// per half-line; with one slope it is the Gaussian N(0, C0 + tau_sd^2 J J^T)).
// Each piece's marginal second moment is C0_j + tau_sd^2 T_j (model.hpp), so
// the per-piece noise fit (piece_noise.hpp) estimates tau_sd consistently;
// the block only adds what ties the pieces of a run together.
//
// Scores (gap_stats.hpp) under the block: the innovations of a Kalman filter
// along the run over w = (max(u, 0), min(u, 0)), e_j = [J-, J+]_j w + n_j,
// with w Gaussian of w's true mean and covariance (the one-sided slopes give
// e a mean: tau_sd / sqrt(2 pi) (J- - J+)): piece j is scored given the
// run's earlier pieces, so the scores are again independent N(0, 1) under
// the model (to second moments).
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "diagnosis/model.hpp"
#include "diagnosis/piece_noise.hpp"

namespace umbmark::diag {

/// True when the likelihood of `n` has run blocks (tau_sd > 0 and no bump
/// mixture; with bumps the pieces stay independent).
bool HasRunBlocks(const NoiseParams& n);

/// Log-likelihood of the pieces with use[j] (all when `use` is empty or
/// null): run blocks when HasRunBlocks(n), else the sum of PieceLogLik.
double BlockLogLik(const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                   const std::vector<Piece>& pieces, const NoiseParams& n, const std::vector<char>* use = nullptr);

/// Residual of each piece given the earlier pieces of its run, and its
/// covariance (the Kalman innovation and its covariance; the residual and
/// PieceCovariance when !HasRunBlocks(n)). Pieces with use[j] == 0 (when
/// `use` is given) are skipped and left untouched.
struct Innovation {
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
};
std::vector<Innovation> RunInnovations(const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                                       const std::vector<Piece>& pieces, const NoiseParams& n);

/// run_time_offset at its own scale: ComputeBases takes the levers over one
/// sample interval, but a sample near a motion's start or stop responds to
/// tau only beyond its distance to it, so the slope that matters is the
/// secant over the offsets the runs have. Starting from the fit `n` on
/// `bases`, the levers are re-taken over +-tau_sd (at p) and the noise
/// refitted by `refit`, twice; returns the bases the fit ends on (`n`
/// updated). Unchanged when n.run_tau2 is 0.
using NoiseRefit = std::function<NoiseParams(const std::vector<PieceBases>& bases, const NoiseParams& start)>;
std::vector<PieceBases> RescaleTimeLevers(const MeanModel& model, const ParamVector& p, std::vector<PieceBases> bases,
                                          NoiseParams& n, const NoiseRefit& refit);

}  // namespace umbmark::diag
