// Public facade: UMBmark calibration (Borenstein & Feng) of E_d, E_b from
// square runs, and the correction of the robot's parameters.
//   CalibrateUmbmark(return errors, recorded robot, side) -> UmbmarkSummary
//   InputFromEndpoints / InputFromTrajectories + RunCalibrateJob: what
//   `umbmark calibrate` does; ApplyCorrection, CorrectionLeft/Right.
#pragma once

#include "calibration/calibrate_job.hpp"
#include "calibration/umbmark.hpp"
#include "evaluation/return_error.hpp"
#include "model/true_robot.hpp"
#include "umbmark/io.hpp"
