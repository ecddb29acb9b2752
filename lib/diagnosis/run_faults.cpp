// Faults of single runs: per-run statistics, the robust outlier test, and the
// campaign without the faulty runs (run_faults.hpp).
#include "diagnosis/run_faults.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "simulation/rng.hpp"
#include "stats/distributions.hpp"

namespace umbmark::diag {

std::string RunFaultOptions::Check() const {
  if (!(alpha > 0.0 && alpha < 0.5)) return fmt::format("alpha = {} must be in (0, 0.5)", alpha);
  if (min_runs < 4) return fmt::format("min_runs = {} must be >= 4", min_runs);
  if (simulations < 200) return fmt::format("simulations = {} must be >= 200", simulations);
  if (!(clock_step_s > 0.0)) return fmt::format("clock_step_s = {} must be > 0", clock_step_s);
  if (!(clock_range_s >= 2.0 * clock_step_s))
    return fmt::format("clock_range_s = {} must be >= 2 clock_step_s", clock_range_s);
  if (!(min_shift_m >= 0.0)) return fmt::format("min_shift_m = {} must be >= 0", min_shift_m);
  if (!(min_scatter_ratio >= 1.0)) return fmt::format("min_scatter_ratio = {} must be >= 1", min_scatter_ratio);
  return {};
}

namespace {

/// 1.4826 MAD is the standard deviation of normal data.
constexpr double kMadToSd = 1.482602218505602;
/// Statistics tested per run: tau, dx, dy, scatter, event (the Bonferroni
/// factor).
constexpr int kStatistics = 5;
/// The smallest tail probability an event's normal score is taken from
/// (a chi^2 beyond about 1400 underflows; the score is then 37 sd).
constexpr double kMinEventTail = 1e-300;

double Median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m), v.end());
  const double hi = v[m];
  if (v.size() % 2 == 1) return hi;
  return 0.5 * (hi + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(m)));
}

/// Whitened residuals of piece j (zeros for components it lacks).
Eigen::Vector3d Whitened(const BaselineFit& base, const std::vector<double>& eps, std::size_t j) {
  return base.W[j] * Eigen::Vector3d(eps[3 * j], eps[3 * j + 1], eps[3 * j + 2]);
}

/// Each run's median wheel speed over its moving intervals [m/s].
std::vector<double> RunSpeeds(const CampaignData& c) {
  std::vector<double> out(c.runs.size(), 0.0);
  for (std::size_t r = 0; r < c.runs.size(); ++r) {
    const DiagRun& run = c.runs[r];
    if (run.endpoint) continue;
    std::vector<double> v;
    for (std::size_t i = 0; i + 1 < run.t.size() && i < run.interval_class.size(); ++i) {
      const double dt = run.t[i + 1] - run.t[i];
      if (run.interval_class[i] < 0 || !(dt > 0.0)) continue;
      v.push_back(0.5 * (std::abs(run.left[i + 1] - run.left[i]) + std::abs(run.right[i + 1] - run.right[i])) / dt);
    }
    out[r] = Median(std::move(v));
  }
  return out;
}

