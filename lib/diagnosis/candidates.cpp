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
#include "effects/registry.hpp"
#include "stats/distributions.hpp"

namespace umbmark::diag {

std::vector<int> EffectParams(sim::EffectKind k) {
  const effects::Effect& e = effects::Of(k);
  if (!e.Describe().mean_terms.empty()) return e.Describe().mean_terms;
  return RunTimeParams(e);  // one that predicts through the interface, or a noise effect
}

namespace {

bool Has(const std::vector<int>& v, int k) { return std::find(v.begin(), v.end(), k) != v.end(); }

}  // namespace

std::vector<int> EffectParams(sim::EffectKind k, const CampaignData& c) {
  std::vector<int> all = EffectParams(k);
  // The coast terms show only at stops of their kind (effects::MeanTerm).
  if (!Has(all, kParamSlideD)) return all;
  bool line_stop = false, turn_stop = false, arc_stop = false, forward_stop = false, backward_stop = false;
  for (const DiagRun& r : c.runs)
    for (const DiagRun::Stop& st : r.stops) {
      (st.cls == static_cast<signed char>(sim::MotionClass::kTurn) ? turn_stop : line_stop) = true;
      if (st.cls == static_cast<signed char>(sim::MotionClass::kTurn)) continue;
      // Curving at the stop (a radius under 25 wheel separations): an
      // arc's coast may keep its curvature.
      arc_stop = arc_stop || std::abs(st.rate_right - st.rate_left) > 0.02 * std::abs(st.rate_right + st.rate_left);
      (st.rate_left + st.rate_right < 0.0 ? backward_stop : forward_stop) = true;
    }
  const auto shown = [&](int term) {
    switch (term) {
      case kParamSlideD: return line_stop || !turn_stop;
      case kParamSlideA: return turn_stop;
      case kParamSlideArc: return arc_stop;
      case kParamSlideBack: return forward_stop && backward_stop;
      default: return true;
    }
  };
  std::vector<int> out;
  for (const int term : all)
    if (shown(term)) out.push_back(term);
  return out;
}

std::vector<int> FittedParams(sim::EffectKind effect, const std::vector<Candidate>& candidates,
                              const CampaignData& c) {
  for (const Candidate& cd : candidates)
    if (cd.effect == effect && !cd.fitted_params.empty()) return cd.fitted_params;
  return EffectParams(effect, c);
}

/// A typical size of each effect parameter (its effect's, Parameter::typical:
/// the realistic ranges of the blind benchmark; 1 where the effect gives
/// none): an effect is distinguishable from E_d, E_b on a campaign when
/// such an effect would stand 3 standard errors out.
double TypicalMagnitude(int param) {
  for (const auto& d : sim::EffectCatalogue())
    for (const int q : EffectParams(d.kind))
      if (q == param) {
        const double typical = effects::Of(d.kind).TypicalSize(ParamName(param));
        return typical > 0.0 ? typical : 1.0;
      }
  return 1.0;
}

bool IsNoiseEffect(sim::EffectKind k) { return effects::Of(k).Random(); }

void EnableNoiseEffect(sim::EffectKind k, PieceNoiseFitOptions& o) {
  switch (effects::Of(k).Describe().noise_term) {
    case effects::NoiseTerm::kCorrelated: o.correlated = true; break;
    case effects::NoiseTerm::kStandstill: o.standstill = true; break;
    case effects::NoiseTerm::kMotionFloor: o.motion_floor = true; break;
    case effects::NoiseTerm::kRunTime: o.run_time = true; break;
    case effects::NoiseTerm::kWheelNoise: o.fit_wheel_noise = true; break;
    case effects::NoiseTerm::kFirstStart: o.first_start = true; break;
    case effects::NoiseTerm::kBumps:  // its own mixture fit (FitBumps)
    case effects::NoiseTerm::kNone: break;
  }
}

effects::NoiseValues NoiseValuesOf(const NoiseParams& n) {
  effects::NoiseValues v;
  v.rho = n.rho();
  // (NoiseParams' bump fields share bump_outliers' parameter name: the
  // noise model's, not the effect's.)
  v.bumps_per_m = n.bump_rate;
  v.bump_var = n.bump_s2;
  v.stand_xy2 = n.stand_xy2;
  v.stand_th2 = n.stand_th2;
  v.floor_s2 = n.floor_s2;
  v.run_tau2 = n.run_tau2;
  v.kL2 = n.kL2;
  v.kR2 = n.kR2;
  v.first_start_th2 = n.first_start2;
  v.first_start_xy2 = n.first_start_xy2;
  v.turn_start_th2 = n.turn_start2;
  return v;
}

std::map<std::string, double> NoiseEffectParams(sim::EffectKind k, const NoiseParams& n) {
  return effects::Of(k).FromNoise(NoiseValuesOf(n));
}

effects::NoiseTerm NoiseTermOf(sim::EffectKind k) { return effects::Of(k).Describe().noise_term; }

std::string NoiseEffectName(effects::NoiseTerm term) {
  for (const effects::Effect* e : effects::All())
    if (e->Describe().noise_term == term) return std::string(e->Name());
  return "?";
}

int EffectParameterCount(sim::EffectKind k) {
  if (IsNoiseEffect(k)) return std::max(1, static_cast<int>(effects::Of(k).FromNoise({}).size()));
  // A mean effect with a random part (a variance it switches on) counts its
  // variances too.
  const int random_part =
      NoiseTermOf(k) == effects::NoiseTerm::kNone ? 0 : static_cast<int>(effects::Of(k).FromNoise({}).size());
  return static_cast<int>(EffectParams(k).size()) + random_part;
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
/// whitened footprint orthogonal to the baseline's. `at`: where the
/// footprint is taken (default the baseline, every effect zero).
bool Identify(const Shared& x, const std::vector<int>& eparams, Candidate& cd, Eigen::MatrixXd& projected,
              const ParamVector* at = nullptr) {
  // Identifiability against E_d, E_b.
  std::vector<double> eps_at;
  if (at) x.model.Residuals(*at, eps_at);
  const Eigen::MatrixXd De = at ? x.model.Jacobian(*at, eparams, eps_at) : x.model.Jacobian(x.b.p, eparams, x.b.eps);
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
  // A parameter these data do not show at all (stop_slide's turn part on
  // straight runs only) stays at 0; the others decide.
  Eigen::Index shown = 0;
  for (Eigen::Index k = 0; k < Jw_e.cols(); ++k) shown += Jw_e.col(k).norm() > 0.0 ? 1 : 0;
  for (Eigen::Index k = 0; k < Jw_e.cols(); ++k) {
    const double raw = Jw_e.col(k).norm(), perp = proj.col(k).norm();
    if (!(raw > 0.0) && shown > 0) continue;
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

/// Wheel speed over interval i of run r (the faster wheel's travel over
/// its duration) [m/s].
double IntervalSpeed(const DiagRun& r, std::size_t i) {
  const double dt = r.t[i + 1] - r.t[i];
  const double d = std::max(std::abs(r.left[i + 1] - r.left[i]), std::abs(r.right[i + 1] - r.right[i]));
  return dt > 0.0 ? d / dt : 0.0;
}

/// The pieces that end at a moving sample: neither a standstill piece nor
/// one that ends at a stop (nor an endpoint run's return error), and one
/// that ends in the motion's cruise: over the piece's last
/// kCruiseIntervals intervals the wheels turn at least kCruiseFraction of
/// the run's median wheel speed while moving. Their ground truth shows a
/// clock offset (the samples while the robot moves lag or lead by tau) but
/// never a slide at a stop, which acts only on the pieces that end there.
/// Nor do the creeps and nudges that open a motion count: a piece of a
/// few millimetres (one wheel counting every few samples) holds the
/// start's own effects (a castor kick, a start slip, a pivot on one wheel)
/// under the noise of a few millimetres of travel, and its response to a
/// clock is not v tau but saturates where the shown pose reaches back
/// before the start: on the June squares such pieces (5-6 mm, 1-4 % of a
/// leg) held 90 % of the moving samples' cost and their fit stood still
/// while an injected clock moved the legs' and circles' by its size.
constexpr int kCruiseIntervals = 3;
constexpr double kCruiseFraction = 0.5;

std::vector<char> MovingSamplePieces(const CampaignData& c) {
  std::vector<double> median(c.runs.size(), 0.0);
  for (std::size_t k = 0; k < c.runs.size(); ++k) {
    const DiagRun& r = c.runs[k];
    std::vector<double> v;
    for (std::size_t i = 0; i + 1 < r.t.size(); ++i)
      if (const double s = IntervalSpeed(r, i); s > 0.0) v.push_back(s);
    if (v.empty()) continue;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    median[k] = v[v.size() / 2];
  }
  std::vector<char> use(c.pieces.size(), 0);
  for (std::size_t j = 0; j < c.pieces.size(); ++j) {
    const Piece& p = c.pieces[j];
    if (p.type == PieceType::kStand || p.type == PieceType::kReturn || p.ends_at_standstill) continue;
    const DiagRun& r = c.runs[static_cast<std::size_t>(p.run)];
    const std::size_t n = std::min<std::size_t>(kCruiseIntervals, p.b - p.a);
    double sum = 0.0;
    for (std::size_t i = p.b - n; i < p.b; ++i) sum += IntervalSpeed(r, i);
    use[j] = n > 0 && sum / static_cast<double>(n) >= kCruiseFraction * median[static_cast<std::size_t>(p.run)] ? 1 : 0;
  }
  return use;
}

int Count(const std::vector<char>& use) { return static_cast<int>(std::count(use.begin(), use.end(), 1)); }

/// time_offset refitted (with E_d, E_b) on the moving samples alone, with
/// the noise and weights of the full fit `mf`: is it there too? The test is
/// the likelihood ratio on those samples of the refitted clock against none
/// (E_d, E_b refitted at tau = 0): a clock's cost is not quadratic in tau
/// (the pose at t - tau is interpolated between samples whose wheel rates
/// jump, FitMean), so the standard error from the slope at the refit says
/// little. Supported when the deviance, divided by the moving samples'
/// dispersion (their cost per degree of freedom, at least 1), exceeds 9
/// (chi^2_1 at 0.27 %, the two-sided level of 3 standard errors) and the
/// refit has the full fit's sign.
void CheckTimeOffset(const Shared& x, const std::vector<Eigen::Matrix3d>& We, const MeanFit& mf, Candidate& cd) {
  const std::vector<char> use = MovingSamplePieces(x.c);
  std::vector<Eigen::Matrix3d> Wm = We;
  for (std::size_t j = 0; j < Wm.size(); ++j)
    if (!use[j]) Wm[j].setZero();
  std::vector<int> joint = x.b.free;
  joint.push_back(kParamTau);
  const MeanFit mm = FitMean(x.model, x.b.p, joint, Wm, MeanFitOptions{12});
  ParamVector none = mm.p;
  none[kParamTau] = 0.0;
  const MeanFit m0 = FitMean(x.model, none, x.b.free, Wm, MeanFitOptions{12});
  Eigen::VectorXd r, r0;
  Eigen::MatrixXd J, J0;
  Whiten(Wm, mm.eps, mm.D, r, J);
  Whiten(Wm, m0.eps, m0.D, r0, J0);
  const Eigen::MatrixXd info = J.transpose() * J;
  const Eigen::Index t = info.cols() - 1;
  const Eigen::MatrixXd cov = info.ldlt().solve(Eigen::MatrixXd::Identity(info.rows(), info.cols()));
  Candidate::ClockCheck& k = cd.clock;
  k.checked = true;
  k.pieces = Count(use);
  k.value = mm.p[kParamTau];
  k.se = info(t, t) > 0.0 ? std::sqrt(std::max(0.0, cov(t, t))) : std::numeric_limits<double>::infinity();
  const double full = mf.p[kParamTau];
  int components = 0;
  for (std::size_t j = 0; j < use.size(); ++j) components += use[j] ? x.c.pieces[j].components : 0;
  const int dof = components - static_cast<int>(joint.size());
  const double dispersion = dof > 0 ? std::max(1.0, r.squaredNorm() / dof) : 1.0;
  const double deviance = std::max(0.0, r0.squaredNorm() - r.squaredNorm()) / dispersion;
  k.supported = k.pieces > 0 && dof > 0 && std::isfinite(deviance) && deviance > 9.0 && k.value * full > 0.0;
  k.text = fmt::format(
      "the clock offset on the moving samples alone (the ends of {} pieces in a motion's cruise that do not end at a "
      "stop: a slide cannot act there) is tau = {:.1f} ms (se {:.1f}; deviance {:.1f} against no clock there{}, "
      "9 at 0.27 %), on all pieces {:.1f} ms: {}",
      k.pieces, 1e3 * k.value, 1e3 * k.se, deviance,
      dispersion > 1.0 ? fmt::format(", scaled by their dispersion {:.2f}", dispersion) : std::string(), 1e3 * full,
      k.supported ? "the moving samples carry the evidence"
                  : "the moving samples do not support it, so the evidence lies at the stops (a slide or settling "
                    "there, not a clock); never named");
}

/// run_time_offset refitted on the moving samples alone (see
/// CheckTimeOffset): supported when it keeps half the full fit's tau_sd or
/// is significant there.
void CheckRunTimeOffset(const Shared& x, const std::vector<PieceBases>& bases, const NoiseParams& ne,
                        const PieceNoiseFitOptions& cf, Candidate& cd) {
  const std::vector<char> use = MovingSamplePieces(x.c);
  const NoiseParams nm = FitPieceNoise(x.b.eps, bases, x.c.pieces, use, ne, cf);
  // The same pieces without run_time_offset: its likelihood-ratio test there
  // (pieces taken one by one, the run blocks' correlation left out).
  PieceNoiseFitOptions cf0 = cf;
  cf0.run_time = false;
  const NoiseParams n0 = FitPieceNoise(x.b.eps, bases, x.c.pieces, use, ne, cf0);
  double gain = 0.0;
  for (std::size_t j = 0; j < use.size(); ++j)
    if (use[j])
      gain += PieceLogLik(&x.b.eps[3 * j], x.c.pieces[j].components, bases[j], nm) -
              PieceLogLik(&x.b.eps[3 * j], x.c.pieces[j].components, bases[j], n0);
  Candidate::ClockCheck& k = cd.clock;
  k.checked = true;
  k.pieces = Count(use);
  k.value = std::sqrt(nm.run_tau2);
  const double full = std::sqrt(ne.run_tau2);
  // Half the full fit's spread, or significant there on its own (chi^2_1 at
  // 0.1 %: 2 x 5.4 nats).
  k.supported = k.pieces > 0 && (k.value >= 0.5 * full || gain > 5.4);
  // Fitted at 0 on all pieces, the candidate has nothing the check could
  // support (NullNoiseFit credits it with nothing); "the moving samples
  // carry the evidence" read as if they did.
  if (full == 0.0) {
    k.text = fmt::format(
        "fitted at 0 on all pieces, so there is no per-run clock to check (on the moving samples alone, the ends of "
        "{} pieces that do not end at a stop: tau_sd = {:.1f} ms, {:+.1f} nats there)",
        k.pieces, 1e3 * k.value, gain);
    return;
  }
  k.text = fmt::format(
      "the per-run clock offsets on the moving samples alone (the ends of {} pieces that do not end at a stop) "
      "have tau_sd = {:.1f} ms ({:+.1f} nats there), on all pieces {:.1f} ms: {}",
      k.pieces, 1e3 * k.value, gain, 1e3 * full,
      k.supported ? "the moving samples carry the evidence"
                  : "the moving samples do not support them, so the evidence lies at the stops (a slide or "
                    "settling there, not a clock); never named");
}

/// A mean effect fitted jointly with E_d, E_b.
/// Why a slide may not show: the median speed at the stops after straight
/// or arc motions and the slide a typical d would give there.
std::string SlideSpeedNote(const CampaignData& c) {
  std::vector<double> v;
  for (const DiagRun& r : c.runs)
    for (const DiagRun::Stop& st : r.stops)
      if (st.cls != static_cast<signed char>(sim::MotionClass::kTurn))
        v.push_back(0.5 * std::abs(st.rate_left + st.rate_right));
  if (v.empty()) return {};
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  const double med = v[v.size() / 2], d = TypicalMagnitude(kParamSlideD);
  return fmt::format("; the motions end at {:.3f} m/s (median over {} stops): a slide of typical size (d = {:.3f} "
                     "s^2/m) would be {:.3f} mm there",
                     med, v.size(), d, 1e3 * d * med * med);
}

MeanFit FitMeanEffect(const Shared& x, const std::vector<int>& eparams, Candidate& cd) {
  const CampaignData& c = x.c;
  std::vector<int> joint = x.b.free;
  joint.insert(joint.end(), eparams.begin(), eparams.end());
  MeanFit mf = FitMean(x.model, x.b.p, joint, x.b.W, MeanFitOptions{12});
  // turn_scrub also changes the noise's heading in spot turns relative
  // to straight motion: its covariance bases follow the fit.
  std::vector<PieceBases> scrub_bases;
  const bool bases_follow = Has(eparams, kParamScrub);
  if (bases_follow) scrub_bases = ComputeBases(c, x.model, mf.p);
  const std::vector<PieceBases>& bases = bases_follow ? scrub_bases : x.b.bases;
  // castor_swivel's random kicks after reversals: kappa^2 of heading
  // variance there, from the fitted kappa.
  NoiseParams start = x.b.noise;
  start.swivel_rev2 = mf.p[kParamSwivel] * mf.p[kParamSwivel];
  // A mean effect's random part (a variance it switches on, such as a
  // heading kick at each run's first start) is fitted with it, in the
  // folds too.
  PieceNoiseFitOptions nf = x.b.noise_fit, fold_fit = x.fold_fit;
  EnableNoiseEffect(cd.effect, nf);
  EnableNoiseEffect(cd.effect, fold_fit);
  start = HeldWheelNoise(c, x.b, mf.eps, bases, start, nf, /*bumps=*/false);
  NoiseParams ne = FitPieceNoise(mf.eps, bases, c.pieces, {}, start, nf);
  const std::vector<Eigen::Matrix3d> We = Whiteners(bases, c.pieces, ne);
  // Parameter standard errors with the refitted noise.
  Eigen::VectorXd r2;
  Eigen::MatrixXd J2;
  Whiten(We, mf.eps, mf.D, r2, J2);
  // Columns the data do not show (Identify) stay out of the covariance.
  Eigen::MatrixXd J2s(J2.rows(), 0);
  std::vector<Eigen::Index> at(static_cast<std::size_t>(J2.cols()), -1);
  for (Eigen::Index k = 0; k < J2.cols(); ++k) {
    if (!(J2.col(k).norm() > 0.0)) continue;
    J2s.conservativeResize(Eigen::NoChange, J2s.cols() + 1);
    J2s.col(J2s.cols() - 1) = J2.col(k);
    at[static_cast<std::size_t>(k)] = J2s.cols() - 1;
  }
  const Eigen::MatrixXd cov = (J2s.transpose() * J2s).ldlt().solve(Eigen::MatrixXd::Identity(J2s.cols(), J2s.cols()));
  int shown = 0;
  for (std::size_t k = 0; k < eparams.size(); ++k) {
    const Eigen::Index a = at[x.b.free.size() + k];
    cd.params[ParamName(eparams[k])] = mf.p[eparams[k]];
    cd.param_se[ParamName(eparams[k])] = a >= 0 ? std::sqrt(std::max(0.0, cov(a, a))) : 0.0;
    shown += a >= 0 ? 1 : 0;
  }
  // Its random part's fitted values (and one parameter each where the
  // campaign shows it).
  if (NoiseTermOf(cd.effect) != effects::NoiseTerm::kNone)
    for (const auto& [name, value] : NoiseEffectParams(cd.effect, ne)) {
      cd.params[name] = value;
      shown += value > 0.0 ? 1 : 0;
    }
  cd.parameters = std::max(1, shown);
  cd.E_d = mf.p[kParamEd];
  cd.E_b = mf.p[kParamEb];
  LikelihoodRatioTest(cd, TotalLogLik(c, bases, mf.eps, ne), x.ll_base);
  const GapSummary ga = ComputeGap(c, PieceScores(mf.eps, bases, c.pieces, ne), x.options.gap);
  cd.gap_after = ga.score;
  cd.gap_by_kind = ga.by_kind;
  const CrossValidation cv = CrossValidate(
      c, bases, x.folds, mf.eps, mf.D, We, [&](const std::vector<double>& e, const std::vector<char>& use) {
        return FitPieceNoise(e, bases, c.pieces, use, ne, fold_fit);
      });
  cd.heldout_loglik_gain = cv.loglik - x.cv_ll_base;
  const double gcv = ComputeGap(c, cv.scores, x.options.gap).score;
  cd.heldout_shrink = Shrink(Gap(gcv, x.null_median), x.gap_cv_before);
  if (Has(eparams, kParamTau)) CheckTimeOffset(x, We, mf, cd);
  return mf;
}

/// A mean effect's candidate: identifiability, fit, parameter standard
/// errors (false: not identifiable, `cd` says why). stop_slide's turn part
/// on spot turns of one angle and rate is a constant extra turn, E_b's
/// footprint, unless the samples resolve the coast after the turns: fitted
/// only when it can be told from E_d, E_b. A slide's footprint is taken at
/// a typical-size slide: at d = a = 0 the coast ends at once, and only its
/// constant extra length and turn (E_d's and E_b's footprints) would show,
/// and its shape none.
bool FitMeanCandidate(const Shared& x, sim::EffectKind kind, Candidate& cd, Eigen::MatrixXd& projected, MeanFit& mf) {
  std::vector<int> eparams = EffectParams(kind, x.c);
  const bool slide = Has(EffectParams(kind), kParamSlideD);
  ParamVector slide_at = x.b.p;
  slide_at[kParamSlideD] = TypicalMagnitude(kParamSlideD);
  slide_at[kParamSlideA] = TypicalMagnitude(kParamSlideA);
  auto has = [&](int k) { return std::find(eparams.begin(), eparams.end(), k) != eparams.end(); };
  // Each part beside d (the turn part a, the shape arc and back) is kept
  // only where these data tell it from E_d, E_b on its own: a, and against
  // a given model every part, only when not even weakly absorbed (a weak
  // part would make the whole slide unidentifiable there).
  bool turn_part_dropped = false;
  for (const int part : {kParamSlideA, kParamSlideArc, kParamSlideBack}) {
    if (!slide || !has(part) || !has(kParamSlideD)) continue;
    Candidate probe;
    Eigen::MatrixXd unused;
    if (!Identify(x, {part}, probe, unused, &slide_at) || (probe.weak && (part == kParamSlideA || x.b.given))) {
      eparams.erase(std::find(eparams.begin(), eparams.end(), part));
      turn_part_dropped = turn_part_dropped || part == kParamSlideA;
    }
  }
  cd.fitted_params = eparams;
  cd.parameters = static_cast<int>(eparams.size());
  // A parameter error frees a baseline parameter itself: nothing to tell
  // it apart from.
  if (!sim::IsParameterError(kind) && !Identify(x, eparams, cd, projected, slide ? &slide_at : nullptr)) {
    if (slide) cd.note += SlideSpeedNote(x.c);
    return false;
  }
  mf = FitMeanEffect(x, eparams, cd);
  // A turn part that comes out negative beyond 2 SE (a slide against the
  // turn) is E_b's constant extra turn read through a coast the samples
  // barely catch (10 Hz, a 16 ms coast): refitted without it.
  if (slide && !turn_part_dropped && cd.params.count("a") && cd.params.at("a") < -2.0 * cd.param_se.at("a")) {
    eparams.erase(std::find(eparams.begin(), eparams.end(), kParamSlideA));
    cd.fitted_params = eparams;
    cd.params.clear();
    cd.param_se.clear();
    cd.parameters = static_cast<int>(eparams.size());
    turn_part_dropped = true;
    mf = FitMeanEffect(x, eparams, cd);
  }
  if (turn_part_dropped)
    cd.note = std::string(cd.note.empty() ? "" : cd.note + "; ") +
              "its turn part a is not fitted: a slide after spot turns of one angle and rate is a constant extra "
              "turn, which the baseline's E_b absorbs, and these samples do not resolve the coast";
  return true;
}

/// correlated_noise or bump_outliers on the baseline's residuals.
void FitNoiseEffect(const Shared& x, sim::EffectKind kind, Candidate& cd) {
  const CampaignData& c = x.c;
  // Gaussian noise effects (a variance component each); bump_outliers is
  // a mixture with its own fit.
  const bool corr = NoiseTermOf(kind) != effects::NoiseTerm::kBumps;
  cd.parameters = EffectParameterCount(kind);
  cd.E_d = x.b.p[kParamEd];
  cd.E_b = x.b.p[kParamEb];
  PieceNoiseFitOptions cf = x.b.noise_fit;
  EnableNoiseEffect(kind, cf);
  PieceNoiseFitOptions cf_fold = x.fold_fit;
  EnableNoiseEffect(kind, cf_fold);
  // A held wheel noise is re-measured with this effect's variance (baseline.hpp).
  const NoiseParams start = HeldWheelNoise(c, x.b, x.b.eps, x.b.bases, x.b.noise, cf, !corr);
  BumpFitOptions bf = BumpFitOptions::Terms(cf);
  if (x.b.repeat.measured) {
    bf.repeat_kL2 = x.b.repeat.k_L * x.b.repeat.k_L;
    bf.repeat_kR2 = x.b.repeat.k_R * x.b.repeat.k_R;
  }
  NoiseParams ne = corr ? FitPieceNoise(x.b.eps, x.b.bases, c.pieces, {}, start, cf)
                        : FitBumps(x.b.eps, x.b.bases, c.pieces, {}, start, bf);
  BumpFitOptions bf_fold = BumpFitOptions::Terms(cf_fold);
  bf_fold.start_only = true;
  // run_time_offset: its levers at the fitted tau_sd (run_block.hpp).
  std::vector<PieceBases> rescaled;
  if (NoiseTermOf(kind) == effects::NoiseTerm::kRunTime)
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
                    : FitBumps(e, bases, c.pieces, use, ne, bf_fold);
      });
  cd.heldout_loglik_gain = cv.loglik - x.cv_ll_base;
  const double gcv = ComputeGap(c, cv.scores, x.options.gap).score;
  cd.heldout_shrink = Shrink(Gap(gcv, x.null_median), x.gap_cv_before);
  if (NoiseTermOf(kind) == effects::NoiseTerm::kRunTime) CheckRunTimeOffset(x, bases, ne, cf, cd);
  else cd.footprint = CheckNoiseFootprint(c, x.b.eps, bases, ne);
  // Fitted at zero, a noise effect is the baseline: what its refit changes
  // (the other noise parameters beside it, the folds' fits) is not its own,
  // so it is credited with nothing (issue 28: standstill_motion at sigma 0
  // showed 24 % held-out shrink on the example campaign).
  if (std::string why = NullNoiseFit(sim::EffectToString(kind), cd.params); !why.empty()) {
    cd.gap_after = x.gap_score;
    cd.gap_by_kind = x.gap_by_kind;
    cd.heldout_shrink = 0.0;
    cd.heldout_loglik_gain = 0.0;
    cd.loglik_gain = 0.0;
    cd.lr_p_value = 1.0;
    cd.note = std::string(cd.note.empty() ? "" : cd.note + "; ") + why;
  }
  // With the wheel noise given (diagnose --baseline --kl --kr), bumps at
  // their rate bound are their Gaussian limit: many small travel errors,
  // rate x sigma_b^2 of variance per metre, i.e. wheel noise growing with
  // distance, more than the given k. That is a wheel_noise_error (which
  // names the wheel and the k to set), not bumps.
  const effects::NoiseValues fitted = NoiseValuesOf(ne);
  if (!corr && !cf.fit_wheel_noise && fitted.bumps_per_m >= 0.95 * kMaxBumpRatePerMetre) {
    cd.identifiable = false;
    cd.note = fmt::format("not identifiable here: indistinguishable from {}: fitted at its rate bound "
                          "({:.2g} per metre of {:.2g} mm), bumps are their Gaussian limit, wheel noise growing "
                          "with distance, more than the given k",
                          NoiseEffectName(effects::NoiseTerm::kWheelNoise), fitted.bumps_per_m,
                          1e3 * std::sqrt(fitted.bump_var));
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
    if (const std::vector<int> eparams = EffectParams(kind, c); !eparams.empty()) {
      if (!FitMeanCandidate(x, kind, cd, out.projected[ei], mean_fits[ei])) return;
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
    for (int k : out.candidates[i].fitted_params) key.push_back(k);
    out.mean_fits.emplace(std::move(key), std::move(mean_fits[i]));
  }
  return out;
}

}  // namespace umbmark::diag
