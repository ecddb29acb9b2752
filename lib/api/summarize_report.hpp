// The fleet page of `umbmark summarize --report FILE.html`, made to fit a
// fleet of any size in 1280 px: per quantity a histogram of the robots with
// the outliers marked and labelled by name, a table of the outlier robots
// only with the reasons, and the fleet's median and spread. Robots are named
// by their robot id (calibrate JSON `robot_id`) or their file's stem, never
// by path.
#pragma once

#include <string>
#include <vector>

#include "calibration/fleet.hpp"

namespace umbmark::api {

struct FleetPage {
  std::vector<std::string> names;   ///< per robot (input order): robot id or file stem, unique
  const std::vector<FleetRobot>* robots = nullptr;
  const FleetSummary* summary = nullptr;
  double threshold = 3.5;           ///< the outlier threshold on |robust z|
  std::size_t files = 0;            ///< calibration files read
  std::size_t outliers = 0;
  std::vector<std::string> warnings;
};

/// The page (self-contained HTML, io::HtmlReport).
std::string FleetReportHtml(const FleetPage& page);

}  // namespace umbmark::api
