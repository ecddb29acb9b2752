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

std::string TurnScrubDesignNote(const CampaignData& campaign, bool scrub_separable, double E_b) {
  int turns = 0, arcs = 0;
  for (const Piece& p : campaign.pieces) {
    turns += p.type == PieceType::kTurn || p.type == PieceType::kReturn;
    arcs += p.type == PieceType::kArc;
  }
  if (turns == 0 || arcs > 0 || scrub_separable) return {};
  return fmt::format(
      "turn_scrub is indistinguishable from the fitted wheelbase on this design: every rotation is a spot turn, where "
      "a scrub k (heading x (1 - k)) is exactly a wheelbase of b E_b / (1 - k); the baseline's E_b = {:.5f} holds any "
      "scrub, so spot turns are predicted right but arcs would not be. To tell a scrub from a wheelbase error, add a "
      "free experiment that turns while driving (e.g. 4 figure-eight runs of about 1 m radius)",
      E_b);
}

}  // namespace umbmark::diag