/// Each run's own clock offset: chi^2 of its pieces over a grid of tau
/// (E_d, E_b and the noise held at the baseline's), the minimum refined by
/// a parabola through its neighbours (se from the curvature: chi^2 =
/// -2 log L). A minimum at the grid's edge is kept at the edge.
std::vector<RunStatistic> ClockProfiles(const CampaignData& c, const MeanModel& model, const BaselineFit& base,
                                        const RunFaultOptions& o) {
  const std::size_t runs = c.runs.size();
  const int half = static_cast<int>(std::floor(o.clock_range_s / o.clock_step_s + 1e-9));
  const int steps = 2 * half + 1;
  std::vector<std::vector<double>> chi2(runs, std::vector<double>(static_cast<std::size_t>(steps), 0.0));
  std::vector<double> eps;
  for (int k = 0; k < steps; ++k) {
    ParamVector p = base.p;
    p[kParamTau] += (k - half) * o.clock_step_s;
    if (k == half) {
      eps = base.eps;
    } else {
      model.Residuals(p, eps);
    }
    for (std::size_t j = 0; j < c.pieces.size(); ++j)
      chi2[static_cast<std::size_t>(c.pieces[j].run)][static_cast<std::size_t>(k)] += Whitened(base, eps, j).squaredNorm();
  }
  std::vector<RunStatistic> out(runs);
  for (std::size_t r = 0; r < runs; ++r) {
    const std::vector<double>& f = chi2[r];
    const auto lo = std::min_element(f.begin(), f.end());
    const double spread = *std::max_element(f.begin(), f.end()) - *lo;
    if (c.runs[r].endpoint || !std::isfinite(spread) || spread < 1e-6) continue;
    const int k = static_cast<int>(lo - f.begin());
    RunStatistic& s = out[r];
    if (k == 0 || k == steps - 1) {
      s.value = base.p[kParamTau] + (k - half) * o.clock_step_s;
      s.se = o.clock_step_s;
      s.informative = true;
      continue;
    }
    const double fm = f[static_cast<std::size_t>(k - 1)], f0 = f[static_cast<std::size_t>(k)],
                 fp = f[static_cast<std::size_t>(k + 1)];
    const double curv = (fm - 2.0 * f0 + fp) / (o.clock_step_s * o.clock_step_s);
    if (!(curv > 0.0)) continue;
    const double shift = 0.5 * o.clock_step_s * (fm - fp) / (fm - 2.0 * f0 + fp);
    s.value = base.p[kParamTau] + (k - half) * o.clock_step_s + shift;
    s.se = std::sqrt(2.0 / curv);
    s.informative = std::isfinite(s.value) && s.se < o.clock_range_s;
  }
  return out;
}

/// Each run's own marker offset (dx, dy) by weighted least squares on its
/// pieces, linear about the baseline.
void MarkerFits(const CampaignData& c, const MeanModel& model, const BaselineFit& base, RunStatistics& out) {
  const std::size_t runs = c.runs.size();
  out.dx.assign(runs, {});
  out.dy.assign(runs, {});
  const Eigen::MatrixXd D = model.Jacobian(base.p, {kParamDx, kParamDy}, base.eps);
  std::vector<Eigen::Matrix2d> A(runs, Eigen::Matrix2d::Zero());
  std::vector<Eigen::Vector2d> b(runs, Eigen::Vector2d::Zero());
  for (std::size_t j = 0; j < c.pieces.size(); ++j) {
    const std::size_t r = static_cast<std::size_t>(c.pieces[j].run);
    const Eigen::Matrix<double, 3, 2> Dj = base.W[j] * D.middleRows(static_cast<Eigen::Index>(3 * j), 3);
    A[r] += Dj.transpose() * Dj;
    b[r] += Dj.transpose() * Whitened(base, base.eps, j);
  }
  for (std::size_t r = 0; r < runs; ++r) {
    // A run that hardly turns cannot place its marker: a condition number
    // beyond 1e8 or a standard error beyond 0.3 m is no information.
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(A[r]);
    if (!(es.eigenvalues()[0] > 1e-8 * es.eigenvalues()[1]) || !(es.eigenvalues()[0] > 0.0)) continue;
    const Eigen::Matrix2d cov = A[r].inverse();
    const Eigen::Vector2d theta = Eigen::Vector2d(base.p[kParamDx], base.p[kParamDy]) - cov * b[r];
    const double sx = std::sqrt(cov(0, 0)), sy = std::sqrt(cov(1, 1));
    if (!(sx < 0.3 && sy < 0.3)) continue;
    out.dx[r] = {theta[0], sx, true};
    out.dy[r] = {theta[1], sy, true};
  }
}

