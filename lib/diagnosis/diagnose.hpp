// `umbmark diagnose`: where a campaign leaves the baseline model, which of
// the contract's effects causes it, and how far the gap shrinks once that
// effect is modelled.
//
// Steps (each timed in DiagnoseSummary::timings; one file per stage):
//  1. Baseline (baseline.hpp, mean_fit.hpp, return_check.hpp): E_d, E_b from the refined calibration (refine.hpp, scale
//     fixed) polished by Ceres (Levenberg-Marquardt) on the whitened piece residuals (model.hpp);
//     k_L, k_R (and the ground truth's sigmas when the manifest does not
//     state them) by maximum likelihood (piece_noise.hpp). Predicted return
//     errors (mean, covariance) per experiment and direction, and residual
//     growth per segment type.
//  2. Where (where.hpp, null_distribution.hpp): the gap statistics (gap_stats.hpp), ranked by |z|; the gap
//     score G and its p-value from a parametric bootstrap of the fitted
//     baseline itself (null_simulations campaigns of piece residuals drawn
//     from the baseline's noise model -- wheel noise per piece, ground-truth
//     noise per boundary sample, encoder quantisation -- each refitted like
//     the data), so data from the baseline raise a false alarm at rate
//     alpha.
//  3. Which (candidates.hpp, cross_validation.hpp): every contract effect fitted on top of the baseline (mean
//     effects: their parameters with E_d, E_b by Ceres; correlated
//     noise and bumps: maximum likelihood), with gap after, shrink and
//     heldout_shrink from k-fold cross-validation over runs. Candidates are
//     ranked by held-out log-likelihood gain minus complexity_penalty_nats
//     per parameter.
//  4. Significance (verdict.hpp): the gap score G spreads its power over hundreds of
//     statistics, so a small effect that moves one parameter (a noise
//     correlation, say) can hide in it. Beside G, every candidate with a
//     regular likelihood (the mean effects and correlated_noise) gives a
//     likelihood-ratio test against the baseline (Wilks: chi^2 with as many
//     degrees of freedom as parameters); the tests are combined by
//     Bonferroni, p_tests = min(1, m min p_e), and with G's own p-value,
//     p = min(1, 2 min(p_G, p_tests)), so the false-alarm rate stays at most
//     alpha.
//  5. Verdict (verdict.hpp): `none` when p >= alpha; else the verdict is
//     the stepwise explanation's (explanation.hpp; docs/diagnosis.md, "The
//     verdict's rule"): effects added one at a time by held-out evidence,
//     the first like every other; its practical effects are named when,
//     G having found the gap, they close at least min_heldout_shrink of it
//     held out and what they leave lies mostly outside the runs' means
//     (a significant remainder is reported beside them), or when
//     the residual G is not significant (or below 1 - full_shrink of the
//     held-out gap); else `unexplained`. This stage
//     ranks the candidates fitted alone and lists the effects the data
//     cannot tell apart (from the baseline, or from each other).
//
// Gap sizes: gap = max(0, G - G0) with G0 the median of G over the null
// simulations (what the model's own noise produces), so shrink =
// 1 - gap_after / gap_before is 1 when an effect brings the data back to
// noise level.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>

#include "diagnosis/baseline_given.hpp"
#include "diagnosis/candidates.hpp"
#include "diagnosis/explanation.hpp"
#include "diagnosis/gap_stats.hpp"
#include "diagnosis/model.hpp"
#include "diagnosis/piece_noise.hpp"
#include "diagnosis/piece_residuals.hpp"
#include "diagnosis/pieces.hpp"
#include "diagnosis/return_check.hpp"
#include "diagnosis/run_faults.hpp"
#include "diagnosis/standstill_noise.hpp"
#include "diagnosis/where.hpp"
#include "simulation/effects.hpp"

