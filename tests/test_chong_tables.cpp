// Reproduces Tables 1-7 of Chong & Kleeman (section 6.1): wheelbase 0.4 m,
// one circular arc (left wheel L, right wheel R), 10000 Monte Carlo runs of
// 10000 partitions, initial covariance diag(s_xy^2, s_xy^2, s_theta^2) with
// heading variances 0.0012 rad^2 ("2 deg") and 0.0076 rad^2 ("5 deg").
//
// Theory columns: our closed form (eqs. 23 and 25) must give every printed
// cell to its printed digits -- within one unit of the last printed digit
// (the paper's own arithmetic is not exact to half a unit: e.g. its Table 7
// sd x for k = 0.05, 0.1, 0.5 reads 0.761173, 1.522347, 7.611734, which
// should be exactly in ratio 1:2:10; six cells of Tables 1, 3 and 5 are off
// by 0.51-0.74 of a unit), or within 2e-6 relative for the seven-digit cells
// of Table 7. The printed values are kept as text, so a printed trailing zero
// ("3.6930e-2") counts as a digit.
//
// Simulation columns: our simulator, same set-up (10000 runs; 1000
// partitions for Tables 1-6 -- the discretisation effect, O((dtheta/P)^2),
// is below 1e-4 of a standard error -- and the paper's 10000 for Table 7,
// where the per-partition noise is large), must agree with every printed
// cell within |z| <= 4, z = (ours - paper) / (SE_ours * sqrt(1 + N_ours /
// N_paper)), SE_ours from 200 bootstrap resamples of our runs (valid for the
// non-Gaussian Table 7 too). Under the null, the chance that any of the 189
// cells exceeds 4 is about 1%.
//
// Transcription: the text extraction splits each Theory cell at a column
// boundary (e.g. "-0.38 | 3357"), sometimes repeating the character at the
// split ("1.437 | 76e-3" is 1.4376e-3, "7.8 | 326" is 7.826, but "1.28 | 319"
// is 1.28319); the values below are the readings with the number of
// significant digits of the neighbouring cells. Table 7 prints correlations
// as fractions under a "(%)" heading; they are multiplied by 100.
//
// Misprinted cells (skipped, NaN below), with the evidence:
//  * Table 5, Theory (II): sd y 0.110046, sd theta 0.109738, corr xtheta
//    12.089, corr ytheta -39.425, corr xy -3.428. sd theta is exactly
//    sqrt(0.0076 + (k_L^2 |L| + k_R^2 |R|)/B^2) = 0.088282 (the paper's own
//    simulation gives 0.088878); 0.110046, 0.109738 and -39.425 are the
//    Simulation (III) cells of the same rows, copied. sd x of the same column
//    (0.103131) matches our value.
//  * Table 6, Theory mean theta (I, II, III): 6.6391e-2. The theory mean does
//    not depend on k or P0; Tables 2, 4 and 7 print 6.637e-2, 6.63706e-2 and
//    0.0663706 for the same arc (= 4 pi - 12.5).
//  * Table 6, Theory (I) corr xtheta: -1.8571. Our -1.5712 comes from the
//    same covariance that matches all other 26 Theory cells of Table 6 to
//    the printed digit; no reading of "-1.8 | 571" gives it.
#include <catch2/catch.hpp>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/angles.hpp"
#include "error_models/path_covariance.hpp"
#include "simulation/monte_carlo.hpp"

using namespace umbmark;

