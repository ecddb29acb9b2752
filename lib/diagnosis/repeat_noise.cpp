// Wheel noise from the scatter of repeated runs (see repeat_noise.hpp).
#include "diagnosis/repeat_noise.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

#include <Eigen/Dense>
#include <fmt/format.h>

namespace umbmark::diag {

std::string RepeatNoiseOptions::Check() const {
  if (min_runs < 2) return fmt::format("min_runs = {} must be >= 2", min_runs);
  if (min_contrasts < 1) return fmt::format("min_contrasts = {} must be >= 1", min_contrasts);
  if (!(travel_tolerance > 0.0)) return fmt::format("travel_tolerance = {} must be > 0", travel_tolerance);
  if (!(travel_slack_m >= 0.0)) return fmt::format("travel_slack_m = {} must be >= 0", travel_slack_m);
  if (!(max_correlation > 0.0 && max_correlation < 1.0))
    return fmt::format("max_correlation = {} must be in (0, 1)", max_correlation);
  return {};
}

namespace {

/// sum_i w_i B_i over the bases the covariance is linear in.
void AddBases(PieceBases& out, const PieceBases& B, double w) {
  out.A_L += w * B.A_L;
  out.A_R += w * B.A_R;
  out.A_LR += w * B.A_LR;
  out.G_xy += w * B.G_xy;
  out.G_theta += w * B.G_theta;
  out.Q += w * B.Q;
  out.F += w * B.F;
  out.S_xy += w * B.S_xy;
  out.S_theta += w * B.S_theta;
  out.T += w * B.T;
  out.K += w * B.K;
  out.travel_left_m += w * B.travel_left_m;
  out.travel_right_m += w * B.travel_right_m;
}

/// Orthonormal rows spanning the complement of the columns of X (n x p):
/// the contrasts free of a mean (and of a trend when X has one).
Eigen::MatrixXd Contrasts(const Eigen::MatrixXd& X) {
  const Eigen::Index n = X.rows(), p = X.cols();
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(X);
  const Eigen::MatrixXd Q = qr.householderQ() * Eigen::MatrixXd::Identity(n, n);
  return Q.rightCols(n - p).transpose();
}

/// Whether piece b is the same stretch of the path as reference a.
bool SameStretch(const Piece& a, const Piece& b, double median_travel, const RepeatNoiseOptions& o) {
  if (a.type != b.type || a.sign != b.sign) return false;
  return std::abs(b.travel_m - median_travel) <= std::max(o.travel_tolerance * median_travel, o.travel_slack_m);
}

/// Runs of each experiment and direction (campaign order), each with its
/// pieces in order.
std::map<std::pair<int, std::string>, std::vector<std::vector<int>>> GroupRuns(const CampaignData& c) {
  std::vector<std::vector<int>> of_run(c.runs.size());
  for (std::size_t j = 0; j < c.pieces.size(); ++j) of_run[static_cast<std::size_t>(c.pieces[j].run)].push_back(static_cast<int>(j));
  std::vector<int> order(c.runs.size());
  for (std::size_t r = 0; r < order.size(); ++r) order[r] = static_cast<int>(r);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return c.runs[static_cast<std::size_t>(a)].campaign_index < c.runs[static_cast<std::size_t>(b)].campaign_index; });
  std::map<std::pair<int, std::string>, std::vector<std::vector<int>>> groups;
  for (int r : order) {
    const DiagRun& run = c.runs[static_cast<std::size_t>(r)];
    if (!of_run[static_cast<std::size_t>(r)].empty())
      groups[{run.experiment, run.direction}].push_back(std::move(of_run[static_cast<std::size_t>(r)]));
  }
  return groups;
}

/// The runs of a group with its most common piece count (a run with a
/// piece more or less, a glitch or a stop of its own, is left out).
std::vector<std::vector<int>> ModalRuns(std::vector<std::vector<int>> runs) {
  std::map<std::size_t, int> count;
  for (const auto& r : runs) ++count[r.size()];
  std::size_t best = 0;
  int most = 0;
  for (const auto& [size, n] : count)
    if (n > most) best = size, most = n;
  std::erase_if(runs, [&](const std::vector<int>& r) { return r.size() != best; });
  return runs;
}

/// The contrasts of one position m of a group's runs `runs` (indices of
/// their pieces), appended to out; false when the runs' pieces differ.
bool AddPosition(const CampaignData& c, const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                 const std::vector<std::vector<int>>& runs, std::size_t m, const Eigen::MatrixXd& H,
                 const RepeatNoiseOptions& o, RepeatContrasts& out) {
  std::vector<double> travel;
  for (const auto& r : runs) travel.push_back(c.pieces[static_cast<std::size_t>(r[m])].travel_m);
  std::nth_element(travel.begin(), travel.begin() + static_cast<std::ptrdiff_t>(travel.size() / 2), travel.end());
  const double median = travel[travel.size() / 2];
  const Piece& ref = c.pieces[static_cast<std::size_t>(runs.front()[m])];
  int components = 3;
  for (const auto& r : runs) {
    const Piece& p = c.pieces[static_cast<std::size_t>(r[m])];
    if (!SameStretch(ref, p, median, o)) return false;
    components = std::min(components, p.components);
  }
  for (Eigen::Index k = 0; k < H.rows(); ++k) {
    Eigen::Vector3d z = Eigen::Vector3d::Zero();
    PieceBases B;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      const std::size_t j = static_cast<std::size_t>(runs[i][m]);
      const double h = H(k, static_cast<Eigen::Index>(i));
      z += h * Eigen::Vector3d(eps[3 * j], eps[3 * j + 1], eps[3 * j + 2]);
      AddBases(B, bases[j], h * h);
    }
    if (components < 3) z[2] = 0.0;
    out.eps.insert(out.eps.end(), {z[0], z[1], z[2]});
    out.bases.push_back(B);
    Piece p = ref;
    p.components = components;
    out.pieces.push_back(p);
  }
  return true;
}

