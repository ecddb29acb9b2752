// Loads a run file of either contract format, deciding by its header: a
// header with any ticks_*, dist_* or t_* (t_s) column is a trajectory CSV
// (so a file with a wrong time unit or a missing wheel column gets the
// trajectory reader's message); otherwise it is an endpoint CSV.
#pragma once

#include <string>
#include <variant>

#include "core/runs.hpp"

namespace umbmark::io {

using RunFile = std::variant<EndpointData, TrajectoryData>;

/// Throws InputError on any fault (see the two readers).
RunFile ReadRunFile(const std::string& path);

}  // namespace umbmark::io
