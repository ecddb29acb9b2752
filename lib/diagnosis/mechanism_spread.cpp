#include "diagnosis/mechanism_spread.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "core/angles.hpp"
#include "diagnosis/candidates.hpp"
#include "diagnosis/piece_noise.hpp"
#include "effects/registry.hpp"

namespace umbmark::diag {

namespace {

/// Named by the verdict's filters (diagnose.cpp NameEffects), before
/// MarkSpreads.
bool PassesFilters(const ExplanationStep& s) {
  return s.unphysical.empty() && !s.negligible && !s.not_decisive && s.outside_range.empty();
}

/// The share of noise term `term` that lies on pieces within the named
/// mechanisms' reach: where their mean moves (`moved - still`), or their
/// own random parts (`own`: their noise terms) add, at least the term's
/// own sd, in the component (position or heading) the term widens most
/// there. The larger of two shares: of the variance it adds (each piece's
/// relative to the piece's variance without it) and of its evidence (each
/// piece's log-likelihood at the explained noise minus without the term,
/// where positive). A Gaussian term earns where it adds; a mixture of rare
/// bumps adds on every straight and earns on the few pieces with a large
/// residual (a swivel castor's first starts).
double ShareWithinReach(const CampaignData& c, const Explanation& ex, const std::vector<double>& eps,
                        effects::NoiseTerm term, const std::vector<effects::NoiseTerm>& own,
                        const std::vector<Pose2>& moved, const std::vector<Pose2>& still) {
  const NoiseParams without = WithoutTerm(ex.noise, term);
  double all = 0.0, reach = 0.0, all_added = 0.0, reach_added = 0.0;
  for (std::size_t j = 0; j < c.pieces.size(); ++j) {
    if (c.pieces[j].components != 3) continue;
    const PieceBases& B = ex.bases[j];
    const Eigen::Matrix3d A = TotalCovariance(B, ex.noise), B0 = TotalCovariance(B, without);
    const double vp0 = B0(0, 0) + B0(1, 1), vh0 = B0(2, 2);
    const double dvp = std::abs(A(0, 0) + A(1, 1) - vp0), dvh = std::abs(A(2, 2) - vh0);
    if (!(dvp > 0.0 || dvh > 0.0)) continue;
    const double gain = PieceLogLik(&eps[3 * j], 3, B, ex.noise) - PieceLogLik(&eps[3 * j], 3, B, without);
    double rp = 0.0, rh = 0.0;  // the mechanisms' own random parts' variance here
    for (effects::NoiseTerm t : own) {
      const Eigen::Matrix3d M = A - TotalCovariance(B, WithoutTerm(ex.noise, t));
      rp += std::max(M(0, 0) + M(1, 1), 0.0);
      rh += std::max(M(2, 2), 0.0);
    }
    const double wp = dvp / std::max(vp0, 1e-300), wh = dvh / std::max(vh0, 1e-300);
    const bool position = wp >= wh;
    const double dp = std::hypot(moved[j].x - still[j].x, moved[j].y - still[j].y);
    const double dh = std::abs(WrapAngle(moved[j].theta - still[j].theta));
    const bool within = position ? std::max(dp, std::sqrt(rp)) >= std::sqrt(dvp)
                                 : std::max(dh, std::sqrt(rh)) >= std::sqrt(dvh);
    const double added = std::max(wp, wh);
    all_added += added;
    if (within) reach_added += added;
    if (!(gain > 0.0)) continue;
    all += gain;
    if (within) reach += gain;
  }
  return std::max(all > 0.0 ? reach / all : 0.0, all_added > 0.0 ? reach_added / all_added : 0.0);
}

}  // namespace

void MarkSpreads(const CampaignData& c, const MeanModel& model, const BaselineFit& b, Explanation& ex) {
  if (ex.bases.size() != c.pieces.size()) return;
  std::vector<std::string> mechanisms;
  std::vector<effects::NoiseTerm> own;  // the mechanisms' own random parts
  ParamVector without = ex.p;
  for (const ExplanationStep& s : ex.steps) {
    if (!PassesFilters(s) || effects::Of(s.effect).Class() != effects::EffectClass::kMechanism) continue;
    mechanisms.push_back(sim::EffectToString(s.effect));
    for (int k : EffectParams(s.effect)) without[k] = b.p[k];
    if (NoiseTermOf(s.effect) != effects::NoiseTerm::kNone) own.push_back(NoiseTermOf(s.effect));
  }
  if (mechanisms.empty()) return;
  const std::vector<Pose2> moved = model.PredictedPieceMotion(ex.p), still = model.PredictedPieceMotion(without);
  if (moved.size() != c.pieces.size() || still.size() != c.pieces.size()) return;
  std::vector<double> eps;
  model.Residuals(ex.p, eps);
  if (eps.size() != 3 * c.pieces.size()) return;
  // The larger part (0.5, the verdict's level everywhere) of it within
  // the mechanisms' reach: a scatter no larger than the mean it
  // varies about, or than the mechanism's own scatter, where it lies
  // (docs/diagnosis.md, "A noise effect within the mechanisms' reach").
  for (ExplanationStep& s : ex.steps)
    if (PassesFilters(s) && effects::Of(s.effect).PureNoise() &&
        ShareWithinReach(c, ex, eps, NoiseTermOf(s.effect), own, moved, still) >= 0.5)
      s.spread_of_named = fmt::format("{}", fmt::join(mechanisms, " + "));
}

}  // namespace umbmark::diag
