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
  if (!(turn_tolerance_rad > 0.0)) return fmt::format("turn_tolerance_rad = {} must be > 0", turn_tolerance_rad);
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
  out.P += w * B.P;
  out.P_xy += w * B.P_xy;
  out.P_turn += w * B.P_turn;
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

/// Piece b of another run matched to piece a of the reference run: the
/// same type and sign, and travel within the tolerance.
bool Matches(const Piece& a, const Piece& b, const PieceBases& A, const PieceBases& B, double wheelbase_m,
             const RepeatNoiseOptions& o) {
  if (a.type != b.type || a.sign != b.sign) return false;
  if (std::abs(b.travel_m - a.travel_m) > std::max(o.travel_tolerance * std::max(a.travel_m, b.travel_m), o.travel_slack_m))
    return false;
  // Heading change: the same turn or circle, not its mirror or another
  // radius (a spot turn's from both wheels' travel and its sign).
  auto turn = [&](const Piece& p, const PieceBases& q) {
    return p.type == PieceType::kTurn ? p.sign * (q.travel_left_m + q.travel_right_m) / wheelbase_m
                                      : (q.travel_right_m - q.travel_left_m) / wheelbase_m;
  };
  return std::abs(turn(a, A) - turn(b, B)) <= o.turn_tolerance_rad;
}

/// For each piece of the reference run `ref`, the matched piece of `run`
/// (-1: none), by the longest common subsequence under Matches: a real run
/// has a creep or a split the others lack, so pieces are aligned, not
/// counted.
std::vector<int> Align(const CampaignData& c, const std::vector<PieceBases>& bases, const std::vector<int>& ref,
                       const std::vector<int>& run, const RepeatNoiseOptions& o) {
  const std::size_t n = ref.size(), m = run.size();
  std::vector<int> L((n + 1) * (m + 1), 0);
  auto at = [&](std::size_t i, std::size_t j) -> int& { return L[i * (m + 1) + j]; };
  auto match = [&](std::size_t i, std::size_t j) {
    const std::size_t a = static_cast<std::size_t>(ref[i]), b = static_cast<std::size_t>(run[j]);
    return Matches(c.pieces[a], c.pieces[b], bases[a], bases[b], c.robot.wheelbase_m, o);
  };
  for (std::size_t i = n; i-- > 0;)
    for (std::size_t j = m; j-- > 0;)
      at(i, j) = match(i, j) ? at(i + 1, j + 1) + 1 : std::max(at(i + 1, j), at(i, j + 1));
  std::vector<int> out(n, -1);
  for (std::size_t i = 0, j = 0; i < n && j < m;) {
    if (match(i, j) && at(i, j) == at(i + 1, j + 1) + 1) {
      out[i] = run[j];
      ++i, ++j;
    } else if (at(i + 1, j) >= at(i, j + 1)) {
      ++i;
    } else {
      ++j;
    }
  }
  return out;
}

