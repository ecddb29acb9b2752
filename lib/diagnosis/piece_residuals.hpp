// Standardised piece residuals of the baseline, for plots and reports: for
// every piece (pieces.hpp) each component of its residual eps (model.hpp:
// x along the piece's start heading, y to its left, theta) divided by its
// predicted standard deviation under the fitted baseline,
//   z_c = eps_c / sqrt(Cov(eps)_cc)        (Cov: piece_noise.hpp, PieceCovariance)
// so under the baseline each z_c is N(0, 1) and 95 % of them lie within
// +-1.96 (the predicted band). Pieces are listed in campaign order
// (experiment, run in file order, then along the run), with where each one
// starts along its run's nominal travel, so a plot can show where the runs
// leave the model.
#pragma once

#include <array>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

struct BaselineFit;

struct PieceResidual {
  int experiment = 0;  ///< 0-based
  int run = 0;         ///< index into CampaignData::runs
  std::string run_id;
  PieceType type = PieceType::kStand;
  double travel_start_m = 0.0;  ///< nominal travel along the run before the piece [m]
  double travel_m = 0.0;        ///< the piece's own nominal travel [m]
  /// Standardised residual [x, y, theta]; theta NaN when not measured
  /// (endpoint runs without heading).
  std::array<double, 3> z{};
};

/// One entry per piece of `c`, in campaign order, at the baseline `b`.
std::vector<PieceResidual> StandardisedPieceResiduals(const CampaignData& c, const BaselineFit& b);

/// JSON extension key `piece_residuals` of the diagnosis (docs/formats.md):
/// {"components": [...], "band95": 1.96, "pieces": [{experiment (1-based),
/// run, type, travel_start_m, travel_m, z: [x, y, theta]}, ...]}.
nlohmann::json PieceResidualsToJson(const std::vector<PieceResidual>& r);

}  // namespace umbmark::diag
