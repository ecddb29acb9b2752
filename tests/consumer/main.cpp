// Consumer of the installed umbmark: simulates a small campaign with a known
// true robot, writes and reads it back through io, calibrates it by UMBmark
// and checks the estimate recovers the truth. Exit 0 on success.
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
  std::printf("%s\n", ok ? "consumer: OK" : "consumer: WRONG ESTIMATE");
  return ok ? 0 : 1;
}
