// Public facade: refined calibration (least squares on the exact commanded
// square or along trajectories; docs/refine.md).
//   RefineFromReturnErrors, RefineFromTrajectories -> RefineSummary
//   ApplyRefinedFactors, RefinedToJson, RefineReport.
#pragma once

#include "calibration/refine.hpp"
#include "umbmark/calibrate.hpp"
