// Stage "explanation" of the diagnosis: real robots differ from the model in
// more than one way, so the gap is explained by a SET of effects, added one
// at a time (forward selection). At every step each remaining candidate is
// fitted jointly with the effects already chosen (mean parameters with
// E_d, E_b by weighted least squares; the noise refitted, with rho or bumps
// when chosen) and cross-validated over runs; the one with the largest
// held-out log-likelihood gain is added when it gains more than the
// complexity penalty per parameter, the first step like every other (no
// effect of a kind is preferred). Selection stops when no effect gains
// held-out evidence or the remaining gap is no longer significant (G at or
// below the null's 1 - alpha quantile); then every chosen effect must
// still earn its penalty given the others (backward check), else it is
// left out. The verdict is this explanation (diagnose.cpp NameEffects;
// docs/diagnosis.md, "The verdict's rule").
//
// Practical significance: an effect's size is how far it moves the
// predicted (measured) pose over a run -- the RMS over a run's ground-truth
// samples of the change in predicted position [mm] and heading [mrad] when
// the effect is removed (the others kept), median over an experiment's
// runs, largest over the experiments -- relative to
// the noise the diagnosis compares with: the baseline's scatter of one
// piece's relative motion (wheel noise over a piece of up to 1 m or a spot
// turn, plus the ground truth's noise at both ends; RMS over the pieces;
// position and heading separately, the larger ratio counts). A noise
// effect changes the spread, not the mean, and matters most on short
// pieces, so its size is measured on the pieces the campaign has: per
// piece type, the median relative growth of the predicted pose sd of the
// pieces it acts on, the type where it is largest (standstill_motion,
// motion_noise_floor; `size_pieces` names the type); run_time_offset is
// sized as a fixed time_offset of tau_sd (a run with the typical offset);
// the relative growth of the wheel-noise sd for correlated_noise and
// bump_outliers; and for wheel_noise_error |k_fit / k_given - 1|, the
// wheel further off. Below `negligible` (default 0.25: a quarter of the noise) an
// effect is negligible: reported, never named in the verdict, however
// significant. Beside that relative rule, mismatches every robot has are
// negligible whatever the noise (PracticalFloor, each effect's own, as a
// pose size at the campaign's speeds and distances): a clock offset |tau|
// or tau_sd that moves the pose by less than 0.3 mm at the campaign's
// typical speed and 0.3 mrad at its typical turn rate, a common diameter
// error that adds less than 0.3 mm over a typical motion, a marker within
// 0.3 mm of the axle midpoint, a castor kick or swivel below 0.3 mrad; the
// floors scale with `negligible` / 0.25 (0 switches them off with the
// relative rule). At 2 m/s a 1.4 ms clock is 2.8 mm: not negligible.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "diagnosis/candidates.hpp"
#include "effects/effect.hpp"

