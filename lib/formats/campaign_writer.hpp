// Writers for the contract's trajectory and endpoint CSV and campaign
// manifest, used by `import optiodom` and `simulate`. Numbers are written in shortest
// round-trip form, so reading back gives the same doubles.
#pragma once

#include <string>
#include <variant>
#include <vector>

#include "core/runs.hpp"

namespace umbmark::io {

/// Trajectory CSV text: run,direction,t_s,ticks_left,ticks_right (or
/// dist_left_m,dist_right_m),x_gt_m,y_gt_m,theta_gt_rad; NaN ground truth is
/// written as empty cells. `comment` lines are written first, prefixed "# "
/// (invalid UTF-8 and control characters escaped as \xNN). Throws InputError
/// (naming data.path) for any other non-finite value: no reader takes it.
std::string FormatTrajectoryCsv(const TrajectoryData& data, const std::vector<std::string>& comment = {});

/// A key of the manifest's [ground_truth] beyond the two sigmas that an
/// importer knows (`import rosbag2 --scan`: source, the lidar's pose, the
/// gyro; docs/formats.md).
struct ManifestKey {
  std::string key;
  std::variant<double, std::string> value;
};

/// Campaign manifest TOML text for `manifest` (experiment `file` entries are
/// written as given, relative to the manifest); `ground_truth_keys` go into
/// its [ground_truth] table after the sigmas.
std::string FormatManifest(const Manifest& manifest, const std::vector<std::string>& comment = {},
                           const std::vector<ManifestKey>& ground_truth_keys = {});

/// Endpoint CSV text (run,direction,ex_m,ey_m,etheta_rad).
std::string FormatEndpointCsv(const EndpointData& data, const std::vector<std::string>& comment = {});

/// A further file written into the campaign folder (e.g. truth.json).
struct ExtraFile {
  std::string name;  ///< relative to the folder
  std::string content;
};

/// Writes a campaign as the folder `dir`: `campaign.toml`, one file per
/// experiment (data[e] for manifest.experiments[e], named by its `file`) and
/// `extra_files`, all into a staging folder next to `dir` that is renamed
/// into place as a whole (an interrupted run leaves the complete old folder
/// or the complete new one). `dir` must be new or empty; with `replace` a
/// non-empty `dir` is replaced with everything in it. Returns the manifest
/// path. Throws InputError when a file cannot be written, two experiments
/// name the same file, data and experiments differ in number, or `dir` is
/// not empty.
std::string WriteCampaign(const Manifest& manifest, const std::vector<ExperimentData>& data, const std::string& dir,
                          const std::vector<std::string>& comment = {}, const std::vector<ExtraFile>& extra_files = {},
                          bool replace = false, const std::vector<ManifestKey>& ground_truth_keys = {});

}  // namespace umbmark::io