/// The contrasts of one stretch of the path: `pieces` (one per run, in
/// campaign order) with their runs' places in the campaign `place`.
void AddPosition(const CampaignData& c, const std::vector<int>& pieces, const std::vector<double>& place,
                 const RepeatNoiseOptions& o, bool pairs, RepeatDesign& out) {
  const Eigen::Index n = static_cast<Eigen::Index>(pieces.size());
  int components = 3;
  for (int j : pieces) components = std::min(components, c.pieces[static_cast<std::size_t>(j)].components);
  if (pairs) {
    const double h = 1.0 / std::sqrt(2.0);
    for (std::size_t i = 0; i + 1 < pieces.size(); i += 2)
      out.contrasts.push_back({{pieces[i], pieces[i + 1]}, {h, -h}, components});
    return;
  }
  Eigen::MatrixXd X(n, o.detrend ? 2 : 1);
  for (Eigen::Index i = 0; i < n; ++i) {
    X(i, 0) = 1.0;
    if (o.detrend) X(i, 1) = place[static_cast<std::size_t>(i)];
  }
  const Eigen::MatrixXd H = Contrasts(X);
  for (Eigen::Index k = 0; k < H.rows(); ++k) {
    RepeatDesign::Contrast z{pieces, std::vector<double>(pieces.size()), components};
    for (Eigen::Index i = 0; i < n; ++i) z.h[static_cast<std::size_t>(i)] = H(k, i);
    out.contrasts.push_back(std::move(z));
  }
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

RepeatDesign BuildRepeatDesign(const CampaignData& c, const std::vector<PieceBases>& bases,
                               const RepeatNoiseOptions& options, bool pairs) {
  RepeatDesign out;
  const std::size_t fewest = options.detrend ? 3 : 2;  // runs at a position: more than the contrasts' constraints
  for (auto& [key, group] : GroupRuns(c)) {
    // Runs of one label may drive different paths (the June circles: cw and
    // ccw both "circular"): the runs that share at least half of a typical
    // run's pieces form one set, the rest are tried again among themselves.
    std::vector<std::vector<int>> left = std::move(group);
    while (static_cast<int>(left.size()) >= options.min_runs) {
      std::vector<std::size_t> by_count(left.size());
      for (std::size_t i = 0; i < left.size(); ++i) by_count[i] = i;
      std::sort(by_count.begin(), by_count.end(), [&](std::size_t a, std::size_t b) { return left[a].size() < left[b].size(); });
      const std::vector<int> ref = left[by_count[left.size() / 2]];
      std::vector<std::vector<int>> aligned, rest;
      for (auto& r : left) {
        std::vector<int> a = Align(c, bases, ref, r, options);
        const std::size_t matched = static_cast<std::size_t>(std::count_if(a.begin(), a.end(), [](int j) { return j >= 0; }));
        if (2 * matched >= ref.size()) aligned.push_back(std::move(a));
        else rest.push_back(std::move(r));
      }
      left = std::move(rest);
      if (static_cast<int>(aligned.size()) < options.min_runs) continue;
      int used = 0;
      for (std::size_t m = 0; m < ref.size(); ++m) {
        std::vector<int> pieces;
        std::vector<double> place;
        for (const auto& a : aligned)
          if (a[m] >= 0) {
            pieces.push_back(a[m]);
            place.push_back(c.runs[static_cast<std::size_t>(c.pieces[static_cast<std::size_t>(a[m])].run)].campaign_index);
          }
        if (pieces.size() < fewest) continue;
        AddPosition(c, pieces, place, options, pairs, out);
        ++used;
      }
      if (used == 0) continue;
      ++out.groups;
      out.runs += static_cast<int>(aligned.size());
      out.positions += used;
    }
  }
  return out;
}

RepeatContrasts ApplyRepeatDesign(const RepeatDesign& design, const CampaignData& c, const std::vector<double>& eps,
                                  const std::vector<PieceBases>& bases) {
  RepeatContrasts out;
  out.groups = design.groups;
  out.runs = design.runs;
  out.positions = design.positions;
  out.eps.reserve(3 * design.contrasts.size());
  out.bases.reserve(design.contrasts.size());
  out.pieces.reserve(design.contrasts.size());
  for (const RepeatDesign::Contrast& k : design.contrasts) {
    Eigen::Vector3d z = Eigen::Vector3d::Zero();
    PieceBases B;
    for (std::size_t i = 0; i < k.pieces.size(); ++i) {
      const std::size_t j = static_cast<std::size_t>(k.pieces[i]);
      z += k.h[i] * Eigen::Vector3d(eps[3 * j], eps[3 * j + 1], eps[3 * j + 2]);
      AddBases(B, bases[j], k.h[i] * k.h[i]);
    }
    if (k.components < 3) z[2] = 0.0;
    out.eps.insert(out.eps.end(), {z[0], z[1], z[2]});
    out.bases.push_back(B);
    Piece p = c.pieces[static_cast<std::size_t>(k.pieces.front())];
    p.components = k.components;
    out.pieces.push_back(p);
  }
  return out;
}

RepeatContrasts FormRepeatContrasts(const CampaignData& c, const std::vector<double>& eps,
                                    const std::vector<PieceBases>& bases, const RepeatNoiseOptions& options) {
  return ApplyRepeatDesign(BuildRepeatDesign(c, bases, options), c, eps, bases);
}

RepeatWheelFit FitRepeatWheelNoise(const RepeatDesign& design, const RepeatDesign& pairs, const CampaignData& c,
                                   const std::vector<double>& eps, const std::vector<PieceBases>& bases,
                                   const NoiseParams& start, const PieceNoiseFitOptions& fit, bool bumps) {
  PieceNoiseFitOptions o = fit;
  o.fit_wheel_noise = true;
  RepeatWheelFit out;
  NoiseParams n = start;
  if (bumps) {
    const RepeatContrasts rc = ApplyRepeatDesign(pairs, c, eps, bases);
    n.c_LR = n.floor_s2 = n.stand_xy2 = n.stand_th2 = n.run_tau2 = 0.0;
    out.noise = FitBumps(rc.eps, rc.bases, rc.pieces, {}, n, BumpFitOptions{});
    out.contrasts = static_cast<int>(rc.pieces.size());
    return out;
  }
  const RepeatContrasts rc = ApplyRepeatDesign(design, c, eps, bases);
  out.noise = FitPieceNoise(rc.eps, rc.bases, rc.pieces, {}, n, o);
  out.contrasts = static_cast<int>(rc.pieces.size());
  // Fisher information of the fitted variances: the wheels first, then each
  // enabled term's basis.
  std::vector<Eigen::Matrix3d PieceBases::*> terms = {&PieceBases::A_L, &PieceBases::A_R};
  if (o.correlated) terms.push_back(&PieceBases::A_LR);
  if (o.motion_floor) terms.push_back(&PieceBases::F);
  if (o.standstill) terms.insert(terms.end(), {&PieceBases::S_xy, &PieceBases::S_theta});
  if (o.run_time) terms.push_back(&PieceBases::T);
  if (o.first_start) terms.insert(terms.end(), {&PieceBases::P, &PieceBases::P_xy, &PieceBases::P_turn});
  const Eigen::Index m = static_cast<Eigen::Index>(terms.size());
  Eigen::MatrixXd I = Eigen::MatrixXd::Zero(m, m);
  for (std::size_t j = 0; j < rc.pieces.size(); ++j) {
    const int d = rc.pieces[j].components;
    const Eigen::MatrixXd Ci = PieceCovariance(rc.bases[j], out.noise).topLeftCorner(d, d).inverse();
    std::vector<Eigen::MatrixXd> M;
    for (auto t : terms) M.push_back(Ci * (rc.bases[j].*t).topLeftCorner(d, d));
    for (Eigen::Index a = 0; a < m; ++a)
      for (Eigen::Index b = 0; b < m; ++b)
        I(a, b) += 0.5 * (M[static_cast<std::size_t>(a)] * M[static_cast<std::size_t>(b)]).trace();
  }
  // A variance term at its floor (0) carries no information in practice:
  // its row is kept, the pseudo-inverse keeps the wheels' part finite.
  const Eigen::MatrixXd V = I.completeOrthogonalDecomposition().pseudoInverse();
  out.sd_kL2 = std::sqrt(std::max(0.0, V(0, 0)));
  out.sd_kR2 = std::sqrt(std::max(0.0, V(1, 1)));
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
  o.correlated = o.motion_floor = o.standstill = o.run_time = o.first_start = false;
  NoiseParams n;  // the wheels and the ground truth only
  n.kL2 = start.kL2;
  n.kR2 = start.kR2;
  n.sxy2 = start.sxy2;
  n.sth2 = start.sth2;
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