/// Each run's log mean chi^2 per residual component under the baseline.
std::vector<RunStatistic> Scatter(const CampaignData& c, const BaselineFit& base) {
  std::vector<double> chi2(c.runs.size(), 0.0), dof(c.runs.size(), 0.0);
  for (std::size_t j = 0; j < c.pieces.size(); ++j) {
    const std::size_t r = static_cast<std::size_t>(c.pieces[j].run);
    chi2[r] += Whitened(base, base.eps, j).squaredNorm();
    dof[r] += c.pieces[j].components;
  }
  std::vector<RunStatistic> out(c.runs.size());
  for (std::size_t r = 0; r < c.runs.size(); ++r)
    if (dof[r] > 0.0 && chi2[r] > 0.0 && std::isfinite(chi2[r]))
      out[r] = {std::log(chi2[r] / dof[r]), std::sqrt(2.0 / dof[r]), true};
  return out;
}

/// Each run's largest single piece: its chi^2 under the baseline (the
/// piece's components' degrees of freedom) as the normal score of the
/// maximum over the run's n pieces, u = -Phi^-1(P(max > chi^2)) with
/// P(max > x) = 1 - (1 - Q(x))^n: N(0, 1) for every run when the model
/// holds, whatever the run's length.
std::vector<RunStatistic> Events(const CampaignData& c, const BaselineFit& base, std::vector<int>& piece) {
  const std::size_t runs = c.runs.size();
  std::vector<double> worst_tail(runs, 1.0);
  std::vector<int> count(runs, 0);
  piece.assign(runs, -1);
  for (std::size_t j = 0; j < c.pieces.size(); ++j) {
    const std::size_t r = static_cast<std::size_t>(c.pieces[j].run);
    const int k = c.pieces[j].components;
    if (k <= 0) continue;
    count[r] += 1;
    const double q = ChiSquareSurvival(Whitened(base, base.eps, j).squaredNorm(), k);
    if (std::isfinite(q) && q < worst_tail[r]) {
      worst_tail[r] = q;
      piece[r] = static_cast<int>(j);
    }
  }
  std::vector<RunStatistic> out(runs);
  for (std::size_t r = 0; r < runs; ++r) {
    if (piece[r] < 0 || count[r] < 2) continue;
    const double p_max = -std::expm1(count[r] * std::log1p(-worst_tail[r]));
    const double u = -NormalQuantile(std::clamp(p_max, kMinEventTail, 1.0 - 1e-16));
    if (std::isfinite(u)) out[r] = {u, 1.0, true};
  }
  return out;
}

/// The informative runs of one statistic: values, standard errors, their
/// experiments (the groups each run is compared within) and run indices.
struct Tested {
  std::vector<double> x, se;
  std::vector<int> group;
  std::vector<std::size_t> run;
};
Tested Collect(const CampaignData& c, const std::vector<RunStatistic>& s) {
  Tested t;
  for (std::size_t r = 0; r < s.size(); ++r)
    if (s[r].informative) {
      t.x.push_back(s[r].value);
      t.se.push_back(s[r].se);
      t.group.push_back(c.runs[r].experiment);
      t.run.push_back(r);
    }
  return t;
}

/// z of every informative run of one statistic (NaN elsewhere), and the
/// median of its experiment.
std::vector<double> Deviations(const Tested& t, std::size_t runs) {
  std::vector<double> out(runs, std::numeric_limits<double>::quiet_NaN());
  const std::vector<double> z = RobustDeviations(t.x, t.se, t.group);
  for (std::size_t i = 0; i < z.size(); ++i) out[t.run[i]] = z[i];
  return out;
}

/// The median of statistic s over the informative runs of each experiment.
std::vector<double> ExperimentMedians(const CampaignData& c, const std::vector<RunStatistic>& s) {
  std::vector<std::vector<double>> v(c.experiments.size());
  for (std::size_t r = 0; r < s.size(); ++r)
    if (s[r].informative) v[static_cast<std::size_t>(c.runs[r].experiment)].push_back(s[r].value);
  std::vector<double> out;
  for (auto& x : v) out.push_back(Median(std::move(x)));
  return out;
}

/// One flagged statistic of a run.
struct Flag {
  std::string statistic, text;
  double excess = 0.0;  ///< |z| / threshold
  double z = 0.0, threshold = 0.0;
};

}  // namespace

