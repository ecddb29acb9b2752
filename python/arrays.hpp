// Trajectories given as arrays (the module's `runs=`): a list of dicts of
// equal-length arrays named as the trajectory CSV's columns (docs/formats.md),
// or one dict with a `run` column, checked by the rules the CSV reader
// applies, with messages naming runs[i]['column'][k].
#pragma once

#include <string>

#include <pybind11/pybind11.h>

#include "core/runs.hpp"

namespace umbmark::python {

/// The name the data is known by in messages and results ("<runs>").
inline constexpr const char* kRunsName = "<runs>";

/// Converts and checks `runs`; throws InputError (file "<runs>") for
/// anything the CSV reader would refuse: a missing or extra-length column,
/// both ticks_* and dist_*_m, time not increasing, a non-finite number,
/// non-integer or wrapping ticks, partial ground truth, no ground truth at a
/// run's first or last sample, a run id given twice.
TrajectoryData TrajectoryFromArrays(const pybind11::handle& runs);

/// `data` as a trajectory CSV (docs/formats.md): every number in its
/// shortest round-trip form, so the command reads back exactly the arrays'
/// values; NaN ground truth as an empty cell.
std::string TrajectoryCsv(const TrajectoryData& data);

}  // namespace umbmark::python
