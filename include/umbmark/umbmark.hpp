// umbmark's public API in one include: calibrate, calibrate-lidar, refine, evaluate,
// fit-noise, import, plan, predict, simulate, diagnose, summarize, io. Link umbmark::umbmark (CMake:
// find_package(umbmark)) or `pkg-config --cflags --libs umbmark`.
// Only the declarations these headers name are the API; the headers under
// umbmark/detail/ they pull in are internals and may change.
#pragma once

#include "umbmark/calibrate.hpp"
#include "umbmark/calibrate_lidar.hpp"
#include "umbmark/diagnose.hpp"
#include "umbmark/evaluate.hpp"
#include "umbmark/fit_noise.hpp"
#include "umbmark/import.hpp"
#include "umbmark/io.hpp"
#include "umbmark/plan.hpp"
#include "umbmark/predict.hpp"
#include "umbmark/refine.hpp"
#include "umbmark/simulate.hpp"
#include "umbmark/summarize.hpp"
#include "umbmark/version.hpp"
