// Loads a run file of either contract format, deciding by its header:
// a trajectory CSV has t_s (or t_*) and ticks_*/dist_* columns; otherwise it
// is an endpoint CSV.
#pragma once

#include <string>
#include <variant>

#include "core/runs.hpp"

namespace umbmark::io {

using RunFile = std::variant<EndpointData, TrajectoryData>;

/// Throws InputError on any fault (see the two readers).
RunFile ReadRunFile(const std::string& path);

}  // namespace umbmark::io