namespace {

constexpr int kStats = 9;  // mean x, y, theta; sd x, y, theta; corr xth, yth, xy (%)
const std::array<const char*, kStats> kStatNames{"mean x", "mean y", "mean theta", "sd x", "sd y",
                                                 "sd theta", "corr xtheta", "corr ytheta", "corr xy"};

struct Case {
  double k_L, k_R;
  std::array<const char*, kStats> theory;  // as printed (nullptr = misprint, see the file comment)
  std::array<double, kStats> simul;
};

struct Table {
  int number;
  double L, R, var_xy, var_theta;
  std::array<Case, 3> cases;
};

// clang-format off
const std::vector<Table> kTables{
  {1, 3.0, 1.0, 0.0, 0.0, {{
    {0.001, 0.001, {"-0.38357", "-0.286535", "1.28319", "1.4376e-3", "2.4666e-3", "5.0000e-3", "-59.47", "-86.46", "41.90"},
                   {-0.383646, -0.286721, 1.28368, 1.4253e-3, 2.4172e-3, 4.9823e-3, -59.45, -86.19, 42.43}},
    {0.003, 0.002, {"-0.38357", "-0.286535", "1.28319", "3.473e-3", "6.494e-3", "0.01392", "-64.81", "-89.95", "50.38"},
                   {-0.383626, -0.286685, 1.28357, 3.4643e-3, 6.402e-3, 0.01392, -64.998, -89.875, 51.148}},
    {0.01, 0.02,   {"-0.38357", "-0.286535", "1.28319", "2.4473e-2", "3.6930e-2", "6.6144e-2", "-52.882", "-79.698", "29.783"},
                   {-0.383321, -0.28738, 1.28458, 2.4104e-2, 3.5939e-2, 6.5469e-2, -52.162, -78.803, 29.471}}}}},
  {2, 15.0, 10.0, 0.0, 0.0, {{
    {0.001, 0.001, {"-6.6322e-2", "-2.2017e-3", "6.637e-2", "1.5223e-2", "8.723e-3", "1.25e-2", "-82.348", "-9.528", "7.826"},
                   {-6.7663e-2, -2.6005e-3, 6.767e-2, 1.5192e-2, 8.704e-3, 1.2413e-2, -82.341, -9.686, 6.992}},
    {0.003, 0.002, {"-6.6322e-2", "-2.2017e-3", "6.637e-2", "3.933e-2", "2.1383e-2", "3.3072e-2", "-84.3", "-10.282", "8.6489"},
                   {-6.748e-2, -3.446e-3, 6.757e-2, 3.9251e-2, 2.1352e-2, 3.2973e-2, -84.276, -10.424, 8.045}},
    {0.01, 0.02,   {"-6.6322e-2", "-2.2017e-3", "6.637e-2", "0.235605", "0.145819", "0.185405", "-78.975", "-8.457", "6.657"},
                   {-7.092e-2, -2.249e-2, 7.137e-2, 0.23263, 0.147936, 0.183095, -78.542, -9.375, 6.015}}}}},
  {3, 3.0, 1.0, 0.0025, 0.0012, {{
    {0.001, 0.001, {"-0.38357", "-0.286535", "1.28319", "5.099e-2", "5.1794e-2", "3.5e-2", "19.025", "-25.979", "-4.937"},
                   {-0.38294, -0.287202, 1.283435, 5.2362e-2, 5.1077e-2, 3.5206e-2, 19.083, -26.72, -3.317}},
    {0.003, 0.002, {"-0.38357", "-0.286535", "1.28319", "5.1094e-2", "5.2141e-2", "3.7333e-2", "16.383", "-27.822", "-4.524"},
                   {-0.383273, -0.287167, 1.2833, 5.2508e-2, 5.1425e-2, 3.7516e-2, 15.99, -28.434, -2.715}},
    // corr xy Theory (III) reads "819" (its leading "3." is lost in the extraction).
    {0.01, 0.02,   {"-0.38357", "-0.286535", "1.28319", "5.6546e-2", "6.3564e-2", "7.4666e-2", "-12.131", "-50.717", "3.819"},
                   {-0.382952, -0.287857, 1.28434, 5.8017e-2, 6.2373e-2, 7.4344e-2, -11.71, -49.487, 5.185}}}}},
  {4, 15.0, 10.0, 0.0025, 0.0012, {{
    {0.001, 0.001, {"-6.6322e-2", "-2.2017e-3", "6.63706e-2", "5.2266e-2", "5.0807e-2", "3.6827e-2", "-8.004", "-4.809", "0.3848"},
                   {-6.7422e-2, -3.3320e-3, 6.7471e-2, 5.3774e-2, 5.0081e-2, 3.7032e-2, -7.548, -5.509, 0.2199}},
    {0.003, 0.002, {"-6.6322e-2", "-2.2017e-3", "6.63706e-2", "6.3615e-2", "5.4429e-2", "4.7893e-2", "-35.903", "-5.842", "2.0956"},
                   {-6.723e-2, -4.175e-3, 6.727e-2, 6.5274e-2, 5.3753e-2, 4.8004e-2, -35.278, -6.722, 3.1899}},
    {0.01, 0.02,   {"-6.6322e-2", "-2.2017e-3", "6.63706e-2", "0.240852", "0.15417", "0.18861", "-75.935", "-8.137", "6.159"},
                   {-7.0508e-2, -2.3202e-2, 7.117e-2, 0.238806, 0.156657, 0.186645, -75.161, -9.165, 5.8689}}}}},
  {5, 3.0, 1.0, 0.01, 0.0076, {{
    {0.001, 0.001, {"-0.38357", "-0.286535", "1.28319", "0.103082", "0.105471", "0.087321", "24.145", "-31.768", "-7.669"},
                   {-0.381971, -0.286882, 1.28306, 0.105786, 0.104072, 8.7836e-2, 24.212, -32.551, -6.159}},
    {0.003, 0.002, {"-0.38357", "-0.286535", "1.28319", "0.103131", nullptr, nullptr, nullptr, nullptr, nullptr},
                   {-0.381949, -0.286846, 1.28296, 0.105885, 0.104245, 8.8878e-2, 23.4391, -32.865, -5.954}},
    {0.01, 0.02,   {"-0.38357", "-0.286535", "1.28319", "0.105938", "0.111722", "0.10943", "11.401", "-39.767", "-4.783"},
                   {-0.381608, -0.287527, 1.28398, 0.108937, 0.110046, 0.109738, 11.444, -39.425, -3.245}}}}},
  {6, 15.0, 10.0, 0.01, 0.0076, {{
    {0.001, 0.001, {"-6.6322e-2", "-2.2017e-3", nullptr, "0.101152", "0.100546", "8.807e-2", nullptr, "-5.81", "0.0913"},
                   {-6.6998e-2, -4.0477e-3, 6.7071e-2, 0.10396, 9.9042e-2, 8.8607e-2, -1.003, -6.53, 1.9125}},
    {0.003, 0.002, {"-6.6322e-2", "-2.2017e-3", nullptr, "0.107457", "0.102424", "9.324e-2", "-10.777", "-6.039", "0.6508"},
                   {-6.678e-2, -4.887e-3, 6.6971e-2, 0.110578, 0.100984, 9.3723e-2, -10.228, -6.956, -2.2438}},
    {0.01, 0.02,   {"-6.6322e-2", "-2.2017e-3", nullptr, "0.255949", "0.176909", "0.20488", "-65.756", "-7.699", "5.0488"},
                   {-6.9807e-2, -2.3840e-2, 7.0771e-2, 0.254892, 0.179717, 0.203619, -64.149, -9.134, 5.2486}}}}},
  {7, 15.0, 10.0, 0.0, 0.0, {{
    {0.05, 0.05,   {"-6.6322e-2", "-2.2017e-3", "0.0663706", "0.761173", "0.436142", "0.625000", "-82.348", "-9.528", "7.8263"},
                   {-5.7167e-2, -0.189423, 0.0714706, 0.67708, 0.491106, 0.62063, -75.888, -11.516, 6.8023}},
    {0.1, 0.1,     {"-6.6322e-2", "-2.2017e-3", "0.0663706", "1.522347", "0.872283", "1.250000", "-82.348", "-9.528", "7.8263"},
                   {-2.795e-3, -0.556837, 0.0753706, 1.1008, 1.03646, 1.241261, -50.629, -12.235, 2.0512}},
    {0.5, 0.5,     {"-6.6322e-2", "-2.2017e-3", "0.0663706", "7.611734", "4.361422", "6.250000", "-82.348", "-9.528", "7.8263"},
                   {0.372037, -0.310966, 0.181841, 2.436149, 2.401108, 6.206303, 5.7035, 4.1792, 1.9032}}}}},
};
// clang-format on

/// Unit of the last printed digit of a value as printed ("3.6930e-2" -> 1e-6).
double LastDigitUnit(const std::string& text) {
  const std::size_t e = text.find_first_of("eE");
  const std::string mantissa = text.substr(0, e);
  const int exponent = e == std::string::npos ? 0 : std::stoi(text.substr(e + 1));
  const std::size_t dot = mantissa.find('.');
  const int decimals = dot == std::string::npos ? 0 : static_cast<int>(mantissa.size() - dot - 1);
  return std::pow(10.0, exponent - decimals);
}

std::array<double, kStats> Statistics(const std::vector<Pose2>& p, const std::vector<std::size_t>* idx,
                                      double theta_shift) {
  const std::size_t n = idx ? idx->size() : p.size();
  double m[3] = {0, 0, 0};
  for (std::size_t i = 0; i < n; ++i) {
    const Pose2& q = p[idx ? (*idx)[i] : i];
    m[0] += q.x, m[1] += q.y, m[2] += q.theta;
  }
  for (double& v : m) v /= static_cast<double>(n);
  double c[3][3] = {};
  for (std::size_t i = 0; i < n; ++i) {
    const Pose2& q = p[idx ? (*idx)[i] : i];
    const double d[3] = {q.x - m[0], q.y - m[1], q.theta - m[2]};
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) c[a][b] += d[a] * d[b];
  }
  for (auto& row : c)
    for (double& v : row) v /= static_cast<double>(n - 1);
  const double sx = std::sqrt(c[0][0]), sy = std::sqrt(c[1][1]), st = std::sqrt(c[2][2]);
  return {m[0], m[1], m[2] + theta_shift, sx, sy, st,
          100 * c[0][2] / (sx * st), 100 * c[1][2] / (sy * st), 100 * c[0][1] / (sx * sy)};
}

}  // namespace

