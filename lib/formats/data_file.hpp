// Loads a run file of either contract format, deciding by its header: a
// header with any ticks_*, dist_* or t_* (t_s) column is a trajectory CSV
// (so a file with a wrong time unit or a missing wheel column gets the
// trajectory reader's message); otherwise it is an endpoint CSV.
#pragma once

#include <string>
#include <variant>

#include "core/runs.hpp"
#include "formats/trajectory_csv.hpp"

namespace umbmark::io {

using RunFile = std::variant<EndpointData, TrajectoryData>;

/// Throws InputError on any fault (see the two readers).
RunFile ReadRunFile(const std::string& path);

/// Same, but a trajectory file is returned as a reader positioned after its
/// header, to be read run by run (memory bounded by the largest run); an
/// endpoint file (small by nature) is read whole.
using OpenedRunFile = std::variant<EndpointData, TrajectoryReader>;
OpenedRunFile OpenRunFile(const std::string& path);

}  // namespace umbmark::io
