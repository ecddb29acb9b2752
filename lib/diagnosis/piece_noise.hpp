// Noise parameters of the diagnosis' model, fitted by maximum likelihood to
// the piece residuals (model.hpp):
//   Cov(eps_j) = k_L^2 A_L + k_R^2 A_R + c A_LR + sigma_xy^2 G_xy + sigma_theta^2 G_theta + Q
// with c = rho k_L k_R (correlated_noise; 0 in the baseline). The model is
// linear in v = [k_L^2, k_R^2, c, sigma_xy^2, sigma_theta^2], so Fisher
// scoring (the Gaussian REML/ML iteration for variance components,
//   v <- v + I^-1 s,  s_m = 1/2 sum_j (eps^T C^-1 B_m C^-1 eps - tr C^-1 B_m),
//   I_mn = 1/2 sum_j tr(C^-1 B_m C^-1 B_n))
// converges in a few steps; bounds keep k^2, sigma^2 >= 0 and |rho| < 1.
// By default the fit is trimmed (PieceNoiseFitOptions::robust): an
// unmodelled effect concentrated on some pieces (the spot turns, say) must
// show as a gap, not as a huge k.
// This is the same estimator `fit-noise` needs (Chong & Kleeman's k_L, k_R
// from runs with ground truth), written here on the diagnosis' pieces.
//
// bump_outliers (a per-wheel Poisson process of travel errors N(0, sigma_b^2),
// `rate` per metre) makes eps_j a scale mixture: with m bumps on the piece
// (m ~ Poisson(rate (|L| + |R|)); the tail beyond kMaxBumpsPerPiece - 1 one
// component at its mean count) its covariance is
//   C_j + m sigma_b^2 (A_L + A_R) / (|L| + |R|)
// (a bump's effect averaged over where on the piece, and which wheel, it
// strikes: wheel L with probability |L| / (|L| + |R|)), so that the mixture's
// covariance is C_j + rate sigma_b^2 (A_L + A_R), wheel noise's. FitBumps
// maximises that mixture likelihood (NLopt Sbplx, bounded) jointly with the
// other variance terms (docs/diagnosis.md, "Bumps fitted jointly").
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "diagnosis/model.hpp"
#include "effects/effect.hpp"

namespace umbmark::diag {

struct NoiseParams {
  double kL2 = 1e-6, kR2 = 1e-6;  ///< k_L^2, k_R^2 [m]
  double c_LR = 0.0;              ///< rho k_L k_R [m]
  double sxy2 = 1e-8;             ///< sigma_xy^2 [m^2]
  double sth2 = 1e-6;             ///< sigma_theta^2 [rad^2]
  double bump_rate = 0.0;         ///< per metre of wheel travel
  double bump_s2 = 0.0;           ///< sigma_b^2 [m^2]
  double floor_s2 = 0.0;          ///< motion_noise_floor sigma^2 [m^2]
  double stand_xy2 = 0.0;         ///< standstill_motion sigma_xy^2 [m^2]
  double stand_th2 = 0.0;         ///< standstill_motion sigma_theta^2 [rad^2]
  double run_tau2 = 0.0;          ///< run_time_offset tau_sd^2 [s^2]
  /// castor_swivel's kicks after reversals, +-kappa with equal probability:
  /// a heading variance kappa^2 at those starts [rad^2]. Never estimated
  /// here: the mean fit's kappa sets it (candidates.cpp, explanation.cpp).
  double swivel_rev2 = 0.0;
  /// A heading kick of random size at a run's first start (a mean effect's
  /// random part, effects::NoiseTerm::kFirstStart) [rad^2].
  double first_start2 = 0.0;
  /// The position slip there, along each axis [m^2].
  double first_start_xy2 = 0.0;
  /// The scatter of a heading kick after a spot turn [rad^2].
  double turn_start2 = 0.0;