namespace umbmark::diag {

struct DiagnoseOptions {
  /// Bootstrap campaigns for the gap's p-value (>= 20). Default 500.
  int null_simulations = 500;
  /// False-alarm rate: the gap is significant when p < alpha. Default 0.01.
  double alpha = 0.01;
  /// The named explanation must close at least this fraction of the gap on
  /// held-out runs when the gap score found the gap; closing it, its
  /// effects are named, and a significant remainder is reported beside
  /// them (DiagnoseSummary::remainder_significant). Default 0.5 ("the
  /// larger part").
  double min_heldout_shrink = 0.5;
  /// A gap closed by negligible effects only is `none` when the explanation
  /// leaves no significant gap (G after its last step below the null's 1 -
  /// alpha quantile) or its cumulative held-out shrink reaches this (a
  /// residual under a tenth of the gap is a misfit of the effects' shape,
  /// not another cause). Default 0.9.
  double full_shrink = 0.9;
  /// Held-out log-likelihood an effect must gain per parameter. Default 2 nats.
  double complexity_penalty_nats = 2.0;
  /// The verdict names an effect of the explanation only when, given the
  /// others, it earns at least this much held-out log-likelihood after its
  /// penalty (ExplanationStep::earned_given_others_nats): a held-out
  /// likelihood ratio of 100, "decisive" on Jeffreys' scale. Below it the
  /// effect stays a step, reported as not decisive. Default ln 100 = 4.61.
  double decisive_nats = 4.605170185988092;
  /// Seed of the bootstrap. Default 1.
  std::uint64_t seed = 1;
  /// Threads for the bootstrap and the candidate fits (>= 1). Default 2.
  int threads = 2;
  /// Ranked discrepancies listed under "where". Default 12.
  int where_top = 12;
  /// Use the refined calibration (refine.hpp) for the starting E_d, E_b.
  /// Default true.
  bool use_refine = true;
  /// Combine G's p-value with the candidates' likelihood-ratio tests
  /// (step 4 above). Default true; false: the gap is judged by G alone.
  bool likelihood_tests = true;
  /// Practical significance: an effect whose size (explanation.hpp: how far
  /// it moves the predicted pose over a run, relative to the scatter of one
  /// piece's motion under the explained model; for a noise effect how much
  /// it widens the pose spread of the pieces it acts on, per piece type) is
  /// below this is negligible and never named in the verdict. Default 0.25.
  double negligible = 0.25;
  /// Most effects in the stepwise explanation (>= 1). Default 4.
  int max_explanation_effects = 4;
  /// A step of the explanation may not lower the cumulative held-out shrink
  /// (ExplanationOptions::keep_heldout_shrink). Default false.
  bool keep_heldout_shrink = false;
  /// The baseline's fit: where the ground truth's noise comes from when the
  /// manifest does not state it (baseline.hpp; default the standstill
  /// scatter, `ground_truth = kFitted` for the fit before issue 28).
  BaselineFitOptions baseline_fit;
  /// Effects to try (empty: the contract's fourteen; with `given`, also its
  /// parameter errors).
  std::vector<sim::EffectKind> effects;
  /// The user's simulation model as the baseline (`--baseline CAL.json
  /// [--kl K --kr K]`, baseline_given.hpp); absent: the model fitted to the
  /// runs. Only with it are wheelbase_error, diameter_ratio_error and
  /// wheel_noise_error candidates.
  std::optional<GivenModel> given;
  /// Look for faults of single runs (run_faults.hpp) and fit the effects
  /// without them. Default true.
  bool find_run_faults = true;
  /// The run-fault test's options (its seed is `seed`'s).
  RunFaultOptions run_faults;
  PieceOptions pieces;
  GapOptions gap;
  /// Progress of the whole diagnosis (core/progress.hpp), in thousandths:
  /// 0-400 the null simulations, 400-700 the candidate fits, 700-1000 the
  /// stepwise explanation (skipped, i.e. jumped over, without a significant
  /// gap). Default: none.
  ProgressCallback progress;

