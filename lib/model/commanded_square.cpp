// Exact model of the commanded UMBmark square (see commanded_square.hpp).
#include "model/commanded_square.hpp"

#include "core/angles.hpp"

namespace umbmark {

const char* SquareDirectionToString(SquareDirection d) { return d == SquareDirection::kCw ? "cw" : "ccw"; }

std::optional<SquareDirection> SquareDirectionFromString(std::string_view s) {
  if (s == "cw") return SquareDirection::kCw;
  if (s == "ccw") return SquareDirection::kCcw;
  return std::nullopt;
}

std::vector<CommandedMotion> CommandedSquare(SquareDirection direction, double side_m, double recorded_wheelbase_m,
                                             bool final_turn) {
  // Nominal wheel travel of a 90 deg spot turn: each wheel on a circle of
  // radius b/2 through pi/2; the right wheel goes forward in a left turn.
  const double arc = 0.5 * recorded_wheelbase_m * (kPi / 2.0);
  const double sign = direction == SquareDirection::kCcw ? 1.0 : -1.0;
  std::vector<CommandedMotion> motions;
  for (int corner = 0; corner < 4; ++corner) {
    motions.push_back({CommandedMotion::Kind::kLeg, side_m, side_m});
    if (corner < 3 || final_turn) motions.push_back({CommandedMotion::Kind::kSpotTurn, -sign * arc, sign * arc});
  }
  return motions;
}

Pose2 OdometryOfCommanded(const std::vector<CommandedMotion>& motions, double recorded_wheelbase_m) {
  return ExecuteCommanded(motions, recorded_wheelbase_m, 1.0, 1.0, 1.0);
}

Pose2 SquareReturnError(SquareDirection direction, double side_m, double recorded_wheelbase_m, double E_b,
                        double c_L, double c_R, bool final_turn) {
  const auto motions = CommandedSquare(direction, side_m, recorded_wheelbase_m, final_turn);
  return PredictReturnError(motions, recorded_wheelbase_m, OdometryOfCommanded(motions, recorded_wheelbase_m), E_b,
                            c_L, c_R);
}

}  // namespace umbmark