namespace umbmark::diag {

struct ExplanationOptions {
  /// Most effects in the explanation. Default 4.
  int max_effects = 4;
  /// Held-out nats an added effect must gain per parameter. Default 2.
  double complexity_penalty_nats = 2.0;
  /// Relative size below which an effect is negligible. Default 0.25.
  double negligible = 0.25;
  /// Threads (>= 1); results do not depend on them. Default 2.
  int threads = 2;
  GapOptions gap;
  /// Admit a step only when it does not lower the cumulative held-out
  /// shrink (besides gaining held-out evidence and being no symptom).
  /// Default false: measured on the injection harness' tuning sessions
  /// (docs/diagnosis.md, "The verdict's rule"), the held-out gap score of
  /// real recordings falls for correct effects (the baseline's noise, fitted
  /// with the effect unmodelled, is too wide), and the rule dropped them;
  /// the likelihood is the criterion, the shrink is reported as it comes.
  bool keep_heldout_shrink = false;
  /// The larger part of the gap (DiagnoseOptions::min_heldout_shrink): below
  /// it against the baseline, the shrinks are measured against the shrinks'
  /// reference when that sees more (Explanation::reference_held). Default 0.5.
  double min_heldout_shrink = 0.5;
  /// Progress in effect sets fitted, of at most max_effects x the candidates
  /// (core/progress.hpp); reaches the total when the search stops early.
  /// Default: none.
  ProgressCallback progress;
};

struct ExplanationStep {
  sim::EffectKind effect{};
  /// Parameters of this effect as fitted jointly at this step: the one
  /// value the report, the JSON, the HTML page, the advice and the
  /// suggested `simulate` command give.
  std::map<std::string, double> params;
  double gap_after = 0.0;                  ///< G with every effect so far
  double cumulative_shrink = 0.0;          ///< in-sample
  double cumulative_heldout_shrink = 0.0;  ///< on held-out runs
  double heldout_gap_after = 0.0;          ///< G on held-out runs with every effect so far
  double heldout_gain_nats = 0.0;          ///< over the previous step, held out
  /// Held-out log-likelihood the final explanation loses without this
  /// effect (the others refitted), less its parameters' penalty: what it
  /// earns given all the others. The verdict names its effects in this
  /// order (the first closes most of the gap given the rest).
  double earned_given_others_nats = 0.0;
  /// Practical size (see the file comment), at the last step's joint fit.
  double size_mm = 0.0, size_mrad = 0.0;
  double relative_size = 0.0;
  /// Noise effects: the piece type whose spread the effect widens most
  /// ("straight", "spot turn", ...), where size_mm, size_mrad and
  /// relative_size are measured; empty for the others.
  std::string size_pieces;
  bool negligible = false;
  /// Negligible by PracticalFloor (what every robot has), in words; empty
  /// otherwise.
  std::string practical_floor;
  /// Why this fit is physically impossible (advice.hpp UnphysicalFit, with
  /// the single-effect candidate's standard errors), empty when it is not;
  /// filled by Diagnose. Such a step is a symptom and never named.
  std::string unphysical;
  /// Given the others it earns less than DiagnoseOptions::decisive_nats:
  /// a step of the explanation, reported, not named (filled by Diagnose).
  bool not_decisive = false;
  /// Its fitted value lies outside the effect's physical range, but within
  /// the tolerance of its standard errors (so not `unphysical`, e.g. a turn
  /// scrub of k = -0.005, 1.5 SE below 0): a step, never named; why, in
  /// words (filled by Diagnose), else empty.
  std::string outside_range;
  /// A named noise effect (class noise) whose added variance or evidence
  /// lies, for the larger part, on pieces where the named mechanisms move
  /// the predicted mean, or their own random parts add, at least its own
  /// sd there: the mechanisms' scatter about their one value, not a cause
  /// of its own (mechanism_spread.hpp MarkSpreads); their names, joined by " + ", else empty.
  /// Such a step is reported, never named.
  std::string spread_of_named;
};

/// Decimals to print a relative size with next to the negligible
/// threshold: three where two would print the threshold itself (x 0.249
/// beside "negligible" below 0.25), else two. Text and HTML reports.
inline int RelativeSizeDecimals(double relative_size, double threshold) {
  return relative_size - threshold < 0.005 && threshold - relative_size < 0.005 ? 3 : 2;
}

/// Why an effect with these fitted parameters is too small to matter
/// whatever the noise (see the file comment), or empty: the effect's own
/// floor (Effect::PracticalFloor), a pose size at the campaign's speeds and
/// distances (`campaign`, campaign_scale.hpp; the floors scale with its
/// negligible / 0.25).
std::string PracticalFloor(sim::EffectKind effect, const std::map<std::string, double>& params,
                           const effects::CampaignScale& campaign);

struct Explanation {
  std::vector<ExplanationStep> steps;  ///< in the order added
  bool gap_left = true;  ///< G after the last step still above the null's 1 - alpha quantile
  std::string stop_reason;
  /// Effects whose joint fit would have been the next step but came out at
  /// a value no robot can have (plausibility.hpp UnphysicalFit, e.g. a
  /// noise correlation of 0.995) or, for a noise effect, at zero (NullNoiseFit:
  /// whatever it gains is the other noise refitted): symptoms, never
  /// steps. Each with its params, the reason in `unphysical` and the
  /// held-out gain it showed; at most one entry per effect.
  std::vector<ExplanationStep> symptoms;
  /// An effect at an impossible value (not a noise effect at zero) had more
  /// held-out evidence than the first step: the gap's largest part is
  /// something no listed effect describes at a possible value, and the
  /// verdict names nothing (docs/diagnosis.md, "The verdict's rule").
  bool symptom_first = false;
  /// The explained model: the last step's joint fit (the baseline's when
  /// there is no step): mean parameters, noise, and the covariance bases it
  /// is whitened with (run_faults.hpp' second pass is taken under it).
  ParamVector p{};
  NoiseParams noise;
  std::vector<PieceBases> bases;
  /// The baseline's wheel noise refitted to the residuals of the
  /// explanation's mean part (its mean effects fitted, no noise effect
  /// beside them) [m^1/2], when the baseline fits its wheel noise and the
  /// explanation has a mean effect: what the baseline's k would be had it
  /// not taken those effects in (docs/diagnosis.md, "What the baseline's
  /// wheel noise took in").
  bool mean_wheel_noise_measured = false;
  double mean_wheel_noise_k_L = 0.0, mean_wheel_noise_k_R = 0.0;
  /// The last step's cumulative held-out shrink measured against the
  /// baseline itself. Where the baseline does not see the larger part of
  /// the gap closed (ExplanationOptions::min_heldout_shrink) and the
  /// shrinks' reference sees more (docs/diagnosis.md, "The shrink's
  /// reference": the baseline's mean seen with the wheel noise above) the
  /// steps' shrinks are measured against the reference; the
  /// remainder's excuse (DiagnoseOptions::full_shrink) takes the smaller of
  /// the two, so a reference the baseline could not see never makes a
  /// remainder look small. Equal to the last step's shrink without a
  /// reference; 0 without a step.
  double baseline_heldout_shrink = 0.0;
  /// The steps' shrinks are measured against the shrinks' reference, not
  /// the baseline (see baseline_heldout_shrink).
  bool reference_held = false;
};

/// A random effect that is the spread about a fixed effect's value
/// (effects::Descriptor::spread_of: run_time_offset about time_offset) is
/// tried only once that effect is chosen or may not be a step: a zero-mean
/// per-run clock takes a clock common to all runs as spread (June session
/// s1 with +80 ms: tau_sd = 110 ms, and time_offset beside it then lost 27
/// nats held out). docs/diagnosis.md, "The mean before the spread about it".
///
/// The rule that admits a step (docs/diagnosis.md, "The verdict's rule"):
/// it gains more than the penalty per parameter in held-out log-likelihood
/// and is no symptom (see Explanation::symptoms); with keep_heldout_shrink
/// it also may not lower the cumulative held-out shrink. Among the
/// admissible trials the largest held-out gain wins, at the first step as
/// at every other. So every step adds held-out evidence; the cumulative
/// held-out shrink is reported as it comes (the likelihood is the
/// criterion), against one reference for every step (the baseline, or
/// where Explanation::reference_held the shrinks' reference), so a step
/// that never lowers the held-out G never lowers its shrink either.
///
/// `known`: mean fits already made (FitCandidates' mean_fits: the same
/// fits, so not repeated). The first step is chosen by the same rule as
/// every other. gap_score, null_median, null_quantile:
/// the baseline's G, the null's median G0 and 1 - alpha quantile.
Explanation Explain(const CampaignData& c, const MeanModel& model, const BaselineFit& baseline,
                    const Folds& folds, const std::vector<Candidate>& candidates,
                    const std::map<std::vector<int>, MeanFit>& known, double gap_score, double null_median,
                    double null_quantile, const ExplanationOptions& options);

}  // namespace umbmark::diag
