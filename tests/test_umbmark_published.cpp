// Reproduces the published UMBmark results on the real OptiOdom square runs
// (data/optiodom-2020-06/published-results.csv, rows `umbmark`): calibrated
// wheelbase and diameters, and the evaluation measures before and after.
// The reference implementation uses the x-based formulas (4.20a, 4.24a),
// computes E_d with the corrected wheelbase and integrates odometry with the
// midpoint form from the first ground-truth pose. Published numbers carry six
// decimals, so agreement is asserted to 1e-6 m and 1e-5 deg.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "calibration/calibrate_job.hpp"
#include "core/angles.hpp"
#include "import/optiodom.hpp"

using namespace umbmark;

namespace {

const std::string kData = std::string(UMBMARK_SOURCE_DIR) + "/data/optiodom-2020-06/";

std::vector<std::map<std::string, std::string>> ReadPublished() {
  std::ifstream f(kData + "published-results.csv");
  REQUIRE(f.good());
  std::string line;
  std::getline(f, line);
  // The published file carries a stray carriage return inside its lines
  // ("runs\r,path_size_m"): drop every CR.
  std::erase(line, '\r');
  std::vector<std::string> header;
  {
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) header.push_back(cell);
  }
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(f, line)) {
    std::erase(line, '\r');
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::string cell;
    std::map<std::string, std::string> row;
    for (std::size_t i = 0; std::getline(ss, cell, ','); ++i) row[header.at(i)] = cell;
    rows.push_back(row);
  }
  return rows;
}

CalibrateJobResult Calibrate(const io::OptiOdomDataset& ds, Integrator integ) {
  CalibrateJobOptions o;
  o.umbmark.estimator = UmbmarkEstimator::kX;
  o.integrator = integ;
  const auto in = InputFromTrajectories(ds.runs, ds.robot, ds.experiment.side_m, integ, ds.id);
  return RunCalibrateJob(in, o);
}

}  // namespace

TEST_CASE("UMBmark reproduces the published OptiOdom results", "[umbmark][published]") {
  for (const auto& row : ReadPublished()) {
    if (row.at("method") != "umbmark") continue;
    const std::string dataset = row.at("dataset");
    SECTION(dataset) {
      const auto ds = io::ImportOptiOdom(kData + dataset);
      auto num = [&](const char* key) { return std::stod(row.at(key)); };
      REQUIRE(ds.robot.wheelbase_m == num("init_wheelbase_m"));
      REQUIRE(ds.runs.runs.size() == static_cast<std::size_t>(num("runs")));
      REQUIRE(ds.experiment.side_m == num("path_size_m"));

      const auto r = Calibrate(ds, Integrator::kMidpoint);
      const double tol_m = 1e-6, tol_deg = 1e-5;
      CHECK_THAT(r.umbmark.corrected.wheelbase_m, Catch::WithinAbs(num("cal_wheelbase_m"), tol_m));
      CHECK_THAT(r.umbmark.corrected.wheel_diameter_right_m, Catch::WithinAbs(num("cal_Dr_m"), tol_m));
      CHECK_THAT(r.umbmark.corrected.wheel_diameter_left_m, Catch::WithinAbs(num("cal_Dl_m"), tol_m));

      REQUIRE(r.evaluation);
      const auto& b = r.evaluation->before;
      const auto& a = r.evaluation->after;
      CHECK_THAT(b.max_max_position_error_m, Catch::WithinAbs(num("init_max_eps_d_m"), tol_m));
      CHECK_THAT(Rad2Deg(b.max_max_heading_error_rad), Catch::WithinAbs(num("init_max_theta_deg"), tol_deg));
      CHECK_THAT(b.max_final_position_error_m, Catch::WithinAbs(num("init_max_final_eps_d_m"), tol_m));
      CHECK_THAT(Rad2Deg(b.max_final_heading_error_rad), Catch::WithinAbs(num("init_max_final_theta_deg"), tol_deg));
      CHECK_THAT(a.max_max_position_error_m, Catch::WithinAbs(num("cal_max_eps_d_m"), tol_m));
      CHECK_THAT(Rad2Deg(a.max_max_heading_error_rad), Catch::WithinAbs(num("cal_max_theta_deg"), tol_deg));
      CHECK_THAT(a.max_final_position_error_m, Catch::WithinAbs(num("cal_max_final_eps_d_m"), tol_m));
      CHECK_THAT(Rad2Deg(a.max_final_heading_error_rad), Catch::WithinAbs(num("cal_max_final_theta_deg"), tol_deg));

      // Our default integrator is the exact arc. On these 20 Hz logs it moves
      // the calibrated parameters by well under a micrometre and the
      // evaluation measures by under 0.1 mm / 0.01 deg: the published
      // procedure is reproduced either way, and the difference is shown here.
      const auto arc = Calibrate(ds, Integrator::kArc);
      const double d_b = std::abs(arc.umbmark.corrected.wheelbase_m - r.umbmark.corrected.wheelbase_m);
      const double d_dl = std::abs(arc.umbmark.corrected.wheel_diameter_left_m - r.umbmark.corrected.wheel_diameter_left_m);
      const double d_eval = std::abs(arc.evaluation->after.max_max_position_error_m - a.max_max_position_error_m);
      const double d_head = std::abs(Rad2Deg(arc.evaluation->after.max_max_heading_error_rad - a.max_max_heading_error_rad));
      INFO("arc vs midpoint: wheelbase " << d_b << " m, D_L " << d_dl << " m, max position error " << d_eval
                                         << " m, max heading error " << d_head << " deg");
      CHECK(d_b < 1e-6);
      CHECK(d_dl < 1e-7);
      CHECK(d_eval < 1e-4);
      CHECK(d_head < 1e-2);
      // Classic E_d with the recorded instead of the corrected wheelbase
      // (contract: either is allowed) moves the diameters by < 2e-6 m here.
    }
  }
}

TEST_CASE("All four published square datasets are present", "[umbmark][published]") {
  int n = 0;
  for (const auto& row : ReadPublished()) n += row.at("method") == "umbmark";
  CHECK(n == 4);
}
