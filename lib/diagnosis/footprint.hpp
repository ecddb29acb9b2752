// Footprint check of the noise effects (issue 21, "a wrong name is worse
// than `unexplained`"): every noise effect on the list adds independent
// errors to disjoint stretches of travel (wheel noise, bumps, correlated
// noise) or acts only where a motion starts or stops (motion_noise_floor,
// standstill_motion). So two stretches of one straight leg that meet at a
// sample taken while the robot moves have heading residuals that are
// independent, apart from the ground truth's noise at the shared sample
// (covariance -sigma_theta^2). A bounded error that comes and goes within
// the motion -- an eccentric or out-of-round wheel, whose travel error
// e (sin phi_b - sin phi_a) depends on the wheel angle only -- makes them
// cancel instead: a strongly negative correlation. Such a gap is not one of
// the listed noise effects, however well one of them fits its spread.
//
// Over the pairs p of adjacent straight pieces (heading residuals e_j,
// e_{j+1}, model variances V): Spearman's rank correlation r_s of the pairs
// against the model's, (6/pi) asin(r0/2) with r0 the mean of -sigma_theta^2
// / sqrt(V_j V_{j+1}); z = (atanh r_s - atanh r_s0) / sqrt(1.06 / (n - 3)).
// Inconsistent when z < -kFootprintZ and r_s < r_s0 - 0.3 (the errors
// cancel, not a wobble of independent ones).
#pragma once

#include <string>
#include <vector>

#include "diagnosis/piece_noise.hpp"
#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

/// How far below 0 the pairs' z may fall before the noise effects are
/// contradicted (one-sided; 4: about 3e-5 under the model).
inline constexpr double kFootprintZ = 4.0;

struct FootprintCheck {
  bool checked = false;     ///< enough pairs (at least 8) to judge
  bool consistent = true;   ///< z >= -kFootprintZ
  int pairs = 0;            ///< adjacent straight pieces meeting at a moving sample
  double z = 0.0;
  double correlation = 0.0;           ///< observed rank correlation of the pairs' heading residuals
  double expected_correlation = 0.0;  ///< the model's (the ground truth's noise at the shared sample)
  std::string text;                   ///< in words (empty when not checked)
};

/// The check on piece residuals `eps` (3 per piece) under the noise model
/// `n` with covariance bases `bases`.
FootprintCheck CheckNoiseFootprint(const CampaignData& c, const std::vector<double>& eps,
                                   const std::vector<PieceBases>& bases, const NoiseParams& n);

}  // namespace umbmark::diag