std::vector<double> RobustDeviations(const std::vector<double>& x, const std::vector<double>& se,
                                     const std::vector<int>& group) {
  const std::size_t n = x.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (se.size() != n || (!group.empty() && group.size() != n)) return {};
  std::map<int, std::vector<std::size_t>> members;
  for (std::size_t i = 0; i < n; ++i) members[group.empty() ? 0 : group[i]].push_back(i);
  std::vector<double> centred(n, nan), pooled, se2;
  for (const auto& [g, idx] : members) {
    if (idx.size() < 3) continue;  // too few to tell a run from its group
    std::vector<double> v;
    for (std::size_t i : idx) v.push_back(x[i]);
    const double med = Median(v);
    for (std::size_t i : idx) {
      centred[i] = x[i] - med;
      pooled.push_back(std::abs(centred[i]));
      se2.push_back(se[i] * se[i]);
    }
  }
  if (pooled.size() < 3) return std::vector<double>(n, nan);
  const double s_tot = kMadToSd * Median(pooled);
  const double sb2 = std::max(0.0, s_tot * s_tot - Median(se2));
  std::vector<double> z(n, nan);
  for (std::size_t i = 0; i < n; ++i) {
    if (std::isnan(centred[i])) continue;
    const double sd = std::sqrt(sb2 + se[i] * se[i]);
    z[i] = sd > 0.0 ? centred[i] / sd
                    : (centred[i] == 0.0 ? 0.0 : std::copysign(std::numeric_limits<double>::infinity(), centred[i]));
  }
  return z;
}

std::vector<double> RobustDeviations(const std::vector<double>& x, const std::vector<double>& se) {
  if (x.size() < 3) return {};
  return RobustDeviations(x, se, {});
}

double MaxDeviationThreshold(const std::vector<int>& group, double rate, int simulations, std::uint64_t seed) {
  const int n = static_cast<int>(group.size());
  std::map<int, int> sizes;
  for (int g : group) sizes[g] += 1;
  int tested = 0;
  for (const auto& [g, k] : sizes) tested += k >= 3 ? k : 0;
  if (tested < 3 || simulations < 1) return std::numeric_limits<double>::infinity();
  std::vector<double> maxima(static_cast<std::size_t>(simulations));
  std::vector<double> x(static_cast<std::size_t>(n)), zero(static_cast<std::size_t>(n), 0.0);
  for (int s = 0; s < simulations; ++s) {
    sim::Xoshiro256pp gen(sim::StreamSeed(seed, static_cast<std::uint64_t>(s), 311));
    for (int i = 0; i < n; i += 2) {
      double z0 = 0.0, z1 = 0.0;
      const std::uint64_t a = gen.Next(), b = gen.Next();
      sim::NormalPairFromBits(a, b, z0, z1);
      x[static_cast<std::size_t>(i)] = z0;
      if (i + 1 < n) x[static_cast<std::size_t>(i + 1)] = z1;
    }
    double m = 0.0;
    for (double z : RobustDeviations(x, zero, group))
      if (std::isfinite(z)) m = std::max(m, std::abs(z));
    maxima[static_cast<std::size_t>(s)] = m;
  }
  std::sort(maxima.begin(), maxima.end());
  const double q = std::clamp(1.0 - rate, 0.0, 1.0) * (simulations - 1);
  const std::size_t k = static_cast<std::size_t>(std::floor(q));
  const double frac = q - static_cast<double>(k);
  return k + 1 < maxima.size() ? maxima[k] + frac * (maxima[k + 1] - maxima[k]) : maxima.back();
}

double MaxDeviationThreshold(int n, double rate, int simulations, std::uint64_t seed) {
  if (n < 3) return std::numeric_limits<double>::infinity();
  return MaxDeviationThreshold(std::vector<int>(static_cast<std::size_t>(n), 0), rate, simulations, seed);
}

