// `umbmark diagnose --hold-wheel-noise` and `--fit-wheel-noise` (docs/diagnosis.md,
// "The wheel noise from repeated runs"): the JSON says where k_L, k_R come
// from (baseline.wheel_noise_source), held k equal the repeated runs'
// scatter, fitted k come with the repeated runs' scatter beside them, and
// the two flags exclude each other (usage error, exit 2).
#include <catch2/catch.hpp>

#include <string>

#include <nlohmann/json.hpp>

#include "formats/campaign_writer.hpp"
#include "simulation/campaign_sim.hpp"
#include "support/diag_campaign.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;

TEST_CASE("umbmark diagnose --hold-wheel-noise / --fit-wheel-noise: the source of k in the JSON",
          "[diagnose][repeat_noise][cli]") {
  using testing::Q;
  const auto dir = testing::TempDir("wheel-noise-cli");
  // cw and ccw squares of 6 runs and 10 back-and-forth runs (test_repeat_noise.cpp).
  const testing::SmallCampaign s = testing::MakeSmallCampaign(7, 6, 10);
  const sim::SimulatedCampaign sc = sim::SimulateCampaign(s.manifest, s.sim);
  const std::string manifest = io::WriteCampaign(sc.manifest, sc.data, (dir / "campaign").string());
  const std::string base = "diagnose " + Q(manifest) + " --null-sims 20 --folds 3 --effects gt_offset,scale_error";

  auto held = testing::RunCli(base + " --hold-wheel-noise --json -");
  INFO(held.err);
  REQUIRE(held.status == 0);
  const auto h = nlohmann::json::parse(held.out);
  CHECK(h["baseline"]["wheel_noise_source"] == "repeats");
  REQUIRE(h["baseline"]["repeat_scatter"]["k_L"].is_number());
  CHECK(h["baseline"]["k_L"].get<double>() == Approx(h["baseline"]["repeat_scatter"]["k_L"].get<double>()).epsilon(1e-6));
  CHECK(h["baseline"]["k_R"].get<double>() == Approx(h["baseline"]["repeat_scatter"]["k_R"].get<double>()).epsilon(1e-6));
  CHECK(h["baseline"]["wheel_noise_fitted_to_pieces"]["k_L"].is_number());

  auto fitted = testing::RunCli(base + " --fit-wheel-noise --json -");
  REQUIRE(fitted.status == 0);
  const auto f = nlohmann::json::parse(fitted.out);
  CHECK(f["baseline"]["wheel_noise_source"] == "fitted");
  CHECK(f["baseline"]["repeat_scatter"]["k_L"].get<double>() ==
        Approx(h["baseline"]["repeat_scatter"]["k_L"].get<double>()).epsilon(1e-9));

  auto both = testing::RunCli(base + " --hold-wheel-noise --fit-wheel-noise");
  CHECK(both.status == 2);
  CHECK(both.err.find("wheel-noise") != std::string::npos);
}
