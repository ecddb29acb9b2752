// Plots of a calibration (calibrate --plot SVG and --report, lib/api): the cw/ccw
// return errors before and after correction on ONE common scale, with the
// centres of gravity and their 95% SEM ellipses and the E_max,syst circles;
// and, for trajectory input, every run's path (small multiples in file
// order, up to 48: beyond, the 48 with the largest final error after
// correction): ground truth vs odometry with the recorded and with the
// corrected parameters, the 3 largest final errors marked.
#pragma once

#include <string>

#include "calibration/calibrate_job.hpp"

namespace umbmark::api {

/// `corrected`: the parameters the "after" panels use, `which`: their name
/// in titles and legends (e.g. "UMBmark (mean)", "refined").
std::string CalibrationPlotSvg(const CalibrateInput& input, const CalibrateJobResult& result, Integrator integrator,
                               const RobotParams& corrected, const std::string& which);

}  // namespace umbmark::api
