// Public facade: maximum-likelihood fit of Chong & Kleeman's wheel noise
// constants k_L, k_R from return errors or trajectories (docs/noise-model.md).
//   NoiseRunsFromEndpoints / NoiseRunsFromTrajectories -> FitWheelNoise;
//   `umbmark fit-noise` as one call: api::FitNoise(api::FitNoiseOptions) ->
//   api::FitNoiseResult, api::ToJson, api::FitNoisePlotSvg,
//   api::FitNoiseReportHtml.
#pragma once

#include "api/fit_noise.hpp"
#include "api/fit_noise_report.hpp"
#include "error_models/wheel_noise_fit.hpp"
#include "error_models/wheel_noise_fit_data.hpp"
#include "umbmark/io.hpp"
