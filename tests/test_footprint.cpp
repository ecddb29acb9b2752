// The noise effects' footprint check (diagnosis/footprint.hpp) on synthetic
// piece residuals drawn from closed-form models: independent wheel noise
// plus the ground truth's noise at each sample (what every listed noise
// effect gives: consistent), and a bounded error that depends on the wheel
// angle only, e (sin phi_b - sin phi_a) (an eccentric wheel: inconsistent).
// Monte Carlo with stated rates.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <vector>

#include "diagnosis/footprint.hpp"

using namespace umbmark::diag;

namespace {

constexpr int kMotions = 40;  // two straight pieces each: one pair at a moving sample
constexpr double kWheel2 = 4e-6, kGt2 = 1e-6;  // heading variances [rad^2]: one piece's wheel noise, one sample's ground truth

struct Synthetic {
  CampaignData c;
  std::vector<PieceBases> bases;
  NoiseParams n;
};

Synthetic Layout() {
  Synthetic s;
  for (int m = 0; m < kMotions; ++m)
    for (int k = 0; k < 2; ++k) {
      Piece p;
      p.run = m / 10;
      p.a = static_cast<std::size_t>(3 * m + k);
      p.b = p.a + 1;
      p.type = PieceType::kStraight;
      p.motion_first = k == 0;
      p.starts_from_standstill = k == 0;
      p.ends_at_standstill = k == 1;
      s.c.pieces.push_back(p);
      PieceBases b;
      b.A_L(2, 2) = 1.0;      // kL2 x 1: the wheel noise's heading variance
      b.G_theta(2, 2) = 2.0;  // the ground truth's at both ends
      s.bases.push_back(b);
    }
  s.n.kL2 = kWheel2;
  s.n.kR2 = 0.0;
  s.n.sth2 = kGt2;
  return s;
}

/// Heading residuals of every piece: wheel noise, ground truth at each
/// sample, and an eccentric error of amplitude `ecc` [rad]: the wheel's
/// phase uniform at the start and at the middle sample, back at the start's
/// at the end (legs of one length, stopped on the same count: a whole
/// number of wheel turns).
std::vector<double> Residuals(std::mt19937_64& rng, double ecc) {
  std::normal_distribution<double> wheel(0.0, std::sqrt(kWheel2)), gt(0.0, std::sqrt(kGt2));
  std::uniform_real_distribution<double> phase(0.0, 2.0 * 3.14159265358979323846);
  std::vector<double> eps;
  for (int m = 0; m < kMotions; ++m) {
    const double start = std::sin(phase(rng));
    double g0 = gt(rng), s0 = start;
    for (int k = 0; k < 2; ++k) {
      const double g1 = gt(rng), s1 = k == 0 ? std::sin(phase(rng)) : start;
      eps.insert(eps.end(), {0.0, 0.0, wheel(rng) + g1 - g0 + ecc * (s1 - s0)});
      g0 = g1;
      s0 = s1;
    }
  }
  return eps;
}

}  // namespace

TEST_CASE("footprint: independent noise is consistent, an eccentric wheel's cancelling errors are not",
          "[diagnose][footprint]") {
  const Synthetic s = Layout();
  std::mt19937_64 rng(20261126);
  int false_alarms = 0, caught = 0;
  double corr_noise = 0.0, corr_ecc = 0.0, expected = 0.0;
  constexpr int kTrials = 300;
  for (int t = 0; t < kTrials; ++t) {
    const FootprintCheck a = CheckNoiseFootprint(s.c, Residuals(rng, 0.0), s.bases, s.n);
    REQUIRE(a.checked);
    REQUIRE(a.pairs == kMotions);
    false_alarms += a.consistent ? 0 : 1;
    corr_noise += a.correlation / kTrials;
    expected = a.expected_correlation;
    // An eccentric error 3x the wheel noise's sd (DART's eccentric hubs: 5
    // mrad against about 1.5).
    const FootprintCheck b = CheckNoiseFootprint(s.c, Residuals(rng, 3.0 * std::sqrt(kWheel2)), s.bases, s.n);
    caught += b.consistent ? 0 : 1;
    corr_ecc += b.correlation / kTrials;
  }
  // The model's correlation: -sigma_gt^2 / V with V = kWheel2 + 2 kGt2 (a
  // Pearson -1/6), as a rank correlation (6/pi) asin(r/2).
  const double r0 = -kGt2 / (kWheel2 + 2.0 * kGt2);
  CHECK_THAT(expected, Catch::Matchers::WithinAbs(6.0 / 3.14159265358979323846 * std::asin(0.5 * r0), 1e-12));
  CHECK_THAT(corr_noise, Catch::Matchers::WithinAbs(expected, 0.03));
  // z < -4 one-sided: about 3e-5 per campaign under the model; allow 1 in 300.
  CHECK(false_alarms <= 1);
  // Eccentric: the two pieces' errors ecc (s_mid - s_0) and ecc (s_0 -
  // s_mid) cancel; with the ground truth at the shared sample a Pearson
  // correlation of -(kGt2 + ecc^2) / (kWheel2 + 2 kGt2 + ecc^2) = -37 / 42
  // = -0.88 (ecc^2 Var(s_mid - s_0) = 36e-6); caught in nearly every
  // campaign.
  CHECK_THAT(corr_ecc, Catch::Matchers::WithinAbs(6.0 / 3.14159265358979323846 * std::asin(-0.5 * 37.0 / 42.0), 0.05));
  CHECK(caught >= 0.9 * kTrials);
}

TEST_CASE("footprint: too few pairs at moving samples are not judged", "[diagnose][footprint]") {
  Synthetic s = Layout();
  // Every piece a whole motion (no moving boundary): nothing to check.
  for (Piece& p : s.c.pieces) p.motion_first = p.starts_from_standstill = p.ends_at_standstill = true;
  std::mt19937_64 rng(7);
  const FootprintCheck f = CheckNoiseFootprint(s.c, Residuals(rng, 0.01), s.bases, s.n);
  CHECK_FALSE(f.checked);
  CHECK(f.consistent);
  CHECK(f.pairs == 0);
}
