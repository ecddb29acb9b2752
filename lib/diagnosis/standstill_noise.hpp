// The ground truth's own noise, measured where no candidate effect reaches
// it: sample-to-sample differences of the ground-truth pose inside
// standstills (every interval still by the encoders), away from the stop
// that begins them (settle_s: a clock offset, a slide, a settling or
// standstill_motion act there) and from the start that ends them (a castor
// kick may lead the first count by a sample). With white measurement noise
// of sd sigma per sample, a difference has sd sqrt(2) sigma; the sd is taken
// robustly (1.4826 x the median absolute deviation), so a nudge within a
// standstill does not inflate it.
//
// Why: fitted together with the wheel noise on the pieces, the ground
// truth's noise absorbs part of any effect the baseline leaves out (on a
// real campaign 1.64 mm / 8.4 mrad fitted against 0.54 mm / 3.3 mrad of
// standstill scatter; 13.8 mm with a 30 mm marker offset injected), and the
// gap test then finds less. The standstill scatter cannot move with an
// effect of the list. Mocap noise correlated over a few samples makes it an
// underestimate; it is the lower end of what the ground truth can be.
#pragma once

#include <string>

#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

struct StandstillNoiseOptions {
  /// Time after a stop before samples count [s] (>= 0). Default 0.5.
  double settle_s = 0.5;
  /// Samples before the next motion's first count left out (>= 0). Default 1.
  int lead_samples = 1;
  /// Fewest differences per component for a measurement (>= 3). Default 30.
  int min_differences = 30;

  std::string Check() const;
};

struct StandstillNoise {
  bool measured = false;  ///< enough differences (min_differences)
  double sigma_xy_m = 0.0, sigma_theta_rad = 0.0;
  int differences = 0;  ///< heading differences used (position: twice as many values, x and y)
  int standstills = 0;  ///< standstills that contributed
};

StandstillNoise MeasureStandstillNoise(const CampaignData& c, const StandstillNoiseOptions& options = {});

}  // namespace umbmark::diag
