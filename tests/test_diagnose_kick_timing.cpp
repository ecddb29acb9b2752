// castor_kick when the first encoder count lags the start of the motion
// (issue 12: "castor kick fitted right, still unexplained"). The contract's
// kick happens when the robot starts to move; with acceleration limits and
// coarse encoders the first count comes tens of ms later, so at 20 Hz the
// last sample whose counts read still often shows the kicked heading
// already. The campaign comes from a small robot written for the tests
// (tests/support/accel_robot.hpp; not lib/simulation, which starts every
// motion at full speed), at 20 Hz:
//   - 1 kHz physics, trapezoidal speed profile: 0.4 m/s^2 up to 0.3 m/s in
//     legs, 0.4 rad/s^2 up to 1 rad/s in spot turns;
//   - 500 counts per revolution on 0.1 m wheels (0.63 mm per count) with a
//     random phase per wheel and run: the first count comes up to
//     sqrt(2 x 0.63 mm / 0.4 m/s^2) = 56 ms after the start, more than one
//     20 Hz sample;
//   - legs and turns end when the counts reach the nominal target;
//   - the kick applied at the instant the robot starts a leg (+kappa forward,
//     -kappa backward), none at spot turns;
//   - wheel noise N(0, k^2 |ds|) per wheel and step, ground truth with
//     0.3 mm / 1.5 mrad noise, E_d = 1.002, E_b = 1.01 (true geometry).
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>
#include <variant>
#include <vector>

#include "diagnosis/diagnose.hpp"
#include "diagnosis/pieces.hpp"
#include "simulation/campaign_sim.hpp"
#include "support/accel_robot.hpp"

using namespace umbmark;
using namespace umbmark::diag;
using Catch::Matchers::WithinRel;

namespace {

constexpr double kKappa = testing::kAccelKappa;

DiagnoseSummary DiagnoseWith(const PieceOptions& pieces) {
  DiagnoseOptions o;
  o.null_simulations = 100;
  o.seed = 1;
  o.threads = 2;
  o.pieces = pieces;
  return Diagnose(BuildCampaign(testing::AccelManifest(), testing::AccelCampaign(12012, kKappa, 20), pieces), o);
}

double FittedKappa(const DiagnoseSummary& d) {
  for (const auto& c : d.candidates)
    if (c.effect == sim::EffectKind::kCastorKick) return c.params.at("kappa");
  return 0.0;
}

}  // namespace

TEST_CASE("castor_kick: the kick at the motion's start, before a lagging first count", "[diagnose][kick-timing]") {
  const DiagnoseSummary d = DiagnoseWith(PieceOptions{});
  INFO(d.verdict_reason);
  CHECK(d.verdict == "castor_kick");
  // 72 kicks, heading noise of a first piece about 3.5 mrad: se ~0.4 mrad.
  CHECK_THAT(FittedKappa(d), WithinRel(kKappa, 0.10));
  CHECK(d.unexplained_fraction < 0.2);
}

TEST_CASE("castor_kick: the old placement (at the first count) leaves the kick in the standstills",
          "[diagnose][kick-timing]") {
  // The same campaign with every motion starting at its first moving
  // interval: the last still sample often shows the kick, so the
  // standstill pieces hold kicks the model does not predict. The issue's
  // symptom exactly: kappa fitted right (9.76 mrad) and 32 % of the gap
  // left on held-out runs (G = 1041 > 12): `unexplained` until session 18;
  // since, castor_kick closes the larger part and is named, and the
  // remainder is reported beside it. With the start one sample earlier
  // (test above) 0.08 % is left, kappa 9.85 mrad.
  PieceOptions old;
  old.start_before_first_count = false;
  const DiagnoseSummary d = DiagnoseWith(old);
  INFO(d.verdict_reason);
  CHECK(d.verdict == "castor_kick");
  CHECK(d.remainder_significant);
  CHECK(d.unexplained_fraction > 0.2);
  CHECK_THAT(FittedKappa(d), WithinRel(kKappa, 0.10));
}
