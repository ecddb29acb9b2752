// SVG for `calibrate --plot`: CW/CCW return errors, their centres of gravity
// and the E_max,syst circle, before and (trajectory input) after correction.
#pragma once

#include <string>

#include "calibration/calibrate_job.hpp"

namespace umbmark::cli {

/// `after` / `after_method`: the calibration the "after" panel shows (the
/// one --use selects).
std::string CalibrationPlotSvg(const CalibrateInput& input, const CalibrateJobResult& result,
                               Integrator integrator, const RobotParams& after, const std::string& after_method);

}  // namespace umbmark::cli
