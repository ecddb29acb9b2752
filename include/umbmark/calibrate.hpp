// Public API: `umbmark calibrate` as one call, and the pieces under it.
//   api::Calibrate(api::CalibrateOptions) -> api::CalibrateResult: every
//   option of the command (inputs: files or runs in memory; robot, side,
//   estimator, refine, held-out comparison, ros2 / plot / report files),
//   one CalibrateUnitResult per calibration with the JSON's keys as
//   members; api::ToJson(result) is the JSON `umbmark calibrate --json`
//   writes (api::DumpJson for its text).
// The pieces: CalibrateUmbmark(return errors, recorded robot, side) ->
// UmbmarkSummary; InputFromEndpoints / InputFromTrajectories +
// RunCalibrateJob; ApplyCorrection, CorrectionLeft/Right.
#pragma once

#include "api/calibrate.hpp"
#include "api/json.hpp"
#include "calibration/calibrate_job.hpp"
#include "calibration/umbmark.hpp"
#include "evaluation/return_error.hpp"
#include "model/true_robot.hpp"
#include "umbmark/io.hpp"