/// Fisher information of (k_L^2, k_R^2) on the contrasts at n.
Eigen::Matrix2d WheelInformation(const RepeatContrasts& rc, const NoiseParams& n) {
  Eigen::Matrix2d I = Eigen::Matrix2d::Zero();
  for (std::size_t j = 0; j < rc.pieces.size(); ++j) {
    const int d = rc.pieces[j].components;
    const Eigen::Matrix3d C = PieceCovariance(rc.bases[j], n);
    const Eigen::MatrixXd Ci = C.topLeftCorner(d, d).inverse();
    const Eigen::MatrixXd M0 = Ci * rc.bases[j].A_L.topLeftCorner(d, d);
    const Eigen::MatrixXd M1 = Ci * rc.bases[j].A_R.topLeftCorner(d, d);
    I(0, 0) += 0.5 * (M0 * M0).trace();
    I(1, 1) += 0.5 * (M1 * M1).trace();
    I(0, 1) += 0.5 * (M0 * M1).trace();
  }
  I(1, 0) = I(0, 1);
  return I;
}

}  // namespace

RepeatContrasts FormRepeatContrasts(const CampaignData& c, const std::vector<double>& eps,
                                    const std::vector<PieceBases>& bases, const RepeatNoiseOptions& options) {
  RepeatContrasts out;
  for (auto& [key, all] : GroupRuns(c)) {
    const std::vector<std::vector<int>> runs = ModalRuns(std::move(all));
    const int n = static_cast<int>(runs.size());
    if (n < options.min_runs || n < (options.detrend ? 3 : 2)) continue;
    Eigen::MatrixXd X(n, options.detrend ? 2 : 1);
    for (int i = 0; i < n; ++i) {
      X(i, 0) = 1.0;
      if (options.detrend) X(i, 1) = c.runs[static_cast<std::size_t>(c.pieces[static_cast<std::size_t>(runs[static_cast<std::size_t>(i)].front())].run)].campaign_index;
    }
    const Eigen::MatrixXd H = Contrasts(X);
    int used = 0;
    for (std::size_t m = 0; m < runs.front().size(); ++m) used += AddPosition(c, eps, bases, runs, m, H, options, out) ? 1 : 0;
    if (used == 0) continue;
    ++out.groups;
    out.runs += n;
    out.positions += used;
  }
  return out;
}

RepeatNoise MeasureRepeatNoise(const CampaignData& c, const std::vector<double>& eps,
                               const std::vector<PieceBases>& bases, const NoiseParams& start,
                               const PieceNoiseFitOptions& fit, const RepeatNoiseOptions& options) {
  RepeatNoise r;
  const RepeatContrasts rc = FormRepeatContrasts(c, eps, bases, options);
  r.groups = rc.groups;
  r.runs = rc.runs;
  r.positions = rc.positions;
  r.contrasts = static_cast<int>(rc.pieces.size());
  if (r.contrasts < options.min_contrasts) {
    r.reason = fmt::format("{} contrast pieces of repeated runs (fewer than {}: experiments need at least {} runs per "
                           "direction that break into the same pieces)",
                           r.contrasts, options.min_contrasts, options.min_runs);
    return r;
  }
  PieceNoiseFitOptions o = fit;
  o.fit_wheel_noise = true;
  o.correlated = o.motion_floor = o.standstill = o.run_time = false;
  NoiseParams n = start;
  n.c_LR = n.floor_s2 = n.stand_xy2 = n.stand_th2 = n.run_tau2 = n.swivel_rev2 = 0.0;
  n.bump_rate = n.bump_s2 = 0.0;
  n = FitPieceNoise(rc.eps, rc.bases, rc.pieces, {}, n, o);
  r.k_L = std::sqrt(n.kL2);
  r.k_R = std::sqrt(n.kR2);
  const Eigen::Matrix2d I = WheelInformation(rc, n);
  const Eigen::Matrix2d V = I.inverse();
  if (!V.allFinite() || V(0, 0) <= 0.0 || V(1, 1) <= 0.0) {
    r.reason = "the repeated runs' contrasts do not determine k_L and k_R (singular information)";
    return r;
  }
  r.sd_kL2 = std::sqrt(V(0, 0));
  r.sd_kR2 = std::sqrt(V(1, 1));
  r.sd_k_L = r.sd_kL2 / (2.0 * std::max(r.k_L, 1e-9));
  r.sd_k_R = r.sd_kR2 / (2.0 * std::max(r.k_R, 1e-9));
  r.correlation = V(0, 1) / std::sqrt(V(0, 0) * V(1, 1));
  if (std::abs(r.correlation) > options.max_correlation) {
    r.reason = fmt::format("the repeated runs do not separate the wheels (k_L^2, k_R^2 estimates correlated {:.3f}, "
                           "beyond {:.2f}): add runs that turn both ways",
                           r.correlation, options.max_correlation);
    return r;
  }
  r.measured = true;
  return r;
}

std::string RepeatNoiseSummary(const RepeatNoise& r) {
  if (!r.measured) return "wheel noise not measured from repeated runs: " + r.reason;
  return fmt::format("k_L = {:.3g} +- {:.2g}, k_R = {:.3g} +- {:.2g} m^1/2 from the scatter of repeated runs about their "
                     "own mean ({} contrast pieces at {} positions of {} runs in {} experiment-direction groups)",
                     r.k_L, r.sd_k_L, r.k_R, r.sd_k_R, r.contrasts, r.positions, r.runs, r.groups);
}

}  // namespace umbmark::diag