RunStatistics ComputeRunStatistics(const CampaignData& c, const MeanModel& model, const BaselineFit& base,
                                   const RunFaultOptions& options) {
  RunStatistics out;
  out.speed = RunSpeeds(c);
  out.tau = ClockProfiles(c, model, base, options);
  MarkerFits(c, model, base, out);
  out.scatter = Scatter(c, base);
  out.event = Events(c, base, out.event_piece);
  return out;
}

namespace {

/// The event flag of run r (its largest piece), with its practical floor:
/// the piece moved by min_shift_m, or turned by as much at a wheel.
std::optional<Flag> EventFlag(std::size_t r, const CampaignData& c, const BaselineFit& base, const RunStatistics& st,
                              double z, double thr, double median, const RunFaultOptions& o) {
  const int j = st.event_piece[r];
  if (j < 0) return std::nullopt;
  const std::size_t jj = static_cast<std::size_t>(j);
  const Piece& p = c.pieces[jj];
  const double ex = base.eps[3 * jj], ey = base.eps[3 * jj + 1], eth = p.components == 3 ? base.eps[3 * jj + 2] : 0.0;
  const double shift = std::max(std::hypot(ex, ey), std::abs(eth) * 0.5 * c.robot.wheelbase_m);
  if (shift < o.min_shift_m) return std::nullopt;
  const DiagRun& run = c.runs[static_cast<std::size_t>(p.run)];
  const double t0 = p.a < run.t.size() ? run.t[p.a] - run.t.front() : 0.0;
  const double t1 = p.b < run.t.size() ? run.t[p.b] - run.t.front() : t0;
  return Flag{"event",
              fmt::format("one {} piece of it, {:.1f}-{:.1f} s into the run, leaves the model by ({:+.2f}, {:+.2f}) mm "
                          "(along, left) and {:+.2f} mrad (its largest-piece score {:.1f} sd, its experiment's median run's "
                          "{:.1f} sd): a push, a coasting stop, a wheel slip or a ground-truth glitch at that "
                          "moment. Look at this run there (or drop the run)",
                          PieceTypeToString(p.type), t0, t1, 1e3 * ex, 1e3 * ey, 1e3 * eth, st.event[r].value, median),
              z / thr, z, thr};
}

/// The flags of run r, with the practical floors applied.
std::vector<Flag> FlagsOfRun(std::size_t r, const CampaignData& c, const BaselineFit& base, const RunStatistics& st,
                             const std::vector<double> z[kStatistics], const double thr[kStatistics],
                             const double med[kStatistics], const RunFaultOptions& o) {
  // med: the medians of the run's own experiment.
  std::vector<Flag> flags;
  auto over = [&](int k) { return std::isfinite(thr[k]) && std::isfinite(z[k][r]) && std::abs(z[k][r]) > thr[k]; };
  if (over(0)) {
    const double d_tau = st.tau[r].value - med[0];
    const double shift = std::abs(d_tau) * st.speed[r];
    if (shift >= o.min_shift_m)
      flags.push_back({"clock",
                       fmt::format("its ground-truth clock is {:+.0f} ms off the other runs' of its experiment (this "
                                   "run {:+.0f} ms, se {:.0f}; their median {:+.0f} ms): at its speed of {:.2f} m/s that moves its "
                                   "poses by {:.1f} mm. Shift this run's ground-truth timestamps by {:+.0f} ms (or "
                                   "drop the run)",
                                   1e3 * d_tau, 1e3 * st.tau[r].value, 1e3 * st.tau[r].se, 1e3 * med[0], st.speed[r],
                                   1e3 * shift, -1e3 * d_tau),
                       std::abs(z[0][r]) / thr[0], z[0][r], thr[0]});
  }
  if (over(1) || over(2)) {
    const double ddx = st.dx[r].value - med[1], ddy = st.dy[r].value - med[2];
    const int k = !over(2) || (over(1) && std::abs(z[1][r]) / thr[1] >= std::abs(z[2][r]) / thr[2]) ? 1 : 2;
    if (std::hypot(ddx, ddy) >= o.min_shift_m)
      flags.push_back({"marker",
                       fmt::format("its motion-capture marker sits at (dx, dy) = ({:+.1f}, {:+.1f}) mm, ({:+.1f}, "
                                   "{:+.1f}) mm from the other runs' of its experiment (median ({:+.1f}, {:+.1f}) mm): the marker or the "
                                   "rigid body changed for this run. Check the rigid body's origin for this recording "
                                   "(or drop the run)",
                                   1e3 * st.dx[r].value, 1e3 * st.dy[r].value, 1e3 * ddx, 1e3 * ddy, 1e3 * med[1],
                                   1e3 * med[2]),
                       std::abs(z[k][r]) / thr[k], z[k][r], thr[k]});
  }
  // One piece far off (upward only) is named beside a clock or marker: a
  // run's clock does not make a single piece stand out.
  if (over(4) && z[4][r] > 0.0)
    if (std::optional<Flag> f = EventFlag(r, c, base, st, z[4][r], thr[4], med[4], o)) flags.push_back(*f);
  // A clock, a marker or an event that far off scatters the run's residuals
  // too: the scatter is named only when none explains the run.
  if (flags.empty() && over(3) && z[3][r] > 0.0) {
    const double ratio = std::exp(st.scatter[r].value - med[3]);
    if (ratio >= o.min_scatter_ratio)
      flags.push_back({"scatter",
                       fmt::format("its residuals scatter {:.1f} times (in variance) as much as its experiment's median run: a "
                                   "stretch of data lost or corrupted, a collision, or a slip. Look at this run's "
                                   "residuals in the plot (or drop the run)",
                                   ratio),
                       z[3][r] / thr[3], z[3][r], thr[3]});
  }
  return flags;
}

}  // namespace