TEST_CASE("Chong & Kleeman Tables 1-7: Theory columns to the printed digits", "[chong]") {
  int compared = 0, beyond_half_unit = 0;
  for (const Table& t : kTables) {
    for (const Case& c : t.cases) {
      PoseCovariance P0 = PoseCovariance::Zero();
      P0(0, 0) = P0(1, 1) = t.var_xy;
      P0(2, 2) = t.var_theta;
      const PathCovarianceSummary s = PredictPathCovariance({{t.L, t.R}}, 0.4, WheelNoise{c.k_L, c.k_R}, P0);
      const PoseCovariance& C = s.covariance;
      const double sx = std::sqrt(C(0, 0)), sy = std::sqrt(C(1, 1)), st = std::sqrt(C(2, 2));
      const std::array<double, kStats> ours{s.mean.x, s.mean.y, WrapAngle(s.mean.theta), sx, sy, st,
                                            100 * C(0, 2) / (sx * st), 100 * C(1, 2) / (sy * st),
                                            100 * C(0, 1) / (sx * sy)};
      for (int k = 0; k < kStats; ++k) {
        const char* text = c.theory[static_cast<std::size_t>(k)];
        if (text == nullptr) continue;  // misprint, see the file comment
        const double printed = std::stod(text);
        const double unit = LastDigitUnit(text);
        const double diff = std::abs(ours[static_cast<std::size_t>(k)] - printed);
        INFO("Table " << t.number << " k_L=" << c.k_L << " " << kStatNames[static_cast<std::size_t>(k)]
                      << ": ours " << ours[static_cast<std::size_t>(k)] << " printed " << printed);
        CHECK((diff <= 1.0 * unit || diff <= 2e-6 * std::abs(printed)));
        ++compared;
        if (diff > 0.5 * unit * (1 + 1e-9) && diff > 2e-6 * std::abs(printed)) {
          ++beyond_half_unit;
          if (std::getenv("CHONG_DUMP"))
            std::printf("beyond half a unit: Table %d k_L=%g %s ours %.9g printed %.9g (%.2f units)\n", t.number, c.k_L,
                        kStatNames[static_cast<std::size_t>(k)], ours[static_cast<std::size_t>(k)], printed, diff / unit);
        }
      }
    }
  }
  CHECK(compared == 7 * 27 - 9);
  CHECK(beyond_half_unit == 6);  // the six cells named in the file comment
}