  double rho() const;
};

/// Covariance of piece j (Gaussian part: no bumps).
Eigen::Matrix3d PieceCovariance(const PieceBases& B, const NoiseParams& n);

/// Piece covariance with the bumps' variance per metre of each wheel's
/// travel added (rate x sigma_b^2, as k^2 in eq. 4).
Eigen::Matrix3d TotalCovariance(const PieceBases& B, const NoiseParams& n);

/// `n` without the variance term `term` (kFirstStart: castor_swivel's kick
/// scatter and first start; kRunTime and kNone: unchanged), to measure what
/// one noise effect adds.
NoiseParams WithoutTerm(NoiseParams n, effects::NoiseTerm term);

/// Largest bump rate FitBumps fits [per metre of wheel travel]: a fit at
/// this bound is the Gaussian limit of bumps (many small ones: wheel noise).
inline constexpr double kMaxBumpRatePerMetre = 2.0;

/// Most bumps per piece the mixture distinguishes (the Poisson tail beyond
/// is lumped into this count).
inline constexpr int kMaxBumpsPerPiece = 5;

/// Mixture of a piece under bump_outliers: weights and covariances of
/// m = 0 .. kMaxBumpsPerPiece bumps.
struct BumpMixture {
  int components = 1;
  double weight[kMaxBumpsPerPiece + 1] = {1.0};
  Eigen::Matrix3d cov[kMaxBumpsPerPiece + 1];
};
BumpMixture PieceMixture(const PieceBases& B, const NoiseParams& n);

struct PieceNoiseFitOptions {
  /// Estimate k_L^2, k_R^2 (else fixed at the start values: a given model's
  /// wheel noise, `diagnose --baseline --kl --kr`). Default true.
  bool fit_wheel_noise = true;
  /// Estimate sigma_xy, sigma_theta (else fixed at the start values).
  bool fit_ground_truth = false;
  /// Estimate c = rho k_L k_R (correlated_noise).
  bool correlated = false;
  /// Estimate motion_noise_floor's sigma^2, standstill_motion's sigma_xy^2
  /// and sigma_theta^2, run_time_offset's tau_sd^2 (else held at 0).
  bool motion_floor = false, standstill = false, run_time = false;
  /// Estimate the starts' variances first_start2, first_start_xy2,
  /// turn_start2 (else held at 0).
  bool first_start = false;
  int max_iterations = 60;
  /// Step halving on the likelihood (robust from a poor start); without it
  /// plain Fisher steps until the relative change is below `tolerance`
  /// (fast, for starts near the answer such as simulated null campaigns).
  bool line_search = true;
  /// Trimmed likelihood: pieces beyond the chi^2 99.9 % quantile of the fit
  /// (Mahalanobis distance) are left out and the fit repeated until the kept
  /// set is stable, so pieces the mean model misses by far cannot inflate
  /// k_L, k_R; the start is scaled by the median chi^2. Under the model
  /// 0.1 % of pieces are left out (bias corrected). Default true.
  bool robust = true;
  double tolerance = 1e-6;
  /// Floors of the variances (keep the covariances invertible).
  double min_k2 = 1e-14, min_sigma_xy2 = 1e-14, min_sigma_theta2 = 1e-14;
};

/// Maximum-likelihood noise parameters on the pieces with use[j] (all when
/// `use` is empty), from `start`. eps: residuals (3 per piece).
NoiseParams FitPieceNoise(const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                     const std::vector<Piece>& pieces, const std::vector<char>& use, const NoiseParams& start,
                     const PieceNoiseFitOptions& options);

/// What FitBumps estimates beside bump_outliers' rate and sigma_b.
struct BumpFitOptions {
  /// One search from `start` (which must carry bumps) instead of the
  /// multi-start -- for refits near a known answer, such as the
  /// cross-validation folds of a full-data fit. Default false.
  bool start_only = false;
  /// Estimate k_L^2, k_R^2 (else held at `start`'s: a given model's wheel
  /// noise). Default true.
  bool fit_wheel_noise = true;
  /// Estimate motion_noise_floor's sigma^2, standstill_motion's sigma_xy^2
  /// and sigma_theta^2, run_time_offset's tau_sd^2 jointly with the bumps
  /// (else held at `start`'s). Default false: a candidate fitted alone.
  bool motion_floor = false, standstill = false, run_time = false;
  /// Estimate first_start2, first_start_xy2, turn_start2 jointly with the
  /// bumps (else held at `start`'s).
  bool first_start = false;
  /// The wheel noise of the repeated runs' scatter [m] (0: not measured):
  /// one more start, k at it and the bumps holding the rest of the Gaussian
  /// fit's k^2 (a mean effect the pieces' k takes in cannot reach it).
  double repeat_kL2 = 0.0, repeat_kR2 = 0.0;
  /// The Gaussian variance components of `fit` (motion_floor, standstill,
  /// run_time, fit_wheel_noise) as the terms fitted with the bumps.
  static BumpFitOptions Terms(const PieceNoiseFitOptions& fit);
};

/// As FitPieceNoise, plus bump_outliers' rate and sigma_b: the mixture
/// likelihood (PieceLogLik) maximised over log k_L^2, log k_R^2, log rate,
/// log sigma_b^2 and the log of every other variance term `options` frees,
/// jointly (bounded Sbplx), from several starts: the Gaussian fit of the
/// same terms without bumps, with the bumps taking a share of its k^2 on a
/// grid of rates and shares (and of the repeated runs' excess over their
/// k^2, when given), the best few of the grid searched. Ground-truth noise
/// and correlation are held at `start`'s (c_LR at 0). The search is bounded
/// to physical bumps: rate in [1e-4, 2] per metre, sigma_b in [0.01, 100] mm.
NoiseParams FitBumps(const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                     const std::vector<Piece>& pieces, const std::vector<char>& use, const NoiseParams& start,
                     const BumpFitOptions& options);

/// Log-likelihood of piece j's residual (Gaussian, or the bump mixture when
/// n.bump_rate > 0).
double PieceLogLik(const double* eps, int components, const PieceBases& B, const NoiseParams& n);

}  // namespace umbmark::diag