  std::string Check() const;
};

struct BaselineSummary {
  double E_d = 1.0, E_b = 1.0;
  double k_L = 0.0, k_R = 0.0;
  double sigma_xy_m = 0.0, sigma_theta_rad = 0.0;
  bool ground_truth_estimated = false;
  /// Where sigma_xy_m, sigma_theta_rad come from: "manifest",
  /// "standstills" (the scatter below) or "fitted" (with the wheel noise).
  std::string ground_truth_source;
  /// The ground truth's noise measured inside standstills, where no
  /// candidate effect reaches it (standstill_noise.hpp).
  StandstillNoise standstill;
  /// Source "standstills": the sigmas the pieces would fit with the wheel
  /// noise (a warning when far from the scatter) [m], [rad]; else 0.
  double pieces_sigma_xy_m = 0.0, pieces_sigma_theta_rad = 0.0;
  /// Where k_L, k_R come from: "repeats" (the scatter of repeated runs
  /// below), "fitted" (jointly with E_d, E_b on the pieces) or "given".
  std::string wheel_noise_source;
  /// The wheel noise from the scatter of repeated runs about their own mean
  /// (repeat_noise.hpp), or why the design does not support it.
  RepeatNoise repeat;
  /// Source "repeats": k_L, k_R the pieces would fit jointly with the mean
  /// (a warning when far from the repeated runs') [m^1/2]; else 0.
  double pieces_k_L = 0.0, pieces_k_R = 0.0;
  std::string start;  ///< where E_d, E_b started (refine or nominal)
  std::vector<ReturnPrediction> returns;
  std::vector<GrowthRow> growth;
  int pieces = 0, runs = 0;
  /// Cross-check: k_L, k_R from the runs' return errors alone by the
  /// fit-noise estimator (error_models/wheel_noise_fit.hpp: systematic mean per
  /// experiment and direction, Kelly's covariance along each run, the
  /// ground truth's noise), with 95 % profile intervals. Absent when that
  /// fit cannot run (too few runs per group); a disagreement with the piece
  /// estimate above says the noise does not grow with distance as eq. 4 has it.
  bool return_fit = false;
  double return_k_L = 0.0, return_k_R = 0.0;
  std::array<double, 2> return_k_L_ci{0.0, 0.0}, return_k_R_ci{0.0, 0.0};
  std::string return_fit_note;
  /// The given model (`--baseline`): its source and values; E_d, E_b above
  /// are then its own, k_L, k_R too when noise_given.
  std::optional<GivenModel> given;
};

struct DiagnoseSummary {
  BaselineSummary baseline;
  double gap_score = 0.0;       ///< G of the baseline
  double null_median = 0.0;     ///< G0
  double null_quantile_alpha = 0.0;  ///< G at the 1 - alpha quantile of the null
  double p_value = 1.0;         ///< combined: min(1, 2 min(score_p_value, tests_p_value))
  double score_p_value = 1.0;   ///< G against its null simulations
  double tests_p_value = 1.0;   ///< min(1, m min_e p_e) over the m tested candidates
  int tests = 0;                ///< m
  double alpha = 0.01;
  int null_simulations = 0;
  bool significant = false;
  std::array<double, kNumStatKinds> gap_by_kind{};
  std::vector<WhereItem> where;
  /// What is left after the explanation: the same statistics as `where`,
  /// of the explained model (its last step's joint fit: mean parameters,
  /// noise, covariance bases), largest first; G of that model in
  /// remaining_gap_score. Empty (and NaN) without an explanation step.
  std::vector<WhereItem> remaining_where;
  double remaining_gap_score = NAN;
  /// Every piece's standardised residual under the baseline
  /// (piece_residuals.hpp), in campaign order: where the runs leave the model.
  std::vector<PieceResidual> piece_residuals;
  std::vector<Candidate> candidates;  ///< best first
  std::string verdict;                ///< effect name | none | unexplained
  std::string verdict_reason;
  /// Stepwise explanation (explanation.hpp), in the order added; empty
  /// without a significant gap.
  std::vector<ExplanationStep> explanation;
  /// The explained model's E_d, E_b: fitted jointly with the explanation's
  /// effects (its last step), which the advice's concrete changes use; the
  /// baseline's when there is no step. A marker offset or a clock the
  /// baseline leaves out can drive its E_b far off (s4 of the June
  /// sessions with a 47 mm marker: E_b 1.245; explained, 1.00).
  double explained_E_d = 1.0, explained_E_b = 1.0;
  /// The robot those E_d, E_b describe (B&F eqs. 4.31, 4.32 on the
  /// manifest's robot: wheelbase E_b b, diameters c_L D_L, c_R D_R) [m];
  /// 0 when there is no explanation step or the model is given. Printed
  /// beside the baseline's (JSON verdict.explained_model).
  double explained_wheelbase_m = 0.0, explained_diameter_left_m = 0.0, explained_diameter_right_m = 0.0;
  std::string explanation_stop;
  /// Fits the explanation met that no robot can have, or noise effects at
  /// zero (Explanation::symptoms): symptoms, never steps (JSON `symptoms`).
  std::vector<ExplanationStep> symptoms;
  /// Every effect the verdict names (the explanation's non-negligible
  /// effects; for `unexplained` those that close part of the gap).
  std::vector<std::string> verdict_effects;
  /// 1 - the explanation's cumulative held-out shrink (0 for `none`).
  double unexplained_fraction = 0.0;
  /// What the explanation's shrinks are measured against
  /// (docs/diagnosis.md, "The shrink's reference"): "baseline", or
  /// "mean_effects_wheel_noise" (the baseline's mean seen with the wheel
  /// noise left once the explanation's mean effects are fitted) where the
  /// baseline does not see the larger part of the gap closed and that
  /// reference sees more. JSON verdict.shrink_reference.
  std::string shrink_reference = "baseline";
  /// The explanation's held-out shrink against the baseline itself (equal
  /// to 1 - unexplained_fraction with the baseline as reference). JSON
  /// verdict.heldout_shrink_against_baseline.
  double heldout_shrink_against_baseline = 0.0;
  /// The gap left after the explanation is still significant (G with its
  /// effects fitted above the null's 1 - alpha quantile) and more than the
  /// misfit of the effects' shape (their held-out shrink below
  /// full_shrink, against the shrinks' reference and against the baseline
  /// both); false for `none`. With a named verdict: the named
  /// effects close the larger part of the gap and a remainder no listed
  /// effect describes is left.
  bool remainder_significant = false;
  /// The share of the gap left (G with the explanation's effects fitted)
  /// in mean and trend statistics: what is the same in every run, or
  /// drifts over the runs. At min_heldout_shrink or more the remainder is
  /// a systematic cause no listed effect describes and the verdict is
  /// `unexplained`; below, it is the noise description's misfit
  /// (variances, correlations, tails), reported beside the named effects.
  double remainder_mean_share = 0.0;
  double negligible_threshold = 0.25;
  std::vector<std::string> indistinguishable;
  /// With a given model: what to change in the user's simulation, for every
  /// parameter error the verdict names.
  std::vector<ParameterCorrection> corrections;
  /// Faults of single runs (run_faults.hpp; contract `run_faults`): these
  /// runs were left out, and everything else in this summary (baseline,
  /// candidates, verdict) is fitted without them.
  std::vector<RunFault> run_faults;
  /// The run-fault test in one sentence (empty when it did not run).
  std::string run_fault_test;
  /// What a person must know before trusting the numbers (JSON `warnings`):
  /// e.g. a fitted ground-truth noise the standstills contradict.
  std::vector<std::string> warnings;
  std::vector<std::pair<std::string, double>> timings;  ///< stage, seconds
  std::vector<std::string> experiment_labels;
  std::vector<std::string> notes;
  /// The reading of the encoder stops the diagnosis used (stop_model.hpp).
  StopModel stop_model = StopModel::kWheelEdge;
  /// What to do next, for a person (advice.hpp).
  std::vector<std::string> next_steps;
  /// What is wrong with the robot or the recording and what to do, in plain
  /// words, no statistics (advice.hpp PlainSummary; JSON `summary`): the
  /// report opens with it.
  std::string summary;
  std::uint64_t seed = 0;
};

/// Runs the diagnosis. Throws InvalidOptions for bad options; the campaign
/// is already validated by BuildCampaign.
DiagnoseSummary Diagnose(const CampaignData& campaign, const DiagnoseOptions& options);

/// The contract's JSON ("gap", "candidates", "verdict") plus "baseline",
/// "indistinguishable", "timing_s".
nlohmann::json DiagnoseToJson(const DiagnoseSummary& summary);

/// A readable report (the app prints it).
std::string DiagnoseReport(const DiagnoseSummary& summary);

/// SVG bars of the gap per statistic kind before and after the winning
/// effect (or the best candidate).
std::string DiagnosePlotSvg(const DiagnoseSummary& summary);

}  // namespace umbmark::diag
