// Faults of single runs (contract: `run_faults`): one run whose clock jumps,
// whose marker was swapped, or whose data lost a stretch is that run's fault,
// not an effect of the campaign. The run is named and the effects are fitted
// without it.
//
// The test (docs/diagnosis.md, "Faults of single runs"). Under the baseline
// fit, every run gets three statistics of its own, each with a standard
// error:
//   clock    its own ground-truth clock offset tau_r (the time_offset of the
//            mean model profiled over a grid on the run's pieces alone,
//            E_d, E_b held; a parabola through the grid's best three points);
//   marker   its own marker offset (dx_r, dy_r) (gt_offset on the run's
//            pieces alone, weighted least squares, linear in dx, dy);
//   scatter  log of its mean chi^2 per residual component under the
//            baseline (se sqrt(2 / components)).
//   event    its largest single piece: the piece's chi^2 under the baseline
//            as the normal score of the largest of the run's n pieces,
//            u = -Phi^-1(1 - (1 - Q)^n), Q the chi^2 tail (se 1; N(0, 1)
//            for every run when the model holds). One push, coasting stop,
//            wheel slip or ground-truth glitch in one run stands out; an
//            effect acting on many pieces (bumps, a castor's kick at every
//            run's first start) raises every run's u and none stands out.
// A per-run effect (run_time_offset: tau_r ~ N(mu, tau_sd^2)) makes the
// statistic of every run vary from run to run; a fault makes one run stand
// out of that spread. Runs of different experiments may differ by design (a
// slide at the stops shows as an apparent clock offset that grows with the
// speed, which differs between squares and free paths), so each statistic is
// compared with the same statistic of the other runs of the run's
// experiment, robustly, the spread pooled over experiments:
//   z_r = (x_r - median_e x) / sqrt(s_b^2 + se_r^2),
//   s_b^2 = max(0, (1.4826 median |x - median_e x|)^2 - median se^2)
// (experiments of fewer than 3 runs are not tested: a run cannot be told
// from a group of two)
// (the median absolute deviation is not inflated by the outliers it is
// looking for; s_b is the between-run spread with the estimation noise
// removed). A run is faulty when |z_r| exceeds the (1 - alpha / m) quantile
// of max_r |z_r| over runs whose statistic is independent and normal (a
// per-run effect's tail), by Monte Carlo with these experiments' sizes (`simulations` draws,
// seeded), m = 5 statistics (tau, dx, dy, scatter, event; scatter and event
// count only upward). So a campaign with per-run clocks but no fault names a run in
// at most a fraction alpha (default 1 %) of cases, whatever its size, and
// the threshold is set by that rate, not between observed cases. A fault
// must also matter in practice: a clock or marker that moves the run's
// poses by at least `min_shift_m` (the clock at the run's median moving
// speed), a scatter at least `min_scatter_ratio` times the campaign's, an
// event that moves the piece by at least `min_shift_m` (or turns it by as
// much at a wheel: heading x half the wheelbase).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "diagnosis/baseline.hpp"
#include "diagnosis/model.hpp"
#include "diagnosis/pieces.hpp"

namespace umbmark::diag {

struct RunFaultOptions {
  /// Campaign-wide false-alarm rate of the test (0 < alpha < 0.5): the
  /// chance that a campaign of normal per-run variation names a run.
  /// Default 0.01.
  double alpha = 0.01;
  /// Fewest runs with a statistic for the test of that statistic (>= 4).
  /// Default 5.
  int min_runs = 5;
  /// Monte Carlo draws for the threshold (>= 200). Default 4000.
  int simulations = 4000;
  std::uint64_t seed = 1;
  /// The clock profile's grid: -clock_range_s .. +clock_range_s in steps of
  /// clock_step_s (> 0). Default 0.8 s and 0.04 s.
  double clock_range_s = 0.8;
  double clock_step_s = 0.04;
  /// Practical floor of a clock or marker fault: the shift of the run's
  /// poses [m] (>= 0). Default 0.001 (1 mm).
  double min_shift_m = 0.001;
  /// Practical floor of a scatter fault: its mean chi^2 this many times the
  /// campaign's median run (>= 1). Default 4 (twice the scatter).
  double min_scatter_ratio = 4.0;

  std::string Check() const;
};

/// One statistic of one run.
struct RunStatistic {
  double value = 0.0, se = 0.0;
  bool informative = false;  ///< the run determines it (finite, positive se)
};

struct RunFault {
  int run = 0;         ///< index into CampaignData::runs
  int experiment = 0;  ///< 0-based
  std::string run_id;  ///< as in the file
  std::string what;    ///< in words, with the numbers and what to do
  /// The statistic that stands out most: "clock", "marker", "event" or
  /// "scatter".
  std::string statistic;
  double z = 0.0, threshold = 0.0;
  /// The run's own clock offset [s] or marker offset [m] less the
  /// campaign's median (what to change for this run).
  double tau_s = 0.0, dx_m = 0.0, dy_m = 0.0;
};

struct RunFaultScan {
  std::vector<RunFault> faults;
  /// The threshold on |z| for each statistic (0 where not tested) and the
  /// number of runs tested.
  double threshold_clock = 0.0, threshold_marker = 0.0, threshold_scatter = 0.0, threshold_event = 0.0;
  int runs_tested = 0;
  std::string test;  ///< the test in one sentence, for the report
};

/// Robust deviations z_r of statistic values x with standard errors se (see
/// the file comment), each centred on the median of its group (`group[r]`;
/// empty: one group) with the MAD pooled over the groups; NaN for the
/// members of groups under 3 values (a run cannot be told from a group of
/// two). Empty when the sizes disagree.
std::vector<double> RobustDeviations(const std::vector<double>& x, const std::vector<double>& se,
                                     const std::vector<int>& group);
/// One group; empty when fewer than 3 values.
std::vector<double> RobustDeviations(const std::vector<double>& x, const std::vector<double>& se);

/// The (1 - rate) quantile of max_r |z_r| (RobustDeviations with se = 0 and
/// these groups) for independent standard normal values, from
/// `simulations` seeded draws.
double MaxDeviationThreshold(const std::vector<int>& group, double rate, int simulations, std::uint64_t seed);
/// One group of n.
double MaxDeviationThreshold(int n, double rate, int simulations, std::uint64_t seed);

/// Per-run statistics under the baseline `base` (see the file comment).
struct RunStatistics {
  std::vector<RunStatistic> tau, dx, dy, scatter, event;
  std::vector<int> event_piece;  ///< the piece of each run's event (index into CampaignData::pieces; -1: none)
  std::vector<double> speed;     ///< each run's median moving speed [m/s] (0: none)
};
RunStatistics ComputeRunStatistics(const CampaignData& c, const MeanModel& model, const BaselineFit& base,
                                   const RunFaultOptions& options);

/// The test on a campaign under its baseline.
RunFaultScan FindRunFaults(const CampaignData& c, const MeanModel& model, const BaselineFit& base,
                           const RunFaultOptions& options);

/// The campaign without the runs `drop` (indices into c.runs): runs,
/// pieces (re-indexed) and the files the refined calibration reads.
CampaignData WithoutRuns(const CampaignData& c, const std::vector<int>& drop);

}  // namespace umbmark::diag
