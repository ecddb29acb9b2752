// The wheel noise k_L, k_R measured where a mean effect cannot reach it:
// the scatter of repeated runs about their own mean.
//
// Runs of one experiment and direction repeat the same commanded path, so
// they break into the same sequence of pieces (pieces.hpp), up to a creep
// or a split a real run has and the others lack: aligned to the group's
// typical run (longest common subsequence of pieces of the same type, sign,
// travel and heading change), piece m of each run is the same stretch of
// the path. Runs of one label that share less than half of the typical
// run's pieces (the June circles label cw and ccw alike) form a set of
// their own. A deterministic effect the baseline
// leaves out (a marker offset, a scale error, a clock offset, a scrub, a
// wrong E_d or E_b) moves piece m's residual by the same amount mu_m in each
// run: eps_{i,m} = mu_m + e_{i,m}, with e_{i,m} ~ N(0, C_{i,m}) independent
// from run to run (Chong & Kleeman's covariance propagation, C of
// piece_noise.hpp: k_L^2 A_L + k_R^2 A_R + the ground truth's noise + the
// encoders' quantisation). For n such runs, a contrast z = sum_i h_i
// eps_{i,m} with sum_i h_i = 0 has no mu_m at all, whatever its size:
//   E z = 0,   Cov z = sum_i h_i^2 C_{i,m}.
// Any n - 1 orthonormal rows h orthogonal to (1, ..., 1) will do (the
// Helmert contrasts, h_k = (1, ..., 1, -k, 0, ...) / sqrt(k (k+1)), are one
// choice; the code takes the complement of a QR factorisation); with equal
// C_{i,m} they are independent N(0, C), so the within-group scatter carries
// n - 1 of the n runs' information on
// k_L, k_R. The same Fisher scoring as on the pieces (piece_noise.hpp)
// fits k_L^2, k_R^2 to the contrasts, the ground truth's noise held at the
// baseline's (the standstill scatter or the manifest's). With unequal
// C_{i,m} the contrasts are slightly correlated; ignoring that keeps the
// score unbiased (a composite likelihood) and costs a little efficiency.
// The standard errors come from the Fisher information of the contrasts.
//
// Option `detrend`: contrasts orthogonal also to the run's place in the
// campaign (a linear parameter_drift, the same in every group, is then
// gone too), at one more contrast per piece.
//
// What the within-group scatter does NOT hold out: effects that differ
// from run to run (run_time_offset's per-run clocks, bump_outliers,
// correlated_noise, standstill_motion, motion_noise_floor): they are noise,
// and widen the repeat scatter as they widen the pieces' fit. A refit that
// gives such variance to an effect of its own fits k jointly with it on the
// contrasts (FitRepeatWheelNoise below), so the held k does not hold it.
//
// The design supports it when the campaign has at least min_contrasts
// contrast pieces and the contrasts separate k_L from k_R (the correlation
// of the two estimates within max_correlation); otherwise `measured` is
// false and `reason` says why (the baseline then fits k_L, k_R jointly
// with the mean on the pieces, baseline.hpp).
#pragma once

#include <string>
#include <vector>

#include "diagnosis/model.hpp"
#include "diagnosis/piece_noise.hpp"
#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

struct RepeatNoiseOptions {
  /// Fewest runs of one experiment and direction for its pieces to count
  /// (>= 2). Default 3.
  int min_runs = 3;
  /// Fewest contrast pieces (over all groups) for a measurement (>= 1).
  /// Default 20.
  int min_contrasts = 20;
  /// Pieces of the runs of a group are one stretch of the path when they
  /// have the same type and sign and their travel agrees within this
  /// fraction (or within travel_slack_m); each run is aligned to the
  /// group's typical run (median piece count) by the longest common
  /// subsequence of such matches, so a creep or a split one run has and the
  /// others lack is skipped, and a stretch counts where at least two runs
  /// (three with detrend) have it (> 0). Default 0.15.
  double travel_tolerance = 0.15;
  /// Absolute slack of the travel match [m] (>= 0). Default 0.05.
  double travel_slack_m = 0.05;
  /// Largest difference of a leg's or arc's heading change between matched
  /// pieces [rad] (> 0): the same circle, not its mirror or another radius
  /// (a marker offset d moves a piece by about d x the heading change, so
  /// 0.02 rad leaves 0.8 mm of a 42 mm offset's effect). Default 0.02.
  double turn_tolerance_rad = 0.02;
  /// Contrasts orthogonal to the run's place in the campaign too (a linear
  /// parameter_drift drops out); needs one run more per group. Default false.
  bool detrend = false;
  /// Largest |correlation| of the k_L^2 and k_R^2 estimates for the design
  /// to separate the wheels (in (0, 1)). Default 0.95.
  double max_correlation = 0.95;

  std::string Check() const;
};

