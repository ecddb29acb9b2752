// The analysis of `plan --check` (check.hpp) for the messages of
// `calibrate` and `diagnose`: what their runs cannot tell apart (with the
// smallest addition that separates it) and how many more runs would
// determine the correction they found. One analysis, three commands: the
// sentences come from ConfusionMessage and RecordMoreMessage.
//
//   planning::DesignAdvice a = planning::AdviseCalibration(input, outputs_use.parameters);
//   for (const auto& w : a.messages) warnings.push_back(w);
//
// Never throws on data it cannot analyse (too few runs, a wheel noise that
// cannot be fitted): `available` is false and `note` says why, so a
// calibration or diagnosis never fails because of its advice.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "calibration/calibrate_job.hpp"
#include "core/robot.hpp"
#include "core/runs.hpp"
#include "error_models/wheel_noise.hpp"
#include "planning/check.hpp"

namespace umbmark::planning {

struct DesignAdvice {
  bool available = false;
  std::string note;  ///< why the analysis did not run (available false)
  CheckResult check;
  /// check.cannot_separate of the kinds asked for: what `messages` says.
  std::vector<Confusion> confusions;
  /// For a person, in this order: the confusions of the kinds asked for
  /// (ConfusionMessage), then the record_more sentences (RecordMoreMessage).
  std::vector<std::string> messages;
};

/// One experiment of a loaded campaign as the check reads it; `data` must
/// outlive the result.
CheckExperiment MakeCheckExperiment(ExperimentKind kind, double side_m, double distance_m, const std::string& label,
                                    const ExperimentData& data);

/// plan --check's analysis of `experiments`; messages for the confusions
/// whose kind is in `kinds` ("parameters", "noise", "effects") and for
/// record_more (options.correction_E_d / _E_b).
DesignAdvice Advise(const RobotParams& robot, const std::vector<CheckExperiment>& experiments,
                    const CheckOptions& options, const std::vector<std::string>& kinds);

/// calibrate: one calibration unit's square runs (trajectories, or return
/// errors) and the parameters it puts on the robot (outputs_use; E_d and
/// E_b are read against input.recorded, a correction of exactly 0 is not
/// advised on), the wheel noise when known (else fitted to the runs), the
/// ground truth's noise when known (else motion-capture values). Messages:
/// parameters the runs confuse, and the runs that would determine a
/// correction they do not.
DesignAdvice AdviseCalibration(const CalibrateInput& input, const RobotParams& calibrated,
                               const std::optional<WheelNoise>& noise = std::nullopt,
                               const std::optional<GroundTruthModel>& ground_truth = std::nullopt);

}  // namespace umbmark::planning
