// Consumer of the installed umbmark: simulates a small campaign with a known
// true robot, writes and reads it back through io, calibrates it by UMBmark
// and checks the estimate recovers the truth; then runs the same through
// api::Calibrate (what `umbmark calibrate` does) on the written manifest
// and checks it agrees and its JSON carries the same numbers. Exit 0 on
// success.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <variant>

#include <umbmark/umbmark.hpp>

int main(int argc, char** argv) {
  using namespace umbmark;
  const std::filesystem::path dir = argc > 1 ? argv[1] : std::filesystem::temp_directory_path() / "umbmark_consumer";
  RobotParams robot;
  robot.wheelbase_m = 0.34;
  robot.wheel_diameter_left_m = 0.1;
  robot.wheel_diameter_right_m = 0.1;
  robot.ticks_per_rev = 4096;
  sim::CampaignSimOptions options;
  options.truth = {1.004, 0.99, 0.0, 0.0};  // E_d, E_b; no wheel noise
  options.seed = 3;
  options.endpoint_squares = true;
  const Manifest manifest = sim::StandardCampaignManifest(robot, 2.0, 2.0, GroundTruthNoise{0.0, 0.0});
  const sim::SimulatedCampaign campaign = sim::SimulateCampaign(manifest, options);
  const std::string manifest_path = io::WriteCampaign(campaign.manifest, campaign.data, dir.string());
  const Manifest back = io::ReadManifest(manifest_path);
  const EndpointData squares = io::ReadEndpointCsv(back.experiments[0].resolved_file);
  UmbmarkOptions calibration;
  calibration.side_m = back.experiments[0].side_m;
  const UmbmarkSummary s = CalibrateUmbmark(ReturnErrorsFromEndpoints(squares), back.robot, calibration);
  std::printf("umbmark %s: E_d = %.5f (true 1.004), E_b = %.5f (true 0.99), %zu runs\n", kVersion, s.selected.E_d,
              s.selected.E_b, squares.runs.size());
  const bool ok = std::abs(s.selected.E_d - 1.004) < 5e-4 && std::abs(s.selected.E_b - 0.99) < 5e-3;
  // The command as one call: the manifest's square experiments pooled.
  api::CalibrateOptions command;
  command.inputs = {manifest_path};
  command.no_heldout = true;
  const api::CalibrateResult r = api::Calibrate(command);
  const api::CalibrateUnitResult& unit = *r.results.at(0).result;
  const nlohmann::json j = api::ToJson(r);
  std::printf("api::Calibrate: E_d = %.5f, E_b = %.5f (JSON E_d %.5f)\n", unit.E_d, unit.E_b, j["E_d"].get<double>());
  const bool api_ok = !r.batch && std::abs(unit.E_d - 1.004) < 5e-4 && std::abs(unit.E_b - 0.99) < 5e-3 &&
                      j["E_d"].get<double>() == unit.E_d && j["parameters"]["wheelbase_m"] == unit.parameters.wheelbase_m;
  // predict as one call: a straight line of 2 m, var(theta) = (k_L^2 + k_R^2) D / b^2 (Chong & Kleeman).
  api::PredictOptions p;
  p.robot.wheelbase_m = robot.wheelbase_m;
  p.robot.diameter_left_m = robot.wheel_diameter_left_m;
  p.robot.diameter_right_m = robot.wheel_diameter_right_m;
  p.k_L = 1e-3;
  p.k_R = 2e-3;
  p.path = "line:2";
  const api::PredictResult pr = api::Predict(p);
  const double var_theta = (1e-6 + 4e-6) * 2.0 / (0.34 * 0.34);
  std::printf("api::Predict: var(theta) = %.6e (closed form %.6e)\n", pr.covariance(2, 2), var_theta);
  const bool predict_ok = std::abs(pr.covariance(2, 2) / var_theta - 1.0) < 1e-9;
  const bool all = ok && api_ok && predict_ok;
  std::printf("%s\n", all ? "consumer: OK" : "consumer: WRONG ESTIMATE");
  return all ? 0 : 1;
}
