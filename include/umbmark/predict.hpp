// Public facade: closed-form pose covariance along a path (Chong & Kleeman)
// and its Monte Carlo check.
//   api::Predict(api::PredictOptions) -> api::PredictResult: `umbmark
//   predict` as one call; api::ToJson(result) is its JSON.
//   ParsePathSpec, ToWheelSegments, PredictPathCovariance;
//   sim::CompilePlan + sim::RunMonteCarlo.
#pragma once

#include "api/predict.hpp"
#include "error_models/path_covariance.hpp"
#include "error_models/path_spec.hpp"
#include "error_models/second_order.hpp"
#include "simulation/monte_carlo.hpp"
#include "simulation/monte_carlo_plan.hpp"
