// Reader for the contract's campaign manifest (TOML): a [robot] table, one or
// more [[experiment]] tables (kind = square | back_and_forth | free, with
// side_m / distance_m / file), and an optional [ground_truth] table with
// sigma_xy_m, sigma_theta_rad. Experiment file paths are relative to the
// manifest.
#pragma once

#include <string>
#include <string_view>

#include "core/runs.hpp"

namespace umbmark::io {

/// Throws InputError (file, line, column) on any fault: TOML syntax, missing
/// or unknown table/key, wrong value type, unknown kind, side_m / distance_m
/// missing, misplaced or not > 0, empty file name, negative ground-truth sigma.
/// The experiment files are not opened (simulate writes them).
Manifest ReadManifest(const std::string& path);

/// Same, from text in memory; `path` names the manifest in messages and its
/// directory is the base for the experiments' resolved_file.
Manifest ParseManifest(std::string_view text, const std::string& path);

/// True when the file looks like a manifest (ends in .toml), so commands can
/// accept either `DATA.csv --robot R.toml` or `MANIFEST.toml`.
bool IsManifestPath(const std::string& path);

/// [ground_truth] source of a manifest as its importer wrote it ("scan": the
/// lidar's registration, whose distances carry the lidar's range scale), or
/// "" when the manifest does not say. Throws InputError as ReadManifest.
std::string ReadGroundTruthSource(const std::string& path);

}  // namespace umbmark::io
