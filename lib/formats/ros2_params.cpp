// diff_drive_controller parameter files (see ros2_params.hpp).
#include "formats/ros2_params.hpp"

#include <array>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace umbmark::io {

namespace {

// A ROS node/controller name: letters, digits, underscores and slashes
// (namespaces), not starting with a digit.
void CheckController(const std::string& name) {
  bool ok = !name.empty() && !(name[0] >= '0' && name[0] <= '9');
  for (char c : name)
    ok = ok && ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '/');
  if (!ok) throw InvalidOptions(fmt::format("controller = '{}': a ROS name (letters, digits, _ and /) is needed", name));
}

std::string Header(const std::string& controller, const std::vector<std::string>& comment) {
  CheckController(controller);
  std::string out;
  for (const auto& c : comment) out += "# " + c + "\n";
  return out;
}

// A YAML double that ROS 2's parameter parser reads as a double: shortest
// round-trip digits, with ".0" added to whole numbers (rcl_yaml_param_parser
// takes "1000000" for an integer, and a list mixing both is rejected).
std::string Double(double v) {
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
  return s;
}

std::string List(const std::array<double, 6>& v) {
  return fmt::format("[{}, {}, {}, {}, {}, {}]", Double(v[0]), Double(v[1]), Double(v[2]), Double(v[3]), Double(v[4]),
                     Double(v[5]));
}

}  // namespace

std::string FormatDiffDriveCalibration(const std::string& controller, const DiffDriveMultipliers& m,
                                       const RobotParams& recorded, const std::vector<std::string>& comment) {
  std::string out = Header(controller, comment);
  out += fmt::format(
      "# The multipliers scale the parameters the runs were recorded with:\n"
      "#   wheel_separation: {}        # m (umbmark wheelbase_m)\n"
      "#   wheel_radius: {} (left), {} (right)   # m\n"
      "# Keep those in your controller configuration and add the lines below.\n"
      "{}:\n"
      "  ros__parameters:\n"
      "    wheel_separation_multiplier: {}\n"
      "    left_wheel_radius_multiplier: {}\n"
      "    right_wheel_radius_multiplier: {}\n",
      recorded.wheelbase_m, 0.5 * recorded.wheel_diameter_left_m, 0.5 * recorded.wheel_diameter_right_m, controller,
      Double(m.wheel_separation_multiplier), Double(m.left_wheel_radius_multiplier),
      Double(m.right_wheel_radius_multiplier));
  return out;
}

std::string FormatDiffDriveCovariance(const std::string& controller, const std::array<double, 6>& pose_diagonal,
                                      const std::array<double, 6>& twist_diagonal, const std::vector<std::string>& comment) {
  std::string out = Header(controller, comment);
  out += fmt::format(
      "# Order: x, y, z, roll, pitch, yaw (pose) and vx, vy, vz, wx, wy, wz (twist).\n"
      "{}:\n"
      "  ros__parameters:\n"
      "    pose_covariance_diagonal: {}\n"
      "    twist_covariance_diagonal: {}\n",
      controller, List(pose_diagonal), List(twist_diagonal));
  return out;
}

}  // namespace umbmark::io
