// SVG for `calibrate --plot`: CW/CCW return errors, their centres of gravity
// and the E_max,syst circle, before and (trajectory input) after correction.
#pragma once

#include <string>

#include "calibration/calibrate_job.hpp"

namespace umbmark::cli {

std::string CalibrationPlotSvg(const CalibrateInput& input, const CalibrateJobResult& result,
                               Integrator integrator);

}  // namespace umbmark::cli
