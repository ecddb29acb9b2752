// Mean model and covariance bases of the diagnosis (see model.hpp).
#include "diagnosis/model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/angles.hpp"
#include "effects/registry.hpp"
#include "kinematics/diff_drive.hpp"
#include "model/true_robot.hpp"

namespace umbmark::diag {


ParamVector NominalParams() {
  ParamVector p{};
  p[kParamEd] = 1.0;
  p[kParamEb] = 1.0;
  return p;
}

const char* ParamName(int index) {
  static const char* names[kParamRunTime0] = {"E_d", "E_b", "s", "k", "a", "kappa", "r", "dx",
                                              "dy",  "tau", "kappa", "d", "a", "arc", "back"};
  if (index >= 0 && index < kParamRunTime0) return names[index];
  for (const RunTimeSlots& rt : RunTimeEffects())
    if (index >= rt.first && index < rt.first + rt.count)
      return rt.effect->Parameters()[static_cast<std::size_t>(index - rt.first)].name.data();
  return "?";
}

std::vector<RunTimeSlots> RunTimeEffects() {
  std::vector<RunTimeSlots> out;
  int next = kParamRunTime0;
  for (const effects::Effect* e : effects::All()) {
    if (!e->PredictsMean()) continue;
    const int n = static_cast<int>(e->Parameters().size());
    if (n == 0 || next + n > kNumParams) continue;
    out.push_back({e, next, n});
    next += n;
  }
  return out;
}

std::vector<int> RunTimeParams(const effects::Effect& effect) {
  for (const RunTimeSlots& rt : RunTimeEffects())
    if (rt.effect == &effect) {
      std::vector<int> out(static_cast<std::size_t>(rt.count));
      for (int k = 0; k < rt.count; ++k) out[static_cast<std::size_t>(k)] = rt.first + k;
      return out;
    }
  return {};
}

namespace {

/// Mean of poses[lo..hi] over the samples with use(i): positions averaged,
/// headings averaged as increments from the first one (no wrap-around).
template <typename PoseAt, typename Use>
Pose2 MeanPose(std::size_t lo, std::size_t hi, const PoseAt& pose_at, const Use& use) {
  if (lo == hi) return pose_at(lo);
  Pose2 first, sum{0.0, 0.0, 0.0};
  bool any = false;
  int n = 0;
  for (std::size_t i = lo; i <= hi; ++i) {
    if (!use(i)) continue;
    const Pose2 q = pose_at(i);
    if (!any) first = q;
    any = true;
    sum.x += q.x;
    sum.y += q.y;
    sum.theta += WrapAngle(q.theta - first.theta);
    ++n;
  }
  return {sum.x / n, sum.y / n, first.theta + sum.theta / n};
}

inline Pose2 Relative(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  const double dx = b.x - a.x, dy = b.y - a.y;
  return {c * dx + s * dy, -s * dx + c * dy, b.theta - a.theta};
}

/// The effects whose mean model moves the robot after a stop (a coast:
/// Effect::PredictStop): those with mean terms and at_motion_stops, each
/// with its parameters' indices in ParamVector (at most kMaxStopTerms).
constexpr std::size_t kMaxStopEffects = 2, kMaxStopTerms = 6;
struct StopEffect {
  const effects::Effect* effect = nullptr;
  std::size_t count = 0;
  int terms[kMaxStopTerms] = {};
};
struct StopEffectList {
  StopEffect list[kMaxStopEffects];
  std::size_t count = 0;
};

const StopEffectList& StopEffects() {
  static const StopEffectList all = [] {
    StopEffectList out;
    for (const effects::Effect* e : effects::All()) {
      const effects::Descriptor& d = e->Describe();
      if (!d.at_motion_stops || d.mean_terms.empty()) continue;
      if (out.count == kMaxStopEffects || d.mean_terms.size() > kMaxStopTerms)
        throw std::logic_error("diagnosis/model.cpp: raise kMaxStopEffects or kMaxStopTerms");
      StopEffect& s = out.list[out.count++];
      s.effect = e;
      s.count = d.mean_terms.size();
      std::copy(d.mean_terms.begin(), d.mean_terms.end(), s.terms);
    }
    return out;
  }();
  return all;
}

/// The true robot of `p` (model/true_robot.hpp: c_L, c_R of E_d) plus the
/// diagnosis' effects on wheel travel and heading, and the values of the
/// effects that move it after a stop (StopEffects, those PredictsStop).
struct TrueFactors {
  double c_L, c_R, scale, back, wheelbase, scrub;
  double kappa, swivel;  ///< heading kicks where motions start (model.hpp kParamKappa, kParamSwivel)
  struct Stop {
    const effects::Effect* effect;
    double v[kMaxStopTerms];
  };
  Stop stop[kMaxStopEffects];
  std::size_t stops = 0;  ///< of stop[]
};

TrueFactors Factors(const ParamVector& p, double wheelbase) {
  const double E_d = p[kParamEd];
  TrueFactors f{CorrectionLeft(E_d),    CorrectionRight(E_d),  1.0 + p[kParamScale], 1.0 + p[kParamAsym],
                p[kParamEb] * wheelbase, 1.0 - p[kParamScrub], p[kParamKappa],      p[kParamSwivel],
                {},                      0};
  const StopEffectList& se = StopEffects();
  for (std::size_t k = 0; k < se.count; ++k) {
    TrueFactors::Stop& s = f.stop[f.stops];
    s.effect = se.list[k].effect;
    for (std::size_t j = 0; j < se.list[k].count; ++j) s.v[j] = p[static_cast<std::size_t>(se.list[k].terms[j])];
    if (s.effect->PredictsStop(s.v)) ++f.stops;
  }
  return f;
}

}  // namespace

MeanModel::MeanModel(const CampaignData& campaign) : campaign_(campaign), run_time_(RunTimeEffects()) {
  observed_.resize(campaign.pieces.size());
  pieces_of_run_.resize(campaign.runs.size());
  for (std::size_t j = 0; j < campaign.pieces.size(); ++j) {
    const Piece& pc = campaign.pieces[j];
    const DiagRun& r = campaign.runs[pc.run];
    auto gt = [&](std::size_t i) { return r.gt[i]; };
    auto has = [&](std::size_t i) { return static_cast<bool>(r.has_gt[i]); };
    observed_[j] = Relative(MeanPose(pc.a_lo, pc.a_hi, gt, has), MeanPose(pc.b_lo, pc.b_hi, gt, has));
    pieces_of_run_[pc.run].push_back(static_cast<int>(j));
  }
}

namespace {

/// A run's own factors of the true left and right wheel: parameter_drift
/// of the right wheel and the run-time effects' PredictWheels (1, 1 without).
struct RunFactors {
  double left = 1.0, right = 1.0;
};

/// True wheel travel of a nominal step (dl, dr): diameters, scale,
/// backward asymmetry, the run's own factors (parameter_drift of the right
/// wheel; a left factor of 1 multiplies exactly).
inline void TrueTravel(const TrueFactors& f, const RunFactors& run, double dl, double dr, double& l, double& r) {
  l = dl * f.c_L * f.scale * run.left * (dl < 0.0 ? f.back : 1.0);
  r = dr * f.c_R * f.scale * run.right * (dr < 0.0 ? f.back : 1.0);
}

inline double HeadingFactor(const TrueFactors& f, signed char cls) {
  return cls == static_cast<signed char>(sim::MotionClass::kTurn) ? f.scrub : 1.0;
}

/// What follows stop `st` from pose q: the effects' coasts (Effect::
/// PredictStop) between tau0 and tau1 seconds after the wheels stopped, at
/// the true speeds the motion ended with.
Pose2 AfterStop(const DiagRun::Stop& st, const TrueFactors& f, const RunFactors& wheels, Pose2 q, double tau0,
                double tau1) {
  effects::StopMotion m;
  m.turn = st.cls == static_cast<signed char>(sim::MotionClass::kTurn);
  TrueTravel(f, wheels, st.rate_left, st.rate_right, m.vl, m.vr);
  m.wheelbase = f.wheelbase;
  for (std::size_t k = 0; k < f.stops; ++k) q = f.stop[k].effect->PredictStop(f.stop[k].v, m, q, tau0, tau1);
  return q;
}

/// The pose after fraction `u` in [0, 1] of interval i's time from `q`
/// (u = 1: the whole interval): a junction's two parts in turn (a swivel
/// kick between them), else the interval's one step within its active
/// window (after the castor kicks of its start, before the slide of its
/// stop).
Pose2 AdvanceInterval(const DiagRun& r, std::size_t i, const TrueFactors& f, const RunFactors& wheels, Pose2 q,
                      double u) {
  const double dl = r.left[i + 1] - r.left[i], dr = r.right[i + 1] - r.right[i];
  double l, rr;
  if (const int jx = r.junction_of.empty() ? -1 : r.junction_of[i]; jx >= 0) {
    const DiagRun::Junction& j = r.junctions[static_cast<std::size_t>(jx)];
    const double fa = j.time_fraction;
    const double ua = fa > 0.0 ? std::min(1.0, u / fa) : 1.0;
    TrueTravel(f, wheels, ua * j.left_m, ua * j.right_m, l, rr);
    q = TrueStep(q, l, rr, f.wheelbase, HeadingFactor(f, j.class_a));
    if (u <= fa) return q;
    if (!r.swivel.empty() && r.swivel[i] != 0) q.theta += f.swivel * r.swivel[i];
    const double ub = fa < 1.0 ? std::min(1.0, (u - fa) / (1.0 - fa)) : 1.0;
    TrueTravel(f, wheels, ub * (dl - j.left_m), ub * (dr - j.right_m), l, rr);
    return TrueStep(q, l, rr, f.wheelbase, HeadingFactor(f, j.class_b));
  }
  if (r.kick[i] != 0) q.theta += f.kappa * r.kick[i];
  if (!r.swivel.empty() && r.swivel[i] != 0) q.theta += f.swivel * r.swivel[i];
  const double w0 = r.window_start[i], w1 = r.window_end[i];
  const double frac = u >= 1.0 ? 1.0 : u <= w0 || w1 <= w0 ? 0.0 : std::min(1.0, (u - w0) / (w1 - w0));
  TrueTravel(f, wheels, frac * dl, frac * dr, l, rr);
  q = TrueStep(q, l, rr, f.wheelbase, HeadingFactor(f, r.interval_class[i]));
  if (f.stops == 0) return q;
  // A coast (Effect::PredictStop) from the wheels' stop (at the end of the
  // stop interval's active window) on into the still intervals after it.
  const double dt = r.t[i + 1] - r.t[i], t_now = r.t[i] + std::min(u, 1.0) * dt;
  if (const int stop = r.stop_of.empty() ? -1 : r.stop_of[i]; stop >= 0 && frac >= 1.0) {
    const DiagRun::Stop& st = r.stops[static_cast<std::size_t>(stop)];
    q = AfterStop(st, f, wheels, q, 0.0, t_now - st.t_stop);
  }
  if (const int coast = r.coast_of.empty() ? -1 : r.coast_of[i]; coast >= 0) {
    const DiagRun::Stop& st = r.stops[static_cast<std::size_t>(coast)];
    q = AfterStop(st, f, wheels, q, r.t[i] - st.t_stop, t_now - st.t_stop);
  }
  return q;
}

}  // namespace

void MeanModel::RunWheels(int run, const ParamVector& p, double& left, double& right) const {
  const DiagRun& r = campaign_.runs[run];
  left = 1.0;
  right = 1.0 + p[kParamDrift] * r.campaign_index;
  for (const RunTimeSlots& rt : run_time_)
    rt.effect->PredictWheels(&p[static_cast<std::size_t>(rt.first)], r.campaign_index, left, right);
}

void MeanModel::ReplayRun(int run, const ParamVector& p, std::vector<Pose2>& poses) const {
  const DiagRun& r = campaign_.runs[run];
  const TrueFactors f = Factors(p, campaign_.robot.wheelbase_m);
  RunFactors wheels;
  RunWheels(run, p, wheels.left, wheels.right);
  const std::size_t n = r.t.size();
  poses.resize(n);
  poses[0] = Pose2{};
  for (std::size_t i = 0; i + 1 < n; ++i) poses[i + 1] = AdvanceInterval(r, i, f, wheels, poses[i], 1.0);
}

Pose2 MeanModel::PoseAt(int run, const ParamVector& p, const std::vector<Pose2>& poses, double t) const {
  const DiagRun& r = campaign_.runs[run];
  const std::size_t n = r.t.size();
  if (t <= r.t.front()) return poses.front();
  if (t >= r.t.back()) return poses.back();
  const std::size_t i = static_cast<std::size_t>(std::upper_bound(r.t.begin(), r.t.end(), t) - r.t.begin()) - 1;
  if (i + 1 >= n) return poses.back();
  const double u = (t - r.t[i]) / (r.t[i + 1] - r.t[i]);
  // Before the wheels move in the interval nothing has happened, not even
  // the castor kick (checked first: most samples a clock scan reads lie in
  // standstills).
  const bool junction = !r.junction_of.empty() && r.junction_of[i] >= 0;
  if (!junction && (u <= r.window_start[i] || r.window_end[i] <= r.window_start[i])) return poses[i];
  const TrueFactors f = Factors(p, campaign_.robot.wheelbase_m);
  RunFactors wheels;
  RunWheels(run, p, wheels.left, wheels.right);
  return AdvanceInterval(r, i, f, wheels, poses[i], u);
}

std::vector<Pose2> MeanModel::PredictRun(int run, const ParamVector& p) const {
  std::vector<Pose2> poses;
  ReplayRun(run, p, poses);
  const DiagRun& r = campaign_.runs[run];
  std::vector<Pose2> out(poses.size());
  const double dx = p[kParamDx], dy = p[kParamDy], tau = p[kParamTau];
  for (std::size_t i = 0; i < poses.size(); ++i) {
    const Pose2 q = tau != 0.0 ? PoseAt(run, p, poses, r.t[i] - tau) : poses[i];
    const double c = std::cos(q.theta), s = std::sin(q.theta);
    out[i] = {q.x + c * dx - s * dy, q.y + s * dx + c * dy, q.theta};
  }
  return out;
}

std::vector<Pose2> MeanModel::PredictedPieceMotion(const ParamVector& p) const {
  std::vector<Pose2> out(campaign_.pieces.size());
  std::vector<Pose2> poses;
  const double dx = p[kParamDx], dy = p[kParamDy], tau = p[kParamTau];
  for (std::size_t run = 0; run < campaign_.runs.size(); ++run) {
    if (pieces_of_run_[run].empty()) continue;
    ReplayRun(static_cast<int>(run), p, poses);
    const DiagRun& r = campaign_.runs[run];
    auto predicted = [&](std::size_t i) {
      const Pose2 q = tau != 0.0 ? PoseAt(static_cast<int>(run), p, poses, r.t[i] - tau) : poses[i];
      const double c = std::cos(q.theta), s = std::sin(q.theta);
      return Pose2{q.x + c * dx - s * dy, q.y + s * dx + c * dy, q.theta};
    };
    auto has = [&](std::size_t i) { return static_cast<bool>(r.has_gt[i]); };
    for (int j : pieces_of_run_[run]) {
      const Piece& pc = campaign_.pieces[j];
      out[j] = Relative(MeanPose(pc.a_lo, pc.a_hi, predicted, has), MeanPose(pc.b_lo, pc.b_hi, predicted, has));
    }
  }
  return out;
}

void MeanModel::ResidualsAtClocks(const ParamVector& p, const std::vector<double>& taus,
                                  std::vector<std::vector<double>>& eps) const {
  const std::size_t np = campaign_.pieces.size();
  eps.assign(taus.size(), std::vector<double>(3 * np, 0.0));
  // Pieces of no run keep the predicted motion Pose2{} (PredictedPieceMotion).
  for (std::vector<double>& e : eps)
    for (std::size_t j = 0; j < np; ++j) {
      e[3 * j] = observed_[j].x;
      e[3 * j + 1] = observed_[j].y;
      e[3 * j + 2] = WrapAngle(observed_[j].theta);
    }
  std::vector<Pose2> poses;
  const double dx = p[kParamDx], dy = p[kParamDy];
  for (std::size_t run = 0; run < campaign_.runs.size(); ++run) {
    if (pieces_of_run_[run].empty()) continue;
    ReplayRun(static_cast<int>(run), p, poses);
    const DiagRun& r = campaign_.runs[run];
    auto has = [&](std::size_t i) { return static_cast<bool>(r.has_gt[i]); };
    for (std::size_t k = 0; k < taus.size(); ++k) {
      const double tau = taus[k];
      auto predicted = [&](std::size_t i) {
        const Pose2 q = tau != 0.0 ? PoseAt(static_cast<int>(run), p, poses, r.t[i] - tau) : poses[i];
        const double c = std::cos(q.theta), s = std::sin(q.theta);
        return Pose2{q.x + c * dx - s * dy, q.y + s * dx + c * dy, q.theta};
      };
      for (int j : pieces_of_run_[run]) {
        const Piece& pc = campaign_.pieces[j];
        const Pose2 pred = Relative(MeanPose(pc.a_lo, pc.a_hi, predicted, has), MeanPose(pc.b_lo, pc.b_hi, predicted, has));
        const auto J = static_cast<std::size_t>(3 * j);
        eps[k][J] = observed_[j].x - pred.x;
        eps[k][J + 1] = observed_[j].y - pred.y;
        eps[k][J + 2] = WrapAngle(observed_[j].theta - pred.theta);
      }
    }
  }
}

void MeanModel::Residuals(const ParamVector& p, std::vector<double>& eps) const {
  const std::vector<Pose2> pred = PredictedPieceMotion(p);
  eps.resize(3 * pred.size());
  for (std::size_t j = 0; j < pred.size(); ++j) {
    eps[3 * j] = observed_[j].x - pred[j].x;
    eps[3 * j + 1] = observed_[j].y - pred[j].y;
    eps[3 * j + 2] = WrapAngle(observed_[j].theta - pred[j].theta);
  }
}

Eigen::MatrixXd MeanModel::Jacobian(const ParamVector& p, const std::vector<int>& params,
                                    const std::vector<double>& eps0) const {
  static const double kStep[kParamRunTime0] = {1e-6, 1e-6, 1e-6, 1e-6, 1e-6, 1e-7, 1e-8,
                                               1e-6, 1e-6, 1e-5, 1e-7, 1e-5, 1e-5, 1e-5, 1e-5};
  Eigen::MatrixXd J(eps0.size(), params.size());
  std::vector<double> eps;
  for (std::size_t k = 0; k < params.size(); ++k) {
    ParamVector q = p;
    // A run-time effect's parameter: 1e-4 of its typical size (1e-6
    // without one).
    double h = 1e-6;
    if (params[k] < kParamRunTime0) {
      h = kStep[params[k]];
    } else {
      for (const RunTimeSlots& rt : run_time_)
        if (params[k] >= rt.first && params[k] < rt.first + rt.count) {
          const double typical = rt.effect->Parameters()[static_cast<std::size_t>(params[k] - rt.first)].typical;
          if (typical > 0.0) h = 1e-4 * typical;
        }
    }
    q[params[k]] += h;
    Residuals(q, eps);
    for (std::size_t i = 0; i < eps.size(); ++i) J(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = (eps[i] - eps0[i]) / h;
  }
  return J;
}

namespace {

/// One encoder interval of a piece as an exact arc from `q` (local frame of
/// the piece start): true wheel travel l, r [m] and the heading's
/// wheelbase b (E_b b, divided by 1 - k in spot turns).
struct ArcStep {
  Pose2 next;
  /// d(next position, heading) / d(l, r): the wheel-noise lever G_u.
  Eigen::Matrix<double, 3, 2> G;
};

ArcStep StepWithJacobian(const Pose2& q, double l, double rr, double b) {
  const double ds = 0.5 * (l + rr), dtheta = (rr - l) / b, h = 0.5 * dtheta;
  const double sinc = Sinc(h);
  // d sinc / d h, stable near 0 (-h/3 + h^3/30).
  const double dsinc = std::abs(h) < 1e-4 ? -h / 3.0 + h * h * h / 30.0 : (h * std::cos(h) - std::sin(h)) / (h * h);
  const double chord = ds * sinc;
  const double hd = q.theta + h, ch = std::cos(hd), sh = std::sin(hd);
  // d(chord)/dl, d(chord)/dr and d(heading)/dl, dr (heading = theta + h).
  const double dchord_dl = 0.5 * sinc - ds * dsinc / (2.0 * b);
  const double dchord_dr = 0.5 * sinc + ds * dsinc / (2.0 * b);
  const double dh_dl = -1.0 / (2.0 * b), dh_dr = 1.0 / (2.0 * b);
  ArcStep out;
  out.G << dchord_dl * ch - chord * sh * dh_dl, dchord_dr * ch - chord * sh * dh_dr,  //
      dchord_dl * sh + chord * ch * dh_dl, dchord_dr * sh + chord * ch * dh_dr,      //
      -1.0 / b, 1.0 / b;
  out.next = TrueStep(q, l, rr, b, 1.0);
  return out;
}

/// Kelly's recursion over a piece's intervals (see model.hpp): the wheel
/// noise bases and the quantisation levers at the piece's first and last
/// moving interval.
struct PiecePropagation {
  Eigen::Matrix3d P_L = Eigen::Matrix3d::Zero(), P_R = Eigen::Matrix3d::Zero(), P_LR = Eigen::Matrix3d::Zero();
  Eigen::Matrix<double, 3, 2> M_start = Eigen::Matrix<double, 3, 2>::Zero();  ///< first moving G, carried to the end
  Eigen::Matrix<double, 3, 2> G_last = Eigen::Matrix<double, 3, 2>::Zero();   ///< last moving G
  bool moved = false;
  double travel_left_m = 0.0, travel_right_m = 0.0;
};

/// Wheel geometry of the bases at `p`: heading (r - l) / b, with b divided
/// by 1 - k in spot turns (turn_scrub scales the wheel noise's heading
/// effect there too).
struct BasesGeometry {
  double b_plain, b_turn, c_L, c_R;
};

BasesGeometry Geometry(const CampaignData& campaign, const ParamVector& p) {
  const double b_plain = campaign.robot.wheelbase_m * p[kParamEb];
  return {b_plain, b_plain / (1.0 - p[kParamScrub]), CorrectionLeft(p[kParamEd]), CorrectionRight(p[kParamEd])};
}

PiecePropagation Propagate(const DiagRun& r, const Piece& pc, const BasesGeometry& g) {
  PiecePropagation out;
  Pose2 q;  // local frame of the piece start
  for (std::size_t i = pc.a; i < pc.b; ++i) {
    const double b = r.interval_class[i] == static_cast<signed char>(sim::MotionClass::kTurn) ? g.b_turn : g.b_plain;
    const double l = (r.left[i + 1] - r.left[i]) * g.c_L, rr = (r.right[i + 1] - r.right[i]) * g.c_R;
    const ArcStep step = StepWithJacobian(q, l, rr, b);
    const Eigen::Matrix<double, 3, 2>& G = step.G;
    Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
    F(0, 2) = -(step.next.y - q.y);
    F(1, 2) = step.next.x - q.x;
    const double al = std::abs(l), ar = std::abs(rr);
    out.P_L = F * out.P_L * F.transpose() + al * G.col(0) * G.col(0).transpose();
    out.P_R = F * out.P_R * F.transpose() + ar * G.col(1) * G.col(1).transpose();
    out.P_LR = F * out.P_LR * F.transpose() +
               std::sqrt(al * ar) * (G.col(0) * G.col(1).transpose() + G.col(1) * G.col(0).transpose());
    out.M_start = F * out.M_start;
    if (al + ar > 0.0) {
      if (!out.moved) {
        out.M_start = G;
        out.moved = true;
      }
      out.G_last = G;
    }
    out.travel_left_m += al;
    out.travel_right_m += ar;
    q = step.next;
  }
  return out;
}

/// Encoder quantisation (Q and its levers) and the start / stop slip basis
/// F of a piece that moved on a logged run.
void QuantisationAndSlip(const DiagRun& r, const Piece& pc, const PiecePropagation& pp, PieceBases& B) {
  if (!pp.moved || r.endpoint) return;
  B.quant_start = pp.M_start;
  B.quant_end = pp.G_last;
  // A wheel that did not turn in the piece has the same count error at
  // both ends: it cancels.
  const double va[2] = {std::pow(r.q_sd_left[pc.a], 2), std::pow(r.q_sd_right[pc.a], 2)};
  const double vb[2] = {std::pow(r.q_sd_left[pc.b], 2), std::pow(r.q_sd_right[pc.b], 2)};
  const bool turned[2] = {B.travel_left_m > 0.0, B.travel_right_m > 0.0};
  for (int w = 0; w < 2; ++w) {
    if (!turned[w]) continue;
    B.Q += va[w] * pp.M_start.col(w) * pp.M_start.col(w).transpose() +
           vb[w] * pp.G_last.col(w) * pp.G_last.col(w).transpose();
  }
  // The two wheels' count errors at a joint stop are correlated under the
  // body stop reading (stop_model.hpp).
  if (turned[0] && turned[1]) {
    const double ca = r.q_cov_lr[pc.a], cb = r.q_cov_lr[pc.b];
    B.Q += ca * (pp.M_start.col(0) * pp.M_start.col(1).transpose() + pp.M_start.col(1) * pp.M_start.col(0).transpose()) +
           cb * (pp.G_last.col(0) * pp.G_last.col(1).transpose() + pp.G_last.col(1) * pp.G_last.col(0).transpose());
  }
  if (pc.starts_from_standstill) B.F += 0.5 * pp.M_start * pp.M_start.transpose();
  if (pc.ends_at_standstill) B.F += 0.5 * pp.G_last * pp.G_last.transpose();
}

/// run_time_offset's levers: d eps / d tau on either side of p's tau, as
/// secants over one ground-truth sample interval h (the median over the
/// campaign). The pose is not smooth in time where a motion starts or stops
/// (a lag shows the motion, a lead the standstill), and the samples next to
/// such a boundary respond to tau only once |tau| exceeds their distance to
/// it, which lies anywhere within one interval: a derivative at tau = 0
/// (1 ms) is zero there, the secant over h carries the onset. With tau_i
/// symmetric about 0 the second moment is tau_sd^2 (J+ J+^T + J- J-^T) / 2.
/// Median interval between ground-truth samples of the logged runs [s]
/// (1 ms without any).
double SampleInterval(const CampaignData& c) {
  std::vector<double> dt;
  for (const DiagRun& r : c.runs)
    for (std::size_t i = 1; i < r.t.size(); ++i)
      if (r.has_gt[i] && r.has_gt[i - 1] && r.t[i] > r.t[i - 1]) dt.push_back(r.t[i] - r.t[i - 1]);
  if (dt.empty()) return 1e-3;
  std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
  return std::max(dt[dt.size() / 2], 1e-3);
}

class TimeOffsetLevers {
 public:
  TimeOffsetLevers(const MeanModel& model, const ParamVector& p, double step) : step_(step) {
    model.Residuals(p, eps0_);
    ParamVector pt = p;
    pt[kParamTau] = p[kParamTau] + step_;
    model.Residuals(pt, plus_);
    pt[kParamTau] = p[kParamTau] - step_;
    model.Residuals(pt, minus_);
  }

  /// T and the levers of piece j (zero when a difference is not finite).
  void Set(std::size_t j, PieceBases& B) const {
    Eigen::Vector3d jp, jm;
    for (int k = 0; k < 3; ++k) {
      jp[k] = (plus_[3 * j + k] - eps0_[3 * j + k]) / step_;
      jm[k] = (eps0_[3 * j + k] - minus_[3 * j + k]) / step_;
    }
    if (!(jp.allFinite() && jm.allFinite())) return;
    B.T = 0.5 * (jp * jp.transpose() + jm * jm.transpose());
    B.tau_lever_pos = jp;
    B.tau_lever_neg = jm;
  }

 private:
  double step_;
  std::vector<double> eps0_, plus_, minus_;
};

/// Ground-truth noise at both ends of a piece with predicted motion `motion`,
/// each end averaged over its samples.
void GroundTruthBases(const Piece& pc, const Pose2& motion, PieceBases& B) {
  const double wa = pc.a_weight, wb = pc.b_weight;
  B.G_xy = Eigen::Vector3d(wa + wb, wa + wb, 0.0).asDiagonal();
  const Eigen::Vector3d jv(motion.y, -motion.x, -1.0);
  B.G_theta = wa * jv * jv.transpose();
  B.G_theta(2, 2) += wb;
}

}  // namespace

std::vector<PieceBases> ComputeBases(const CampaignData& campaign, const MeanModel& model, const ParamVector& p) {
  std::vector<PieceBases> out(campaign.pieces.size());
  const std::vector<Pose2> motion = model.PredictedPieceMotion(p);
  const BasesGeometry geometry = Geometry(campaign, p);
  const TimeOffsetLevers tau(model, p, SampleInterval(campaign));
  for (std::size_t j = 0; j < campaign.pieces.size(); ++j) {
    const Piece& pc = campaign.pieces[j];
    const DiagRun& r = campaign.runs[pc.run];
    PieceBases& B = out[j];
    const PiecePropagation pp = Propagate(r, pc, geometry);
    B.A_L = pp.P_L;
    B.A_R = pp.P_R;
    B.A_LR = pp.P_LR;
    B.travel_left_m = pp.travel_left_m;
    B.travel_right_m = pp.travel_right_m;
    QuantisationAndSlip(r, pc, pp, B);
    if (pc.ends_at_standstill) {
      B.S_xy = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
      B.S_theta(2, 2) = 1.0;
    }
    tau.Set(j, B);
    GroundTruthBases(pc, motion[j], B);
    for (std::size_t i = pc.a; i < pc.b && i < r.reversal.size(); ++i)
      if (r.reversal[i]) {
        const Eigen::Vector3d v(-motion[j].y, motion[j].x, 1.0);
        B.K = v * v.transpose();
        break;
      }
    for (std::size_t i = pc.a; i < pc.b && i < r.first_start.size(); ++i)
      if (r.first_start[i]) {
        const Eigen::Vector3d v(-motion[j].y, motion[j].x, 1.0);
        B.P = v * v.transpose();
        B.P_xy = Eigen::Vector3d(1.0, 1.0, 0.0).asDiagonal();
        break;
      }
    for (std::size_t i = pc.a; i < pc.b && i < r.swivel.size(); ++i)
      if (r.swivel[i] != 0) {
        const Eigen::Vector3d v(-motion[j].y, motion[j].x, 1.0);
        B.P_turn = v * v.transpose();
        break;
      }
  }
  return out;
}

void SetTimeOffsetLevers(const MeanModel& model, const ParamVector& p, double step, std::vector<PieceBases>& bases) {
  const TimeOffsetLevers tau(model, p, std::max(step, 1e-3));
  for (std::size_t j = 0; j < bases.size(); ++j) tau.Set(j, bases[j]);
}

}  // namespace umbmark::diag
