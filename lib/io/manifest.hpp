// Reader for the contract's campaign manifest (TOML): a [robot] table, one or
// more [[experiment]] tables (kind = square | back_and_forth | free, with
// side_m / distance_m / file), and an optional [ground_truth] table with
// sigma_xy_m, sigma_theta_rad. Experiment file paths are relative to the
// manifest.
#pragma once

#include <string>

#include "core/runs.hpp"

namespace umbmark::io {

/// Throws InputError (file, line, column) on any fault.
Manifest ReadManifest(const std::string& path);

/// True when the file looks like a manifest (ends in .toml), so commands can
/// accept either `DATA.csv --robot R.toml` or `MANIFEST.toml`.
bool IsManifestPath(const std::string& path);

}  // namespace umbmark::io