TEST_CASE("Chong & Kleeman Tables 1-7: Simulation columns statistically (|z| <= 4)", "[chong]") {
  const double n_paper = 10000.0;
  double worst_z = 0.0;
  int excluded = 0, compared = 0;
  for (const Table& t : kTables) {
    for (std::size_t ci = 0; ci < 3; ++ci) {
      const Case& c = t.cases[ci];
      PoseCovariance P0 = PoseCovariance::Zero();
      P0(0, 0) = P0(1, 1) = t.var_xy;
      P0(2, 2) = t.var_theta;
      sim::SimulationModel m;
      m.nominal.wheelbase_m = 0.4;
      m.nominal.wheel_diameter_left_m = m.nominal.wheel_diameter_right_m = 0.1;
      m.noise = {c.k_L, c.k_R};
      m.initial_covariance = P0;
      const int partitions = t.number == 7 ? 10000 : 1000;
      const sim::SimPlan plan = sim::CompilePlan(m, {{t.L, t.R}}, partitions);
      sim::MonteCarloOptions o;
      o.runs = 10000;
      o.seed = 1000 + 10 * static_cast<std::uint64_t>(t.number) + ci;
      o.keep_runs = true;
      const sim::MonteCarloSummary mc = sim::RunMonteCarlo(plan, o);
      // Heading: continuous, shifted by the same multiple of 2 pi as the wrapped theory mean.
      const double theta_nominal = (t.R - t.L) / 0.4;
      const double shift = WrapAngle(theta_nominal) - theta_nominal;
      const auto ours = Statistics(mc.finals, nullptr, shift);

      // The exact values the paper's own model implies, for the exclusion
      // rule (see the file comment): E[theta] is exact for any noise level
      // (theta is linear in the wheel travels); the first-order sd's are
      // exact to < 0.3% for k <= 0.003 (cases I and II, Tables 1-2).
      const PathCovarianceSummary th = PredictPathCovariance({{t.L, t.R}}, 0.4, m.noise, P0);
      const double sd_th[3] = {std::sqrt(th.covariance(0, 0)), std::sqrt(th.covariance(1, 1)),
                               std::sqrt(th.covariance(2, 2))};
      std::array<bool, kStats> skip{};
      const double z_heading = (c.simul[2] - WrapAngle(th.mean.theta)) / (sd_th[2] / std::sqrt(n_paper));
      if (std::abs(z_heading) > 4.0) skip[0] = skip[1] = skip[2] = true;
      if (std::max(c.k_L, c.k_R) <= 0.003) {  // cases I and II of Tables 1-6
        for (int k = 0; k < 3; ++k) {
          const double z_sd = (c.simul[3 + k] - sd_th[k]) / (sd_th[k] / std::sqrt(2.0 * n_paper));
          if (std::abs(z_sd) > 4.0) skip[3 + k] = true;
        }
      }
      // Our heading is unbiased in every case.
      CHECK(std::abs(ours[2] - WrapAngle(th.mean.theta)) < 4.0 * sd_th[2] / std::sqrt(static_cast<double>(o.runs)));

      // Bootstrap standard errors.
      std::mt19937_64 rng(o.seed);
      std::uniform_int_distribution<std::size_t> pick(0, mc.finals.size() - 1);
      std::array<double, kStats> s1{}, s2{};
      const int B = 200;
      std::vector<std::size_t> idx(mc.finals.size());
      for (int b = 0; b < B; ++b) {
        for (auto& i : idx) i = pick(rng);
        const auto st = Statistics(mc.finals, &idx, shift);
        for (std::size_t k = 0; k < kStats; ++k) {
          s1[k] += st[k];
          s2[k] += st[k] * st[k];
        }
      }
      for (std::size_t k = 0; k < kStats; ++k) {
        if (skip[k]) {
          if (std::getenv("CHONG_DUMP")) std::printf("excluded T%d c%zu %s\n", t.number, ci + 1, kStatNames[k]);
          ++excluded;
          continue;
        }
        const double se = std::sqrt(std::max(0.0, s2[k] / B - std::pow(s1[k] / B, 2)));
        const double se_diff = se * std::sqrt(1.0 + static_cast<double>(o.runs) / n_paper);
        const double z = (ours[k] - c.simul[k]) / se_diff;
        worst_z = std::max(worst_z, std::abs(z));
        INFO("Table " << t.number << " case " << ci + 1 << " " << kStatNames[k] << ": ours " << ours[k]
                      << " paper " << c.simul[k] << " z " << z);
        CHECK(std::abs(z) <= 4.0);
        ++compared;
      }
    }
  }
  // Excluded: Table 1 (I) and Table 2 (I) mean x, y, theta (the paper's mean
  // theta is 9.8 and 10.4 standard errors above the exact E[theta]); Table 4
  // (I) and Table 6 (II) sd x (4.1 standard errors above the first-order
  // value; all eight sd x cells of cases I-II in Tables 3-6 are 2.6-2.9%
  // high, z = 3.7-4.1, while sd y is low: the paper's initial-pose sampling
  // did not have the stated variance -- its text notes the corr xy
  // discrepancy at large initial covariance).
  CHECK(excluded == 8);
  CHECK(compared == 189 - 8);
  WARN("largest |z| over the compared Simulation cells: " << worst_z);
}
