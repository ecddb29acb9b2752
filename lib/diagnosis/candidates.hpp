// Stage "candidates" of the diagnosis: every effect of the contract fitted
// on top of the baseline -- mean effects (model.hpp) with E_d, E_b jointly by
// weighted least squares, correlated_noise and bump_outliers by maximum
// likelihood (piece_noise.hpp) -- with its identifiability against E_d, E_b,
// the gap it leaves, its in-sample likelihood-ratio test and its held-out
// evidence (cross_validation.hpp).
#pragma once

#include <array>
#include <map>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/progress.hpp"
#include "diagnosis/footprint.hpp"
#include "diagnosis/baseline.hpp"
#include "diagnosis/cross_validation.hpp"
#include "diagnosis/gap_stats.hpp"
#include "diagnosis/mean_fit.hpp"
#include "diagnosis/piece_noise.hpp"
#include "simulation/effects.hpp"

namespace umbmark::diag {

struct Candidate {
  sim::EffectKind effect{};
  std::map<std::string, double> params;
  std::map<std::string, double> param_se;  ///< standard errors (mean effects)
  double E_d = 1.0, E_b = 1.0;             ///< refitted with the effect
  bool identifiable = true;
  /// Identifiable, but a typical-size effect stands < 3 standard errors out
  /// beside E_d, E_b (named only on its own evidence; see `note`).
  bool weak = false;
  double gap_after = 0.0;  ///< G after (raw score)
  double shrink = 0.0;
  double heldout_shrink = 0.0;
  double heldout_loglik_gain = 0.0;  ///< nats over the baseline, held out
  double evidence = 0.0;             ///< gain minus the complexity penalty
  int parameters = 0;
  /// Likelihood-ratio test against the baseline on all runs (in-sample):
  /// log-likelihood gain [nats] and its p-value (chi^2 with `parameters`
  /// degrees of freedom; Wilks). Not tested (p = 1, tested = false) for
  /// bump_outliers, whose rate sits on the boundary under the baseline,
  /// and for effects the data cannot identify.
  bool tested = false;
  double loglik_gain = 0.0;
  double lr_p_value = 1.0;
  /// Fitted beyond the fixed bounds of plausibility.hpp's UnphysicalFit
  /// (e.g. a turn scrub below -0.01; without the standard-error rule, so
  /// a scrub slightly but significantly below 0 does not count). Such a
  /// fit is another likelihood mode, not an alternative near the baseline
  /// where Wilks' chi^2 holds, so its likelihood-ratio test is no evidence
  /// of a gap (verdict.cpp).
  bool impossible = false;
  std::array<double, kNumStatKinds> gap_by_kind{};
  std::string note;
  /// time_offset, run_time_offset: the clock refitted on the moving
  /// samples alone (ClockCheck). A clock offset moves every ground-truth
  /// sample taken while the robot moves (by about v tau along track); a
  /// slide at a stop (stop_slide) moves only the samples after the stop.
  struct ClockCheck {
    bool checked = false;
    /// The moving samples show the clock offset too: the refit has the full
    /// fit's sign and its likelihood ratio against no clock there (deviance
    /// over the samples' dispersion) exceeds chi^2_1 at 0.27 %, the level of
    /// 3 standard errors (time_offset), or keeps
    /// at least half the full fit's tau_sd or gains more than 5.4 nats there
    /// (run_time_offset).
    bool supported = true;
    int pieces = 0;            ///< pieces that end at a moving sample (not at a stop)
    double value = 0.0;        ///< tau [s] or tau_sd [s] refitted on them
    double se = 0.0;           ///< its standard error (time_offset; 0 otherwise)
    std::string text;          ///< which samples carry the evidence, in words
  };
  ClockCheck clock;
  /// Noise effects (not the clocks): whether adjacent stretches of a leg
  /// have independent heading errors, as every listed noise effect gives
  /// (footprint.hpp); inconsistent: never named.
  FootprintCheck footprint;
  /// Mean effects: the mean-model parameters fitted (EffectParams(effect,
  /// campaign) less a part these data cannot tell from E_d, E_b:
  /// stop_slide's turn part a on turns of one angle and rate whose coast
  /// the samples do not resolve); empty for the noise effects.
  std::vector<int> fitted_params;
};

/// The mean parameters `effect` was fitted with among `candidates`
/// (Candidate::fitted_params), or EffectParams(effect, c) when it is not
/// among them.
std::vector<int> FittedParams(sim::EffectKind effect, const std::vector<Candidate>& candidates,
                              const CampaignData& c);

/// Mean-model parameters of an effect (empty for the noise effects).
std::vector<int> EffectParams(sim::EffectKind k);
/// The mean-model parameters of an effect these runs can show: stop_slide's
/// d only with a stop after a straight or arc motion, its a only with a
/// stop after a spot turn, else EffectParams(k). Never empty for a mean
/// effect. (Whether a is told from E_b is the candidate fit's business:
/// Candidate::fitted_params.)
std::vector<int> EffectParams(sim::EffectKind k, const CampaignData& c);

/// The effects the piece noise model carries (piece_noise.hpp):
/// correlated_noise, bump_outliers, standstill_motion, motion_noise_floor,
/// run_time_offset.
bool IsNoiseEffect(sim::EffectKind k);
/// Switches on the variance component(s) of a Gaussian noise effect (not
/// bump_outliers, which has its own mixture fit).
void EnableNoiseEffect(sim::EffectKind k, PieceNoiseFitOptions& o);
/// The fitted noise as the effects read it (effects::NoiseValues).
effects::NoiseValues NoiseValuesOf(const NoiseParams& n);
/// The noise component an effect switches on (kNone: not a noise effect).
effects::NoiseTerm NoiseTermOf(sim::EffectKind k);
/// The name of the effect that switches on noise component `term`.
std::string NoiseEffectName(effects::NoiseTerm term);
/// Contract parameters of a noise effect from fitted noise parameters.
std::map<std::string, double> NoiseEffectParams(sim::EffectKind k, const NoiseParams& n);
/// Parameters an effect adds.
int EffectParameterCount(sim::EffectKind k);

/// gap = max(0, G - G0): what the model's own noise does not produce.
double Gap(double score, double null_median);

/// 1 - after / before, 0 without a gap, floored at -1 (an effect that makes
/// the gap more than twice as large is simply "much worse").
double Shrink(double after, double before);

struct CandidateOptions {
  /// Effects to fit (in this order).
  std::vector<sim::EffectKind> effects;
  /// Held-out log-likelihood an effect must gain per parameter. Default 2 nats.
  double complexity_penalty_nats = 2.0;
  /// Threads (>= 1); results do not depend on them. Default 2.
  int threads = 2;
  GapOptions gap;
  /// Progress in candidate effects fitted (core/progress.hpp). Default: none.
  ProgressCallback progress;
};

struct CandidateFits {
  std::vector<Candidate> candidates;  ///< in CandidateOptions::effects' order
  /// Each mean effect's whitened footprint with what E_d, E_b explain
  /// removed (empty for the noise effects); tells effects apart.
  std::vector<Eigen::MatrixXd> projected;
  /// The mean effects' joint fits with E_d, E_b (FitMean from the
  /// baseline's parameters with its weights W), by the fitted parameter
  /// list (BaselineParams() then the effect's): the stepwise explanation
  /// starts from them instead of fitting them again.
  std::map<std::vector<int>, MeanFit> mean_fits;
};

/// gap_score: G of the baseline; null_median: G0.
CandidateFits FitCandidates(const CampaignData& c, const MeanModel& model, const BaselineFit& baseline,
                            const Folds& folds, double gap_score, double null_median, const CandidateOptions& options);

}  // namespace umbmark::diag
