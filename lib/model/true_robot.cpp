// Validation of the true robot (see true_robot.hpp).
#include "model/true_robot.hpp"

#include <fmt/format.h>

namespace umbmark {

std::string TrueRobot::Check() const {
  if (!(E_d > 0.0) || !std::isfinite(E_d)) return fmt::format("E_d = {} must be a finite number > 0", E_d);
  if (!(E_b > 0.0) || !std::isfinite(E_b)) return fmt::format("E_b = {} must be a finite number > 0", E_b);
  if (!(scale > -1.0) || !std::isfinite(scale)) return fmt::format("scale = {} must be a finite number > -1", scale);
  return {};
}

}  // namespace umbmark