RunFaultScan FindRunFaults(const CampaignData& c, const MeanModel& model, const BaselineFit& base,
                           const RunFaultOptions& options) {
  RunFaultScan out;
  const RunStatistics st = ComputeRunStatistics(c, model, base, options);
  const std::vector<RunStatistic>* stats[kStatistics] = {&st.tau, &st.dx, &st.dy, &st.scatter, &st.event};
  std::vector<double> z[kStatistics], med[kStatistics];
  double thr[kStatistics];
  const double rate = options.alpha / kStatistics;
  for (int k = 0; k < kStatistics; ++k) {
    const Tested t = Collect(c, *stats[k]);
    z[k] = Deviations(t, c.runs.size());
    med[k] = ExperimentMedians(c, *stats[k]);
    const int n = static_cast<int>(std::count_if(z[k].begin(), z[k].end(), [](double v) { return !std::isnan(v); }));
    thr[k] = n >= options.min_runs
                 ? MaxDeviationThreshold(t.group, rate, options.simulations, sim::StreamSeed(options.seed, 0, 400 + k))
                 : std::numeric_limits<double>::infinity();
    out.runs_tested = std::max(out.runs_tested, n);
  }
  out.threshold_clock = std::isfinite(thr[0]) ? thr[0] : 0.0;
  out.threshold_marker = std::isfinite(thr[1]) ? thr[1] : 0.0;
  out.threshold_scatter = std::isfinite(thr[3]) ? thr[3] : 0.0;
  out.threshold_event = std::isfinite(thr[4]) ? thr[4] : 0.0;
  if (!std::isfinite(thr[0]) && !std::isfinite(thr[1]) && !std::isfinite(thr[3]) && !std::isfinite(thr[4])) {
    out.test = fmt::format("not tested: the test needs {} runs or more in experiments of 3 runs or more ({} here)",
                           options.min_runs, out.runs_tested);
    return out;
  }
  auto thr_text = [](double t) { return std::isfinite(t) ? fmt::format("{:.1f}", t) : std::string("(not tested)"); };
  out.test = fmt::format(
      "each run's own clock offset, marker offset, residual scatter and largest single piece against the same "
      "quantity of the other runs of its experiment (median per experiment, spread by the MAD pooled over experiments "
      "of 3 runs or more): a run is faulty beyond {} (clock), {} (marker), {} (scatter), {} (event) robust standard "
      "deviations, where normal run-to-run variation over {} runs goes in {:.0f}% of campaigns",
      thr_text(thr[0]), thr_text(thr[1]), thr_text(thr[3]), thr_text(thr[4]), out.runs_tested, 100.0 * options.alpha);
  for (std::size_t r = 0; r < c.runs.size(); ++r) {
    const std::size_t e = static_cast<std::size_t>(c.runs[r].experiment);
    const double m[kStatistics] = {med[0][e], med[1][e], med[2][e], med[3][e], med[4][e]};
    std::vector<Flag> flags = FlagsOfRun(r, c, base, st, z, thr, m, options);
    if (flags.empty()) continue;
    std::sort(flags.begin(), flags.end(), [](const Flag& a, const Flag& b) { return a.excess > b.excess; });
    RunFault f;
    f.run = static_cast<int>(r);
    f.experiment = c.runs[r].experiment;
    f.run_id = c.runs[r].id;
    f.statistic = flags.front().statistic;
    f.z = flags.front().z;
    f.threshold = flags.front().threshold;
    if (st.tau[r].informative) f.tau_s = st.tau[r].value - m[0];
    if (st.dx[r].informative) {
      f.dx_m = st.dx[r].value - m[1];
      f.dy_m = st.dy[r].value - m[2];
    }
    for (std::size_t i = 0; i < flags.size(); ++i)
      f.what += (i ? "; also " : "") + flags[i].text + fmt::format(" [{} z = {:+.1f}, threshold {:.1f}]",
                                                                     flags[i].statistic, flags[i].z, flags[i].threshold);
    out.faults.push_back(std::move(f));
  }
  return out;
}

