// `umbmark summarize` as a library call: a fleet of robots from their
// `calibrate` JSON outputs (a batch output's `results` count one robot
// each): one row per robot, the fleet's median and robust spread of each
// quantity, and the robots that stand out (robust z-score,
// calibration/fleet.hpp) with the reasons in words.
//   Summarize(SummarizeOptions) -> SummarizeResult; ToJson(result) is the
//   command's --json document, SummarizeCsv its --csv, FleetReportHtml
//   (summarize_report.hpp) its --report.
// Files: reads the calibration JSON files; writes nothing.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "calibration/fleet.hpp"

namespace umbmark::api {

struct SummarizeOptions {
  /// CAL: calibrate JSON outputs (at least one); a file given twice (the
  /// same device and inode) is counted once, with a warning.
  std::vector<std::string> inputs;
  /// --threshold and the smallest relative spread (calibration/fleet.hpp;
  /// its defaults: 3.5 and 1e-4).
  FleetOptions fleet;

  /// "" when usable, else a message naming the bad field.
  std::string Check() const;
};

/// One robot of the fleet: the JSON's "robots" entry (with its row of
/// result.fleet.robots: robust_z, outlier, outlier_reasons).
struct SummarizeRobot {
  FleetRobot fleet;            ///< file ("path" or "path#k" in a batch output) and the quantities
  std::string robot_id;        ///< calibrate JSON `robot_id`, when it has one
  std::string robot;           ///< robot_id or the file's stem (unique over the fleet)
  nlohmann::json parameters;   ///< the calibrated parameters as the file gives them
  std::string parameters_from; ///< "refined" or "umbmark"
};

/// What `summarize` gives; the members are the JSON's keys ("fleet":
/// fleet.fleet; each robot's z-scores and reasons: fleet.robots).
struct SummarizeResult {
  std::vector<SummarizeRobot> robots;
  FleetSummary fleet;
  double threshold = 0.0;
  std::size_t outliers = 0;
  std::vector<std::string> warnings;
  std::size_t files = 0;  ///< calibration files given (not in the JSON)
};

/// Reads and summarises the fleet. Throws InputError naming the file
/// (not a calibrate output, impossible parameters), InvalidOptions.
SummarizeResult Summarize(const SummarizeOptions& options);

nlohmann::json ToJson(const SummarizeResult& result);

/// --csv: one row per robot.
std::string SummarizeCsv(const SummarizeResult& result);

}  // namespace umbmark::api
