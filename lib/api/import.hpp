// `umbmark import` as library calls: a ROS 2 recording (rosbag2) or an
// OptiOdom dataset folder into the contract's campaign (OUTDIR/campaign.toml
// + OUTDIR/runs.csv), and the topic listing of `import rosbag2 --list`.
//   ImportRosbag2(ImportRosbag2Options) -> ImportRosbag2Result;
//   ImportOptiOdom(ImportOptiOdomOptions) -> ImportOptiOdomResult;
//   ToJson(result) is the command's --json document; ToJson(TopicListing)
//   one topic of --list's.
// Files: reads the recordings or the dataset; writes the campaign folder
// as a whole (io::WriteCampaign: staged, then renamed into place). The
// caller checks beforehand that no output is an input (output/output_set).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/robot.hpp"
#include "core/runs.hpp"
#include "import/optiodom.hpp"
#include "import/rosbag2_import.hpp"

namespace umbmark::api {

struct ImportRosbag2Options {
  /// BAG: rosbag2 folders or single .mcap/.db3 files, read in order (runs
  /// numbered across them); at least one.
  std::vector<std::string> bags;
  /// The topics, joints, experiment, time stamps, ground-truth source, ...
  /// (import/rosbag2_import.hpp; its defaults).
  io::rosbag2::Rosbag2ImportOptions import;
  /// The parameters the odometry used (--robot and the overrides).
  RobotParams robot;
  /// --out: the campaign folder (required); --force: replace a non-empty one.
  std::string out;
  bool force = false;

  /// "" when usable, else a message naming the bad field.
  std::string Check() const;
};

/// What `import rosbag2` gives; the members are the JSON's keys (experiment:
/// imported.experiment.kind; recordings, runs, ground_truth: from
/// `imported`, the runs summarised per run in the JSON).
struct ImportRosbag2Result {
  std::string manifest, runs_csv;  ///< the files written
  RobotParams robot;
  io::rosbag2::Rosbag2Import imported;
  /// The importer's warnings, then those of degenerate data
  /// (evaluation/data_warnings.hpp).
  std::vector<std::string> warnings;
};

/// Imports the recordings and writes the campaign. Throws InputError (a
/// file, with the byte or message where it went wrong), InvalidOptions.
ImportRosbag2Result ImportRosbag2(const ImportRosbag2Options& options);

nlohmann::json ToJson(const ImportRosbag2Result& result);

/// One topic of `--list --json`.
nlohmann::json ToJson(const io::rosbag2::TopicListing& topic);

struct ImportOptiOdomOptions {
  std::string dir;       ///< DIR: the dataset folder (<id>_metadata.csv + <id>_run-NN.csv)
  std::string category;  ///< --category square|circular|ivanjko|free ("" = the parent folder's name)
  std::string out;       ///< --out: the campaign folder (required)
  bool force = false;    ///< --force: replace a non-empty --out

  /// "" when usable, else a message naming the bad field.
  std::string Check() const;
};

/// What `import optiodom` gives; the members are the JSON's keys
/// (dataset: imported.id, category, robot, experiment, runs from `imported`).
struct ImportOptiOdomResult {
  std::string manifest, runs_csv;
  io::OptiOdomDataset imported;
  std::vector<std::string> warnings;  ///< degenerate data (evaluation/data_warnings.hpp)
};

ImportOptiOdomResult ImportOptiOdom(const ImportOptiOdomOptions& options);

nlohmann::json ToJson(const ImportOptiOdomResult& result);

}  // namespace umbmark::api