CampaignData WithoutRuns(const CampaignData& c, const std::vector<int>& drop) {
  const std::set<int> gone(drop.begin(), drop.end());
  CampaignData out;
  out.path = c.path;
  out.robot = c.robot;
  out.ground_truth = c.ground_truth;
  out.tick_left_m = c.tick_left_m;
  out.tick_right_m = c.tick_right_m;
  out.stop_model = c.stop_model;
  out.experiments = c.experiments;
  out.subsets = c.subsets;
  out.folds = c.folds;
  std::vector<int> new_index(c.runs.size(), -1);
  // Per experiment, the dropped runs by their index in it (file order of
  // the runs BuildCampaign took: every endpoint run, trajectory runs of two
  // samples or more).
  std::map<int, std::set<int>> dropped;
  for (std::size_t r = 0; r < c.runs.size(); ++r) {
    if (gone.count(static_cast<int>(r))) {
      dropped[c.runs[r].experiment].insert(c.runs[r].index_in_experiment);
      out.experiments[static_cast<std::size_t>(c.runs[r].experiment)].runs -= 1;
      continue;
    }
    new_index[r] = static_cast<int>(out.runs.size());
    out.runs.push_back(c.runs[r]);
  }
  for (const Piece& p : c.pieces) {
    if (new_index[static_cast<std::size_t>(p.run)] < 0) continue;
    out.pieces.push_back(p);
    out.pieces.back().run = new_index[static_cast<std::size_t>(p.run)];
  }
  out.files = c.files;
  for (const auto& [e, indices] : dropped) {
    auto& file = out.files[static_cast<std::size_t>(e)];
    if (auto* t = std::get_if<TrajectoryData>(&file)) {
      std::vector<TrajectoryRun> kept;
      int k = 0;
      for (TrajectoryRun& run : t->runs) {
        const bool taken = run.size() >= 2;
        if (!(taken && indices.count(k))) kept.push_back(std::move(run));
        k += taken ? 1 : 0;
      }
      t->runs = std::move(kept);
    } else {
      auto& runs = std::get<EndpointData>(file).runs;
      std::vector<ReturnError> kept;
      for (std::size_t k = 0; k < runs.size(); ++k)
        if (!indices.count(static_cast<int>(k))) kept.push_back(runs[k]);
      runs = std::move(kept);
    }
  }
  return out;
}

}  // namespace umbmark::diag
