#include "planning/advice.hpp"

#include <algorithm>
#include <cmath>
#include <exception>
#include <variant>

namespace umbmark::planning {

CheckExperiment MakeCheckExperiment(ExperimentKind kind, double side_m, double distance_m, const std::string& label,
                                    const ExperimentData& data) {
  CheckExperiment x{kind, side_m, distance_m, label, nullptr, nullptr};
  if (const auto* t = std::get_if<TrajectoryData>(&data)) x.trajectories = t;
  else x.endpoints = &std::get<EndpointData>(data);
  return x;
}

DesignAdvice Advise(const RobotParams& robot, const std::vector<CheckExperiment>& experiments,
                    const CheckOptions& options, const std::vector<std::string>& kinds) {
  DesignAdvice a;
  try {
    a.check = CheckCampaign(robot, experiments, options);
  } catch (const std::exception& e) {  // InputError, QualityGateError, InvalidOptions: no advice, not a failure
    a.note = e.what();
    return a;
  }
  a.available = true;
  for (const Confusion& c : a.check.cannot_separate)
    if (std::find(kinds.begin(), kinds.end(), c.kind) != kinds.end()) {
      a.confusions.push_back(c);
      a.messages.push_back(ConfusionMessage(c));
    }
  for (const RecordMore& m : a.check.record_more) a.messages.push_back(RecordMoreMessage(m));
  return a;
}

DesignAdvice AdviseCalibration(const CalibrateInput& input, const RobotParams& calibrated,
                               const std::optional<WheelNoise>& noise,
                               const std::optional<GroundTruthModel>& ground_truth) {
  CheckOptions o;
  o.noise = noise;
  o.ground_truth = ground_truth;
  const RobotParams& rec = input.recorded;
  const double E_d = (calibrated.wheel_diameter_right_m / calibrated.wheel_diameter_left_m) /
                     (rec.wheel_diameter_right_m / rec.wheel_diameter_left_m);
  const double E_b = calibrated.wheelbase_m / rec.wheelbase_m;
  // A correction of exactly 0 (the recorded parameters) has nothing to determine.
  if (std::isfinite(E_d) && E_d > 0.0 && E_d != 1.0) o.correction_E_d = E_d;
  if (std::isfinite(E_b) && E_b > 0.0 && E_b != 1.0) o.correction_E_b = E_b;
  const EndpointData endpoints{input.path, input.trajectories ? std::vector<ReturnError>{} : input.errors};
  CheckExperiment x{ExperimentKind::kSquare, input.side_m, 0.0, input.label, nullptr, nullptr};
  if (input.trajectories) x.trajectories = &*input.trajectories;
  else x.endpoints = &endpoints;
  return Advise(input.recorded, {x}, o, {"parameters"});
}

}  // namespace umbmark::planning