struct RepeatNoise {
  bool measured = false;
  std::string reason;       ///< why not measured (empty when measured)
  double k_L = 0.0, k_R = 0.0;        ///< [m^1/2]
  /// Standard errors from the contrasts' Fisher information: of k^2 [m], and
  /// of k by the delta method sd(k^2) / (2 k) [m^1/2] (large when k ~ 0).
  double sd_kL2 = 0.0, sd_kR2 = 0.0, sd_k_L = 0.0, sd_k_R = 0.0;
  double correlation = 0.0;  ///< of the k_L^2 and k_R^2 estimates
  int groups = 0;            ///< experiment-direction groups used
  int runs = 0;              ///< runs in those groups
  int positions = 0;         ///< stretches matched in at least two runs of a group
  int contrasts = 0;         ///< contrast pieces fitted
};

/// The contrasts themselves, for a fit or a test: eps (3 per contrast),
/// their covariance bases sum_i h_i^2 B_i, pseudo-pieces (components).
struct RepeatContrasts {
  std::vector<double> eps;
  std::vector<PieceBases> bases;
  std::vector<Piece> pieces;
  int groups = 0, runs = 0, positions = 0;
};

/// Which pieces form each contrast, with which weights h: the grouping and
/// alignment, done once per campaign (they depend on the pieces' types,
/// signs, travel and turns, not on the residuals), applied to any residuals
/// and bases by ApplyRepeatDesign.
struct RepeatDesign {
  struct Contrast {
    std::vector<int> pieces;  ///< one per run at the stretch, campaign order
    std::vector<double> h;    ///< sum h = 0, sum h^2 = 1
    int components = 3;
  };
  std::vector<Contrast> contrasts;
  int groups = 0, runs = 0, positions = 0;
};

/// The contrasts' design. pairs = false: n - 1 orthonormal contrasts of the
/// n runs at a stretch (as FormRepeatContrasts). pairs = true: floor(n / 2)
/// disjoint differences of consecutive runs, (eps_a - eps_b) / sqrt(2): a
/// bump_outliers process in them is again one (rate x 2 over the piece's
/// travel, sigma_b^2 / 2), which a Helmert contrast's unequal weights are not.
RepeatDesign BuildRepeatDesign(const CampaignData& c, const std::vector<PieceBases>& bases,
                               const RepeatNoiseOptions& options, bool pairs = false);

/// The contrasts of residuals `eps` (3 per piece of c) and their bases
/// sum_i h_i^2 B_i under `design`.
RepeatContrasts ApplyRepeatDesign(const RepeatDesign& design, const CampaignData& c, const std::vector<double>& eps,
                                  const std::vector<PieceBases>& bases);

/// Groups the runs by experiment and direction, matches their pieces by
/// position and forms the contrasts of residuals `eps` (3 per piece of c).
RepeatContrasts FormRepeatContrasts(const CampaignData& c, const std::vector<double>& eps,
                                    const std::vector<PieceBases>& bases, const RepeatNoiseOptions& options);

/// The wheel noise of a refit that adds run-to-run variance of its own
/// (issue 28): k_L^2, k_R^2 fitted on the contrasts of the refit's
/// residuals `eps` jointly with every variance term `fit` enables
/// (correlated_noise's c, motion_noise_floor's sigma^2, standstill_motion's
/// sigma_xy^2, sigma_theta^2, run_time_offset's tau_sd^2; with `bumps` the
/// bump mixture, on the `pairs` design). Each such term's covariance enters
/// a contrast as sum_i h_i^2 of its per-run footprint (its basis F, S_xy,
/// S_theta, T, A_LR), exactly as the wheels' do, so the contrasts' scatter
/// is split between k and the term instead of being given to k whole; a
/// mean the same in every run still drops out. The ground truth's noise and
/// swivel_rev2 stay at `start`'s.
struct RepeatWheelFit {
  /// The contrasts' fit: its k are the ones to hold; its other terms are the
  /// contrasts' own estimates of the enabled variances.
  NoiseParams noise;
  /// Standard errors of k_L^2, k_R^2 [m] from the contrasts' Fisher
  /// information of every fitted variance (the enabled terms' uncertainty
  /// included); 0 for the bump mixture.
  double sd_kL2 = 0.0, sd_kR2 = 0.0;
  int contrasts = 0;
};
RepeatWheelFit FitRepeatWheelNoise(const RepeatDesign& design, const RepeatDesign& pairs, const CampaignData& c,
                                const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                                const NoiseParams& start, const PieceNoiseFitOptions& fit, bool bumps);

/// k_L, k_R from the contrasts of `eps` at bases `bases`; `start` carries the
/// ground truth's noise (held fixed unless fit.fit_ground_truth) and the
/// start of k; `fit` the noise fit's floors (wheel noise always fitted,
/// correlated, motion floor, standstill and run-time terms never).
RepeatNoise MeasureRepeatNoise(const CampaignData& c, const std::vector<double>& eps,
                               const std::vector<PieceBases>& bases, const NoiseParams& start,
                               const PieceNoiseFitOptions& fit, const RepeatNoiseOptions& options = {});

/// One line: "k_L = ... +- ..., k_R = ... +- ... m^1/2 from N contrasts of
/// R runs in G groups" or why it was not measured.
std::string RepeatNoiseSummary(const RepeatNoise& r);

}  // namespace umbmark::diag
