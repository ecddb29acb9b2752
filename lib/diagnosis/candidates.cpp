// Candidate effects of the diagnosis (see candidates.hpp).
#include "diagnosis/candidates.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <fmt/format.h>

#include "diagnosis/mean_fit.hpp"
#include "diagnosis/plausibility.hpp"
#include "diagnosis/run_block.hpp"
#include "core/parallel_for.hpp"
#include "stats/distributions.hpp"

namespace umbmark::diag {

std::vector<int> EffectParams(sim::EffectKind k) {
  switch (k) {
    case sim::EffectKind::kScaleError: return {kParamScale};
    case sim::EffectKind::kTurnScrub: return {kParamScrub};
    case sim::EffectKind::kDirectionAsymmetry: return {kParamAsym};
    case sim::EffectKind::kCastorKick: return {kParamKappa};
    case sim::EffectKind::kParameterDrift: return {kParamDrift};
    case sim::EffectKind::kGtOffset: return {kParamDx, kParamDy};
    case sim::EffectKind::kTimeOffset: return {kParamTau};
    case sim::EffectKind::kWheelbaseError: return {kParamEb};
    case sim::EffectKind::kDiameterRatioError: return {kParamEd};
    default: return {};
  }
}

/// A typical size of each effect parameter (the realistic ranges of the
/// blind benchmark): an effect is distinguishable from E_d, E_b on a
/// campaign when such an effect would stand 3 standard errors out.
double TypicalMagnitude(int param) {
  switch (param) {
    case kParamScale: return 0.01;
    case kParamScrub: return 0.03;
    case kParamAsym: return 0.01;
    case kParamKappa: return 0.005;
    case kParamDrift: return 1e-4;
    case kParamDx:
    case kParamDy: return 0.01;
    case kParamTau: return 0.02;
    default: return 1.0;
  }
}

bool IsNoiseEffect(sim::EffectKind k) {
  return k == sim::EffectKind::kCorrelatedNoise || k == sim::EffectKind::kBumpOutliers ||
         k == sim::EffectKind::kStandstillMotion || k == sim::EffectKind::kMotionNoiseFloor ||
         k == sim::EffectKind::kRunTimeOffset || k == sim::EffectKind::kWheelNoiseError;
}

void EnableNoiseEffect(sim::EffectKind k, PieceNoiseFitOptions& o) {
  if (k == sim::EffectKind::kCorrelatedNoise) o.correlated = true;
  if (k == sim::EffectKind::kStandstillMotion) o.standstill = true;
  if (k == sim::EffectKind::kMotionNoiseFloor) o.motion_floor = true;
  if (k == sim::EffectKind::kRunTimeOffset) o.run_time = true;
  if (k == sim::EffectKind::kWheelNoiseError) o.fit_wheel_noise = true;
}

std::map<std::string, double> NoiseEffectParams(sim::EffectKind k, const NoiseParams& n) {
  switch (k) {
    case sim::EffectKind::kCorrelatedNoise: return {{"rho", n.rho()}};
    case sim::EffectKind::kBumpOutliers: return {{"rate", n.bump_rate}, {"sigma", std::sqrt(n.bump_s2)}};
    case sim::EffectKind::kStandstillMotion:
      return {{"sigma_xy", std::sqrt(n.stand_xy2)}, {"sigma_theta", std::sqrt(n.stand_th2)}};
    case sim::EffectKind::kMotionNoiseFloor: return {{"sigma", std::sqrt(n.floor_s2)}};
    case sim::EffectKind::kRunTimeOffset: return {{"tau_sd", std::sqrt(n.run_tau2)}};
    case sim::EffectKind::kWheelNoiseError: return {{"k_L", std::sqrt(n.kL2)}, {"k_R", std::sqrt(n.kR2)}};
    default: return {};
  }
}

int EffectParameterCount(sim::EffectKind k) {
  if (k == sim::EffectKind::kBumpOutliers || k == sim::EffectKind::kStandstillMotion ||
      k == sim::EffectKind::kWheelNoiseError)
    return 2;
  if (IsNoiseEffect(k)) return 1;
  return static_cast<int>(EffectParams(k).size());
}

double Gap(double score, double null_median) { return std::max(0.0, score - null_median); }

double Shrink(double after, double before) { return before > 0.0 ? std::max(-1.0, 1.0 - after / before) : 0.0; }

namespace {

/// Everything the candidate fits share.
struct Shared {
  const CampaignData& c;
  const MeanModel& model;
  const BaselineFit& b;
  const Folds& folds;
  const CandidateOptions& options;
  double gap_score = 0.0, null_median = 0.0;
  std::array<double, kNumStatKinds> gap_by_kind{};
  PieceNoiseFitOptions fold_fit;
  Eigen::MatrixXd Jw_b, Ab;  ///< whitened baseline columns and their normal matrix
  double ll_base = 0.0, cv_ll_base = 0.0;
  double gap_before = 0.0, gap_cv_before = 0.0;
};

/// Likelihood-ratio test of a fitted candidate (log-likelihood ll) against
/// the baseline (ll_base).
void LikelihoodRatioTest(Candidate& cd, double ll, double ll_base) {
  cd.tested = true;
  cd.loglik_gain = std::max(0.0, ll - ll_base);
  cd.lr_p_value = ChiSquareSurvival(2.0 * cd.loglik_gain, cd.parameters);
}

/// Whether a mean effect can be told apart from E_d, E_b on these data;
/// false: `cd` is filled as not identifiable. `projected`: the effect's
/// whitened footprint orthogonal to the baseline's.
bool Identify(const Shared& x, const std::vector<int>& eparams, Candidate& cd, Eigen::MatrixXd& projected) {
  // Identifiability against E_d, E_b.
  const Eigen::MatrixXd De = x.model.Jacobian(x.b.p, eparams, x.b.eps);
  Eigen::VectorXd tmp;
  Eigen::MatrixXd Jw_e;
  Whiten(x.b.W, x.b.eps, De, tmp, Jw_e);
  const Eigen::MatrixXd proj = Jw_e - x.Jw_b * x.Ab.ldlt().solve(x.Jw_b.transpose() * Jw_e);
  projected = proj;
  // Distinguishable from E_d, E_b when the part of its footprint they
  // cannot absorb determines a typical-size effect to a third of its
  // size (standard error of the parameter with E_d, E_b free). Between
  // that and ten typical sizes it is weakly identifiable: fitted and
  // tested, named only on its own evidence (turn_scrub on squares and
  // straight runs: only the spot turns' small forward motion, (c_R -
  // c_L) b phi / 4 per turn, tells it from a wheelbase error, and only
  // when E_d is far from 1). Beyond that it is not identifiable: E_d,
  // E_b absorb it (the model would only be guessing).
  bool identifiable = true;
  int mimics = kParamEd;
  double weakest = std::numeric_limits<double>::infinity();  // typical size / se
  for (Eigen::Index k = 0; k < Jw_e.cols(); ++k) {
    const double raw = Jw_e.col(k).norm(), perp = proj.col(k).norm();
    const double se = perp > 0.0 ? 1.0 / perp : std::numeric_limits<double>::infinity();
    const double typical = TypicalMagnitude(eparams[static_cast<std::size_t>(k)]);
    weakest = std::min(weakest, typical / se);
    if (!(raw > 0.0) || !(se < 10.0 * typical)) identifiable = false;
    if (!(se < typical / 3.0)) {
      double best = -1.0;
      for (Eigen::Index b = 0; b < x.Jw_b.cols(); ++b) {
        const double nb = x.Jw_b.col(b).norm();
        const double cosv = raw > 0.0 && nb > 0.0 ? std::abs(x.Jw_b.col(b).dot(Jw_e.col(k))) / (raw * nb) : 0.0;
        if (cosv > best) {
          best = cosv;
          mimics = BaselineParams()[static_cast<std::size_t>(b)];
        }
      }
    }
  }
  // Against a given model (baseline_given.hpp) E_d, E_b are not fitted: an
  // effect they mostly absorb would take the credit for a wheelbase or
  // diameter-ratio error, the simpler name, so it is not named there.
  if (x.b.given && weakest < 3.0) identifiable = false;
  if (!identifiable) {
    cd.identifiable = false;
    cd.note = !(Jw_e.norm() > 0.0) ? "not identifiable on these data: these experiments do not show it at all"
                             : fmt::format("not identifiable on these data: indistinguishable from the baseline's {} "
                                           "(a {})",
                                           ParamName(mimics),
                                           mimics == kParamEb ? "wheelbase error" : "wheel-diameter ratio error");
    for (int k : eparams) cd.params[ParamName(k)] = 0.0;
    cd.E_d = x.b.p[kParamEd];
    cd.E_b = x.b.p[kParamEb];
    cd.gap_after = x.gap_score;
    cd.gap_by_kind = x.gap_by_kind;
    return false;
  }
  if (weakest < 3.0) {
    cd.weak = true;
    cd.note = fmt::format(
        "weakly identifiable on these data: mostly absorbed by the baseline's {} (a {}); a typical-size effect "
        "stands only {:.1f} standard errors out",
        ParamName(mimics), mimics == kParamEb ? "wheelbase error" : "wheel-diameter ratio error", weakest);
  }
  return true;
}

/// A mean effect fitted jointly with E_d, E_b.
MeanFit FitMeanEffect(const Shared& x, sim::EffectKind kind, const std::vector<int>& eparams, Candidate& cd) {
  const CampaignData& c = x.c;
  std::vector<int> joint = x.b.free;
  joint.insert(joint.end(), eparams.begin(), eparams.end());
  MeanFit mf = FitMean(x.model, x.b.p, joint, x.b.W, MeanFitOptions{12});
  // turn_scrub also changes the noise's heading in spot turns relative
  // to straight motion: its covariance bases follow the fit.
  std::vector<PieceBases> scrub_bases;
  if (kind == sim::EffectKind::kTurnScrub) scrub_bases = ComputeBases(c, x.model, mf.p);
  const std::vector<PieceBases>& bases = kind == sim::EffectKind::kTurnScrub ? scrub_bases : x.b.bases;
  NoiseParams ne = FitPieceNoise(mf.eps, bases, c.pieces, {}, x.b.noise, x.b.noise_fit);
  const std::vector<Eigen::Matrix3d> We = Whiteners(bases, c.pieces, ne);
  // Parameter standard errors with the refitted noise.
  Eigen::VectorXd r2;
  Eigen::MatrixXd J2;
  Whiten(We, mf.eps, mf.D, r2, J2);
  const Eigen::MatrixXd cov = (J2.transpose() * J2).ldlt().solve(Eigen::MatrixXd::Identity(J2.cols(), J2.cols()));
  for (std::size_t k = 0; k < eparams.size(); ++k) {
    const auto at = static_cast<Eigen::Index>(x.b.free.size() + k);
    cd.params[ParamName(eparams[k])] = mf.p[eparams[k]];
    cd.param_se[ParamName(eparams[k])] = std::sqrt(std::max(0.0, cov(at, at)));
  }
  cd.E_d = mf.p[kParamEd];
  cd.E_b = mf.p[kParamEb];
  LikelihoodRatioTest(cd, TotalLogLik(c, bases, mf.eps, ne), x.ll_base);
  const GapSummary ga = ComputeGap(c, PieceScores(mf.eps, bases, c.pieces, ne), x.options.gap);
  cd.gap_after = ga.score;
  cd.gap_by_kind = ga.by_kind;
  const CrossValidation cv = CrossValidate(
      c, bases, x.folds, mf.eps, mf.D, We, [&](const std::vector<double>& e, const std::vector<char>& use) {
        return FitPieceNoise(e, bases, c.pieces, use, ne, x.fold_fit);
      });
  cd.heldout_loglik_gain = cv.loglik - x.cv_ll_base;
  const double gcv = ComputeGap(c, cv.scores, x.options.gap).score;
  cd.heldout_shrink = Shrink(Gap(gcv, x.null_median), x.gap_cv_before);
  return mf;
}

/// correlated_noise or bump_outliers on the baseline's residuals.
void FitNoiseEffect(const Shared& x, sim::EffectKind kind, Candidate& cd) {
  const CampaignData& c = x.c;
  // Gaussian noise effects (a variance component each); bump_outliers is
  // a mixture with its own fit.
  const bool corr = kind != sim::EffectKind::kBumpOutliers;
  cd.parameters = EffectParameterCount(kind);
  cd.E_d = x.b.p[kParamEd];
  cd.E_b = x.b.p[kParamEb];
  PieceNoiseFitOptions cf = x.b.noise_fit;
  EnableNoiseEffect(kind, cf);
  PieceNoiseFitOptions cf_fold = x.fold_fit;
  EnableNoiseEffect(kind, cf_fold);
  NoiseParams ne = corr ? FitPieceNoise(x.b.eps, x.b.bases, c.pieces, {}, x.b.noise, cf)
                        : FitBumps(x.b.eps, x.b.bases, c.pieces, {}, x.b.noise, /*start_only=*/false,
                                   cf.fit_wheel_noise);
  // run_time_offset: its levers at the fitted tau_sd (run_block.hpp).
  std::vector<PieceBases> rescaled;
  if (kind == sim::EffectKind::kRunTimeOffset)
    rescaled = RescaleTimeLevers(x.model, x.b.p, x.b.bases, ne, [&](const std::vector<PieceBases>& bs, const NoiseParams& s) {
      return FitPieceNoise(x.b.eps, bs, c.pieces, {}, s, cf);
    });
  const std::vector<PieceBases>& bases = rescaled.empty() ? x.b.bases : rescaled;
  cd.params = NoiseEffectParams(kind, ne);
  // A variance at its boundary 0 under the baseline: Wilks' chi^2 is
  // conservative there (the true null is a 50:50 mixture), so the test
  // keeps its level.
  if (corr) LikelihoodRatioTest(cd, TotalLogLik(c, bases, x.b.eps, ne), x.ll_base);
  const GapSummary ga = ComputeGap(c, PieceScores(x.b.eps, bases, c.pieces, ne), x.options.gap);
  cd.gap_after = ga.score;
  cd.gap_by_kind = ga.by_kind;
  const CrossValidation cv = CrossValidate(
      c, bases, x.folds, x.b.eps, x.b.D, x.b.W, [&](const std::vector<double>& e, const std::vector<char>& use) {
        return corr ? FitPieceNoise(e, bases, c.pieces, use, ne, cf_fold)
                    : FitBumps(e, bases, c.pieces, use, ne, /*start_only=*/true, cf_fold.fit_wheel_noise);
      });
  cd.heldout_loglik_gain = cv.loglik - x.cv_ll_base;
  const double gcv = ComputeGap(c, cv.scores, x.options.gap).score;
  cd.heldout_shrink = Shrink(Gap(gcv, x.null_median), x.gap_cv_before);
  // With the wheel noise given (diagnose --baseline --kl --kr), bumps at
  // their rate bound are their Gaussian limit: many small travel errors,
  // rate x sigma_b^2 of variance per metre, i.e. wheel noise growing with
  // distance, more than the given k. That is a wheel_noise_error (which
  // names the wheel and the k to set), not bumps.
  if (kind == sim::EffectKind::kBumpOutliers && !cf.fit_wheel_noise && ne.bump_rate >= 0.95 * kMaxBumpRatePerMetre) {
    cd.identifiable = false;
    cd.note = fmt::format("not identifiable here: indistinguishable from wheel_noise_error: fitted at its rate bound "
                          "({:.2g} per metre of {:.2g} mm), bumps are their Gaussian limit, wheel noise growing "
                          "with distance, more than the given k",
                          ne.bump_rate, 1e3 * std::sqrt(ne.bump_s2));
  }
}

}  // namespace

CandidateFits FitCandidates(const CampaignData& c, const MeanModel& model, const BaselineFit& b, const Folds& folds,
                            double gap_score, double null_median, const CandidateOptions& options) {
  Shared x{c, model, b, folds, options, gap_score, null_median, {}, {}, {}, {}, 0.0, 0.0, 0.0, 0.0};
  x.gap_by_kind = ComputeGap(c, PieceScores(b.eps, b.bases, c.pieces, b.noise), options.gap).by_kind;
  x.fold_fit = b.noise_fit;
  x.fold_fit.line_search = false;
  x.fold_fit.max_iterations = 6;
  // Baseline, cross-validated.
  const CrossValidation cv_base =
      CrossValidate(c, b.bases, folds, b.eps, b.D, b.W, [&](const std::vector<double>& e, const std::vector<char>& use) {
        return FitPieceNoise(e, b.bases, c.pieces, use, b.noise, x.fold_fit);
      });
  x.cv_ll_base = cv_base.loglik;
  const double gcv_base = ComputeGap(c, cv_base.scores, options.gap).score;
  x.gap_before = Gap(gap_score, null_median);
  x.gap_cv_before = Gap(gcv_base, null_median);
  x.ll_base = TotalLogLik(c, b.bases, b.eps, b.noise);
  // Identifiability is judged against E_d, E_b also for a given model
  // (baseline_given.hpp), whose baseline fits neither: an effect they
  // absorb would be a wheelbase or diameter-ratio error in disguise.
  Eigen::VectorXd rw_b;
  Whiten(b.W, b.eps, b.free == BaselineParams() ? b.D : model.Jacobian(b.p, BaselineParams(), b.eps), rw_b, x.Jw_b);
  x.Ab = x.Jw_b.transpose() * x.Jw_b;

  CandidateFits out;
  const std::vector<sim::EffectKind>& effects = options.effects;
  out.candidates.resize(effects.size());
  out.projected.resize(effects.size());
  std::vector<MeanFit> mean_fits(effects.size());
  const auto fit_one = [&](int i) {
    const auto ei = static_cast<std::size_t>(i);
    const sim::EffectKind kind = effects[ei];
    Candidate& cd = out.candidates[ei];
    cd.effect = kind;
    const std::vector<int> eparams = EffectParams(kind);
    if (!eparams.empty()) {
      cd.parameters = static_cast<int>(eparams.size());
      // A parameter error frees a baseline parameter itself: nothing to
      // tell it apart from.
      if (!sim::IsParameterError(kind) && !Identify(x, eparams, cd, out.projected[ei])) return;
      mean_fits[ei] = FitMeanEffect(x, kind, eparams, cd);
    } else if (IsNoiseEffect(kind)) {
      FitNoiseEffect(x, kind, cd);
    } else {
      cd.identifiable = false;
      cd.note = "not a contract effect; not fitted";
      return;
    }
    cd.impossible = !UnphysicalFit(sim::EffectToString(kind), cd.params, static_cast<int>(c.runs.size())).empty();
    cd.shrink = Shrink(Gap(cd.gap_after, null_median), x.gap_before);
    cd.evidence = cd.heldout_loglik_gain - options.complexity_penalty_nats * cd.parameters;
  };
  ProgressCounter progress(options.progress, static_cast<double>(effects.size()));
  ParallelFor(options.threads, static_cast<int>(effects.size()), [&](int i) {
    fit_one(i);
    progress.Add();
  });
  for (std::size_t i = 0; i < effects.size(); ++i) {
    if (mean_fits[i].eps.empty()) continue;
    std::vector<int> key = b.free;
    for (int k : EffectParams(effects[i])) key.push_back(k);
    out.mean_fits.emplace(std::move(key), std::move(mean_fits[i]));
  }
  return out;
}

}  // namespace umbmark::diag
