// Campaign design check before the baseline fit (see design_check.hpp).
#include "diagnosis/design_check.hpp"

#include <fmt/format.h>

namespace umbmark::diag {

std::string CampaignDesignProblem(const Manifest& manifest) {
  int turning = 0, straight = 0;
  for (const auto& e : manifest.experiments) {
    if (e.kind == ExperimentKind::kBackAndForth)
      ++straight;
    else
      ++turning;  // squares turn on the spot; free paths are assumed to turn
  }
  if (turning > 0) return {};
  return fmt::format(
      "the campaign's {} experiment(s) are all back_and_forth: straight motion never turns, so the wheelbase error "
      "E_b cannot be determined and the baseline fit would be arbitrary; add a square experiment (both directions) "
      "or a free experiment that turns",
      straight);
}

effects::DesignFacts DesignFactsOf(const CampaignData& campaign, double E_b) {
  effects::DesignFacts f;
  for (const Piece& p : campaign.pieces) {
    f.spot_turns += p.type == PieceType::kTurn || p.type == PieceType::kReturn;
    f.arcs += p.type == PieceType::kArc;
  }
  f.E_b = E_b;
  return f;
}

}  // namespace umbmark::diag
