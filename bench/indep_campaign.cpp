// Independent campaign generator for the blind benchmark of `umbmark
// diagnose`: a second simulator, written from the contract's effect
// definitions (docs/formats.md) with NONE of lib/simulation or lib/model,
// and with a different controller than `umbmark simulate`, so the benchmark
// does not share the diagnosis' own assumptions.
//
// What differs from `umbmark simulate` (lib/simulation/campaign_run.cpp):
//   - a closed-loop controller on the robot's own odometry (nominal
//     parameters, encoder ticks): legs and spot turns end when the ODOMETRY
//     says the target is reached, not at a tick count of commanded travel;
//   - acceleration limits (trapezoidal speed profile, `--accel`, 0 = none);
//   - optional heading hold in the legs (`--heading-hold K`, 1/s: the
//     controller steers against the odometry's heading error, so legs are
//     gentle S-curves in wheel travel);
//   - a fixed 1 kHz physics step with the wheel noise drawn per step,
//     independent of the sample rate;
//   - its own random streams (std::mt19937_64, one per campaign);
//   - optionally free paths (`--free N` runs, experiment kind `free`): curved
//     paths made of stretches that start from and end at standstill, each
//     stretch two or three arcs of different curvature driven back to back
//     in one direction (forward or backward), ended on the odometry's path
//     length, with a stop of at least 0.5 s between stretches.
//
// Writes DIR/campaign.toml, DIR/square.csv, DIR/fwd_back.csv (and
// DIR/free.csv with --free) (trajectory CSVs with ticks and ground truth,
// formats.md) and DIR/../truth.json beside the campaign (never inside it).
//
// Usage: indep_campaign --out DIR --seed S [--effect NAME:k=v,...]
//   [--rate HZ] [--ticks N] [--pause S] [--accel A] [--heading-hold K] [--free N]
//   [--side M] [--distance M] [--speed V] [--turn-rate W] [--kl K] [--kr K]
//   [--E-d X] [--E-b X] [--gt-sigma-xy M] [--gt-sigma-theta R]
//   [--wheelbase M] [--diameter M] [--settle S] [--square-runs N] [--fwd-back-runs M]
// Effects (contract names, same parameters; --effect may be repeated to
// combine them): scale_error:s, direction_asymmetry:a, castor_kick:kappa,
// gt_offset:dx,dy, time_offset:tau, bump_outliers:rate,sigma,
// standstill_motion:sigma_xy,sigma_theta, run_time_offset:tau_sd,
// stop_slide:d,a, castor_swivel:kappa, and
// outside the contract gt_yaw_misalignment:delta, floor_slope:g,dir.
// The last three contract effects draw from a second random stream (seed
// S xor a constant), so that adding them leaves every other draw, and a
// campaign without them, exactly as before.
//   bump_outliers: per wheel the travel to the next bump is exponential with
//     mean 1/rate metres of |true travel|; a bump adds N(0, sigma^2) m to
//     that wheel's true travel in that 1 ms step.
//   standstill_motion: at every standstill that follows a motion (a pause
//     of at least one physics step), the robot settles: the true pose moves
//     by N(0, sigma_xy^2) along each robot axis and N(0, sigma_theta^2) in
//     heading, spread evenly over the first `--settle` seconds of the
//     standstill (default 0.1 s; all of it when shorter; 0.001 = one
//     physics step, at once as the robot stops) while the wheels, and so
//     the encoders, stand.
//   run_time_offset: per run tau_i ~ N(0, tau_sd^2), ground truth stamped t
//     shows the true pose at t - tau - tau_i.
//   stop_slide (d, a): at a standstill after a leg or stretch that ended at
//     true speed v (the last physics step's), the chassis coasts on along
//     its heading, decelerating uniformly at 1/(2 d) m/s^2 until it has
//     covered d v^2 (it takes 2 d |v| s); after a spot turn that ended at
//     true rate w it turns on at 1/(2 a) rad/s^2 by a w^2. The wheels, and
//     so the encoders, stand meanwhile. (Written from the contract's
//     definition; `umbmark simulate` moves the pose at once instead.)
//   castor_swivel (kappa): a leg or stretch right after a spot turn starts
//     with a heading jump of kappa times the turn's sign (ccw +1, cw -1);
//     one that reverses the drive direction of the leg or stretch before it
//     (no turn between) jumps by +kappa or -kappa, equally likely, drawn
//     from a third stream (seed S xor another constant).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace {

constexpr double kPi = 3.14159265358979323846;

double Wrap(double a) { return std::remainder(a, 2.0 * kPi); }

struct Options {
  std::string out;
  std::uint64_t seed = 1;
  std::map<std::string, std::map<std::string, double>> effects;
  double rate_hz = 20.0, ticks = 4096.0, pause_s = 1.0, accel = 0.0, heading_hold = 0.0, free_runs = 0.0;
  double square_runs = 10.0, fwd_back_runs = 20.0;  ///< squares per direction; back-and-forth runs (0: none)
  double settle_s = 0.1;  ///< standstill_motion: how long the robot settles [s]
  double side_m = 3.0, distance_m = 3.0, speed = 0.3, turn_rate = 1.0;
  double k_L = 1e-3, k_R = 1e-3, E_d = 1.0, E_b = 1.0, gt_xy = 3e-4, gt_th = 1e-3;
  double wheelbase = 0.4, diameter = 0.1;
};

double Effect(const Options& o, const char* name, const char* key, double fallback = 0.0) {
  const auto e = o.effects.find(name);
  if (e == o.effects.end()) return fallback;
  const auto k = e->second.find(key);
  return k == e->second.end() ? fallback : k->second;
}

/// One sample written to the CSV.
struct Sample {
  double t, ticks_L, ticks_R, x, y, th;
};

/// A robot with its true geometry, its encoders, its odometry (nominal
/// geometry) and a 1 kHz clock.
class Robot {
 public:
  Robot(const Options& o, std::mt19937_64& g, std::mt19937_64& gx, std::mt19937_64& gs)
      : o_(o), g_(g), gx_(gx), gs_(gs) {
    // Contract (formats.md): D_R / D_L = E_d, D_L + D_R = 2 D (eqs. 4.31-4.32).
    const double s = 1.0 + Effect(o, "scale_error", "s");
    dl_true_ = 2.0 / (o.E_d + 1.0) * o.diameter * s;
    dr_true_ = 2.0 / (1.0 / o.E_d + 1.0) * o.diameter * s;
    b_true_ = o.E_b * o.wheelbase;
    std::uniform_real_distribution<double> u(0.0, 1.0);
    phase_L_ = u(g);
    phase_R_ = u(g);
    // Second stream: only the effects that came after the first nine draw
    // from it, and only when present.
    if (const double sd = Effect(o, "run_time_offset", "tau_sd"); sd > 0.0)
      tau_run_ = std::normal_distribution<double>(0.0, sd)(gx_);
    if (const double rate = Effect(o, "bump_outliers", "rate"); rate > 0.0) {
      std::exponential_distribution<double> gap(rate);
      next_bump_ = {gap(gx_), gap(gx_)};
    }
  }

  /// Drives one primitive: a leg of `distance` (signed) or a spot turn of
  /// `angle` (signed), ending on the odometry; from standstill when
  /// `from_rest`.
  void Leg(double distance, bool from_rest) {
    if (from_rest) {
      // castor_kick: every start from standstill, + forward, - backward.
      th_ += (distance > 0 ? 1.0 : -1.0) * Effect(o_, "castor_kick", "kappa");
    }
    Swivel(distance > 0 ? 1 : -1);
    const double x0 = ox_, y0 = oy_, th_ref = oth_, dir = distance > 0 ? 1.0 : -1.0;
    double v = 0.0;
    for (int guard = 0; guard < 10'000'000; ++guard) {
      const double done = (ox_ - x0) * std::cos(th_ref) + (oy_ - y0) * std::sin(th_ref);
      const double left = std::abs(distance) - dir * done;
      if (left <= 0.0) break;
      v = Profile(v, left, o_.speed, 0.01);
      const double w = o_.heading_hold > 0.0 ? -o_.heading_hold * Wrap(oth_ - th_ref) : 0.0;
      Step(dir * v, w);
    }
  }
  void Turn(double angle) {
    const double th0 = oth_, dir = angle > 0 ? 1.0 : -1.0;
    turn_sign_ = angle > 0 ? 1 : -1;
    double w = 0.0;
    for (int guard = 0; guard < 10'000'000; ++guard) {
      const double left = std::abs(angle) - dir * (oth_ - th0);
      if (left <= 0.0) break;
      w = Profile(w, left, o_.turn_rate, 0.02);
      Step(0.0, dir * w);
    }
  }
  /// Drives one stretch of a free path from standstill to standstill: arcs
  /// (path length [m] > 0, curvature [1/m]) back to back, forward (dir = +1)
  /// or backward (-1), each ended when the odometry's path length reaches
  /// its length; the speed profile brakes only for the stretch's end.
  void Stretch(const std::vector<std::array<double, 2>>& arcs, double dir) {
    // castor_kick: a start from standstill, + forward, - backward (an arc
    // drives forward or backward like a leg: the sign of the axle speed).
    th_ += dir * Effect(o_, "castor_kick", "kappa");
    Swivel(dir > 0 ? 1 : -1);
    double total = 0.0;
    for (const auto& a : arcs) total += a[0];
    double v = 0.0, done_before = 0.0;
    for (const auto& a : arcs) {
      double done = 0.0;
      for (int guard = 0; guard < 10'000'000 && done < a[0]; ++guard) {
        v = Profile(v, total - done_before - done, o_.speed, 0.01);
        const double x0 = ox_, y0 = oy_;
        Step(dir * v, dir * v * a[1]);
        done += std::hypot(ox_ - x0, oy_ - y0);
      }
      done_before += done;
    }
  }
  void Pause(double seconds) {
    const int steps = static_cast<int>(std::lround(seconds / kDt));
    // standstill_motion: a standstill after a motion; the settling is spread
    // over its first o_.settle_s (robot frame at the stop: x along, y left).
    std::array<double, 3> settle{0.0, 0.0, 0.0};
    const double sxy = Effect(o_, "standstill_motion", "sigma_xy"), sth = Effect(o_, "standstill_motion", "sigma_theta");
    const int settle_steps = std::clamp(static_cast<int>(std::lround(o_.settle_s / kDt)), 1, std::max(steps, 1));
    if (moved_ && steps > 0 && (sxy > 0.0 || sth > 0.0)) {
      std::normal_distribution<double> n01(0.0, 1.0);
      const double along = sxy * n01(gx_), across = sxy * n01(gx_), turn = sth * n01(gx_);
      settle = {(along * std::cos(th_) - across * std::sin(th_)) / settle_steps,
                (along * std::sin(th_) + across * std::cos(th_)) / settle_steps, turn / settle_steps};
    }
    // stop_slide: the coast's deceleration (0: none) from the speed the
    // motion ended with.
    const double d = Effect(o_, "stop_slide", "d"), a = Effect(o_, "stop_slide", "a");
    double v = moved_ && steps > 0 && d > 0.0 ? last_v_ : 0.0, w = moved_ && steps > 0 && a > 0.0 ? last_w_ : 0.0;
    if (steps > 0) moved_ = false;
    for (int i = 0; i < steps; ++i) {
      if (i < settle_steps) {
        x_ += settle[0];
        y_ += settle[1];
        th_ += settle[2];
      }
      // Uniform deceleration, exact over the step: distance v dt - dec dt^2 / 2
      // (or what is left of the coast when it ends within the step).
      if (v != 0.0) {
        const double dec = 1.0 / (2.0 * d), t_left = std::min(kDt, std::abs(v) / dec);
        const double ds = (std::abs(v) * t_left - 0.5 * dec * t_left * t_left) * (v > 0 ? 1.0 : -1.0);
        x_ += ds * std::cos(th_);
        y_ += ds * std::sin(th_);
        v = std::abs(v) <= dec * kDt ? 0.0 : v - (v > 0 ? 1.0 : -1.0) * dec * kDt;
      }
      if (w != 0.0) {
        const double dec = 1.0 / (2.0 * a), t_left = std::min(kDt, std::abs(w) / dec);
        th_ += (std::abs(w) * t_left - 0.5 * dec * t_left * t_left) * (w > 0 ? 1.0 : -1.0);
        w = std::abs(w) <= dec * kDt ? 0.0 : w - (w > 0 ? 1.0 : -1.0) * dec * kDt;
      }
      Step(0.0, 0.0);
    }
  }

  /// The run's samples with their ground truth (after the run, so that a
  /// negative time offset can show poses ahead of the stamp).
  std::vector<Sample> Finish() {
    for (Sample& s : samples_) GroundTruth(s);
    return samples_;
  }

 private:
  static constexpr double kDt = 1e-3;

  /// castor_swivel at the start of a leg or stretch driving in direction
  /// `dir` (+1 forward, -1 backward).
  void Swivel(int dir) {
    const double kappa = Effect(o_, "castor_swivel", "kappa");
    if (kappa != 0.0) {
      if (turn_sign_ != 0)
        th_ += turn_sign_ * kappa;
      else if (drive_dir_ != 0 && dir != drive_dir_)
        th_ += (std::uniform_real_distribution<double>(0.0, 1.0)(gs_) < 0.5 ? -1.0 : 1.0) * kappa;
    }
    turn_sign_ = 0;
    drive_dir_ = dir;
  }

  /// Next speed: accelerate at most `accel` (none when 0), and brake so
  /// that the remaining distance is covered; at least `creep` to finish.
  double Profile(double current, double left, double top, double creep) const {
    if (!(o_.accel > 0.0)) return top;
    const double brake = std::sqrt(2.0 * o_.accel * left);
    return std::max(creep, std::min({top, current + o_.accel * kDt, brake}));
  }

  /// One physics step with commanded body speed v and turn rate w (the
  /// controller converts them to wheel rotation with the NOMINAL geometry;
  /// the wheels follow the commanded rotation exactly).
  void Step(double v, double w) {
    const double r = 0.5 * o_.diameter;
    const double dphi_L = (v - 0.5 * o_.wheelbase * w) / r * kDt, dphi_R = (v + 0.5 * o_.wheelbase * w) / r * kDt;
    phi_L_ += dphi_L;
    phi_R_ += dphi_R;
    // Ground travel: true diameters, direction_asymmetry backwards, noise
    // N(0, k^2 |travel|) per wheel (Chong & Kleeman).
    const double a = Effect(o_, "direction_asymmetry", "a");
    double sL = dphi_L * 0.5 * dl_true_ * (dphi_L < 0 ? 1.0 + a : 1.0);
    double sR = dphi_R * 0.5 * dr_true_ * (dphi_R < 0 ? 1.0 + a : 1.0);
    std::normal_distribution<double> n01(0.0, 1.0);
    sL += o_.k_L * std::sqrt(std::abs(sL)) * n01(g_);
    sR += o_.k_R * std::sqrt(std::abs(sR)) * n01(g_);
    Bump(0, sL);
    Bump(1, sR);
    if (v != 0.0 || w != 0.0) moved_ = true;
    const double ds = 0.5 * (sL + sR), dth = (sR - sL) / b_true_;
    if (v != 0.0 || w != 0.0) {
      last_v_ = ds / kDt;
      last_w_ = dth / kDt;
    }
    x_ += ds * std::cos(th_ + 0.5 * dth);
    y_ += ds * std::sin(th_ + 0.5 * dth);
    th_ += dth;
    // floor_slope (outside): slides g per metre of travel towards dir.
    const double g = Effect(o_, "floor_slope", "g"), gdir = Effect(o_, "floor_slope", "dir");
    x_ += g * std::abs(ds) * std::cos(gdir);
    y_ += g * std::abs(ds) * std::sin(gdir);
    // Encoders and the controller's odometry (nominal geometry).
    const double tL = std::floor(phi_L_ / (2.0 * kPi) * o_.ticks + phase_L_);
    const double tR = std::floor(phi_R_ / (2.0 * kPi) * o_.ticks + phase_R_);
    const double per_tick = kPi * o_.diameter / o_.ticks;
    const double oL = (tL - ticks_L_) * per_tick, oR = (tR - ticks_R_) * per_tick;
    const double ods = 0.5 * (oL + oR), odth = (oR - oL) / o_.wheelbase;
    ox_ += ods * std::cos(oth_ + 0.5 * odth);
    oy_ += ods * std::sin(oth_ + 0.5 * odth);
    oth_ += odth;
    ticks_L_ = tL;
    ticks_R_ = tR;
    t_ += kDt;
    history_.push_back({t_, x_, y_, th_});
    if (t_ + 1e-9 >= next_sample_) {
      next_sample_ += 1.0 / o_.rate_hz;
      samples_.push_back({t_, ticks_L_, ticks_R_, 0.0, 0.0, 0.0});
    }
  }

  /// bump_outliers on wheel `i` (0 left, 1 right) with true travel `s` in
  /// this step: a bump when the wheel's |travel| passes the next bump's
  /// distance (a Poisson process in travel, `rate` per metre).
  void Bump(int i, double& s) {
    const double rate = Effect(o_, "bump_outliers", "rate"), sigma = Effect(o_, "bump_outliers", "sigma");
    if (!(rate > 0.0 && sigma > 0.0)) return;
    next_bump_[i] -= std::abs(s);
    std::exponential_distribution<double> gap(rate);
    std::normal_distribution<double> bump(0.0, sigma);
    for (; next_bump_[i] <= 0.0; next_bump_[i] += gap(gx_)) s += bump(gx_);
  }

  /// The ground truth of the sample stamped s.t as the effects report it,
  /// plus the motion capture's noise.
  void GroundTruth(Sample& out) {
    // time_offset: the true pose at t - tau (the start pose before the run,
    // the end pose after it), to the 1 ms physics step.
    // run_time_offset adds this run's tau_i.
    const double tq = out.t - Effect(o_, "time_offset", "tau") - tau_run_;
    std::size_t i = 0;
    if (tq > history_.front()[0])
      i = std::min(static_cast<std::size_t>(std::lround((tq - history_.front()[0]) / kDt)), history_.size() - 1);
    const auto& h = history_[i];
    std::normal_distribution<double> n01(0.0, 1.0);
    const double dx = Effect(o_, "gt_offset", "dx"), dy = Effect(o_, "gt_offset", "dy");
    const double c = std::cos(h[3]), s = std::sin(h[3]);
    out.x = h[1] + c * dx - s * dy + o_.gt_xy * n01(g_);
    out.y = h[2] + s * dx + c * dy + o_.gt_xy * n01(g_);
    out.th = h[3] + Effect(o_, "gt_yaw_misalignment", "delta") + o_.gt_th * n01(g_);
  }

  const Options& o_;
  std::mt19937_64& g_;
  std::mt19937_64& gx_;  ///< second stream: bump_outliers, standstill_motion, run_time_offset
  std::mt19937_64& gs_;  ///< third stream: castor_swivel's signs after reversals
  bool moved_ = false;   ///< a motion since the last standstill (standstill_motion)
  double last_v_ = 0.0, last_w_ = 0.0;  ///< true speed and turn rate of the last moving step (stop_slide)
  int turn_sign_ = 0, drive_dir_ = 0;   ///< castor_swivel: the last spot turn since a leg; the last leg's direction
  double tau_run_ = 0.0;
  std::array<double, 2> next_bump_{0.0, 0.0};
  double dl_true_, dr_true_, b_true_, phase_L_ = 0.0, phase_R_ = 0.0;
  double x_ = 0.0, y_ = 0.0, th_ = 0.0, phi_L_ = 0.0, phi_R_ = 0.0;
  double ox_ = 0.0, oy_ = 0.0, oth_ = 0.0, ticks_L_ = 0.0, ticks_R_ = 0.0;
  double t_ = 0.0, next_sample_ = 0.0;
  std::vector<std::array<double, 4>> history_;
  std::vector<Sample> samples_;
};

Options Parse(int argc, char** argv) {
  Options o;
  std::map<std::string, double*> num = {
      {"--rate", &o.rate_hz},     {"--ticks", &o.ticks},       {"--pause", &o.pause_s},
      {"--accel", &o.accel},      {"--heading-hold", &o.heading_hold}, {"--side", &o.side_m},
      {"--distance", &o.distance_m}, {"--speed", &o.speed},    {"--turn-rate", &o.turn_rate},
      {"--kl", &o.k_L},           {"--kr", &o.k_R},            {"--E-d", &o.E_d},
      {"--E-b", &o.E_b},          {"--gt-sigma-xy", &o.gt_xy}, {"--gt-sigma-theta", &o.gt_th},
      {"--wheelbase", &o.wheelbase}, {"--diameter", &o.diameter}, {"--free", &o.free_runs},
      {"--settle", &o.settle_s}, {"--square-runs", &o.square_runs}, {"--fwd-back-runs", &o.fwd_back_runs}};
  for (int i = 1; i < argc; ++i) {
    const std::string k = argv[i];
    if (i + 1 >= argc) {
      fmt::print(stderr, "indep_campaign: missing value after {}\n", k);
      std::exit(2);
    }
    const std::string v = argv[++i];
    if (k == "--out") o.out = v;
    else if (k == "--seed") o.seed = std::stoull(v);
    else if (k == "--effect") {
      // NAME:k=v,k=v
      const auto colon = v.find(':');
      auto& params = o.effects[v.substr(0, colon)];
      std::size_t p = colon == std::string::npos ? v.size() : colon + 1;
      while (p < v.size()) {
        const auto comma = v.find(',', p), eq = v.find('=', p);
        const auto end = comma == std::string::npos ? v.size() : comma;
        params[v.substr(p, eq - p)] = std::stod(v.substr(eq + 1, end - eq - 1));
        p = end + 1;
      }
    } else if (num.count(k)) *num[k] = std::stod(v);
    else {
      fmt::print(stderr, "indep_campaign: unknown option {}\n", k);
      std::exit(2);
    }
  }
  if (o.out.empty()) {
    fmt::print(stderr, "indep_campaign: --out DIR is required\n");
    std::exit(2);
  }
  return o;
}

void WriteRuns(const std::string& path, const std::vector<std::pair<std::string, std::vector<Sample>>>& runs) {
  std::ofstream f(path);
  f << "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n";
  for (std::size_t r = 0; r < runs.size(); ++r)
    for (const Sample& s : runs[r].second)
      f << fmt::format("{},{},{:.6f},{:.0f},{:.0f},{:.9g},{:.9g},{:.9g}\n", r + 1, runs[r].first, s.t, s.ticks_L,
                       s.ticks_R, s.x, s.y, s.th);
  if (!f) {
    fmt::print(stderr, "indep_campaign: cannot write {}\n", path);
    std::exit(1);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = Parse(argc, argv);
  std::mt19937_64 g(o.seed);
  std::mt19937_64 gx(o.seed ^ 0x9E3779B97F4A7C15ULL);
  std::mt19937_64 gs(o.seed ^ 0xC2B2AE3D27D4EB4FULL);
  std::filesystem::create_directories(o.out);
  // Squares: N cw + N ccw alternating (--square-runs N, default 10); each:
  // pause, 4 x (leg, pause, turn, pause).
  std::vector<std::pair<std::string, std::vector<Sample>>> squares, fwd_back;
  const double inner_pause = o.pause_s, end_pause = std::max(o.pause_s, 1.0);
  for (int r = 0; r < 2 * static_cast<int>(o.square_runs); ++r) {
    const bool cw = r % 2 == 0;
    Robot robot(o, g, gx, gs);
    robot.Pause(end_pause);
    for (int leg = 0; leg < 4; ++leg) {
      robot.Leg(o.side_m, leg == 0 || inner_pause > 0.0);
      robot.Pause(inner_pause);
      robot.Turn(cw ? -0.5 * kPi : 0.5 * kPi);
      robot.Pause(leg == 3 ? end_pause : inner_pause);
    }
    squares.emplace_back(cw ? "cw" : "ccw", robot.Finish());
  }
  // Back and forth (--fwd-back-runs, default 20): pause, forward, pause, back, pause.
  for (int r = 0; r < static_cast<int>(o.fwd_back_runs); ++r) {
    Robot robot(o, g, gx, gs);
    robot.Pause(end_pause);
    robot.Leg(o.distance_m, true);
    robot.Pause(inner_pause);
    robot.Leg(-o.distance_m, inner_pause > 0.0);
    robot.Pause(end_pause);
    fwd_back.emplace_back("fwd_back", robot.Finish());
  }
  // Free paths: pause, three stretches (70 % forward) of two or three arcs
  // each (0.5-1.5 m, radius >= 0.8 m either way or straight), stops between.
  std::vector<std::pair<std::string, std::vector<Sample>>> free_paths;
  const double stop_pause = std::max(o.pause_s, 0.5);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  for (int r = 0; r < static_cast<int>(o.free_runs); ++r) {
    Robot robot(o, g, gx, gs);
    robot.Pause(end_pause);
    for (int s = 0; s < 3; ++s) {
      std::vector<std::array<double, 2>> arcs(u01(g) < 0.5 ? 2 : 3);
      for (auto& a : arcs) a = {0.5 + u01(g), (2.0 * u01(g) - 1.0) / 0.8};
      robot.Stretch(arcs, u01(g) < 0.7 ? 1.0 : -1.0);
      robot.Pause(s == 2 ? end_pause : stop_pause);
    }
    free_paths.emplace_back("free", robot.Finish());
  }
  WriteRuns(o.out + "/square.csv", squares);
  if (!fwd_back.empty()) WriteRuns(o.out + "/fwd_back.csv", fwd_back);
  if (!free_paths.empty()) WriteRuns(o.out + "/free.csv", free_paths);
  std::ofstream m(o.out + "/campaign.toml");
  m << fmt::format(
      "# written by bench/indep_campaign (independent generator)\n[robot]\nwheelbase_m = {}\n"
      "wheel_diameter_left_m = {}\nwheel_diameter_right_m = {}\nticks_per_rev = {}\n\n[ground_truth]\n"
      "sigma_xy_m = {}\nsigma_theta_rad = {}\n\n[[experiment]]\nkind = \"square\"\nside_m = {}\nfile = \"square.csv\"\n",
      o.wheelbase, o.diameter, o.diameter, o.ticks, o.gt_xy, o.gt_th, o.side_m);
  if (!fwd_back.empty())
    m << fmt::format("\n[[experiment]]\nkind = \"back_and_forth\"\ndistance_m = {}\nfile = \"fwd_back.csv\"\n",
                     o.distance_m);
  if (!free_paths.empty()) m << "\n[[experiment]]\nkind = \"free\"\nfile = \"free.csv\"\n";
  std::ofstream t(std::filesystem::path(o.out).parent_path() / "truth.json");
  t << fmt::format("{{\"seed\": {}, \"E_d\": {}, \"E_b\": {}, \"k_L\": {}, \"k_R\": {}, \"effects\": {{", o.seed, o.E_d,
                   o.E_b, o.k_L, o.k_R);
  bool first = true;
  for (const auto& [name, params] : o.effects) {
    t << (first ? "" : ", ") << fmt::format("\"{}\": {{", name);
    bool fp = true;
    for (const auto& [k, v] : params) {
      t << (fp ? "" : ", ") << fmt::format("\"{}\": {}", k, v);
      fp = false;
    }
    t << "}";
    first = false;
  }
  t << fmt::format("}}, \"design\": {{\"rate_hz\": {}, \"ticks\": {}, \"pause_s\": {}, \"accel\": {}, "
                   "\"heading_hold\": {}, \"free_runs\": {}}}}}\n",
                   o.rate_hz, o.ticks, o.pause_s, o.accel, o.heading_hold, o.free_runs);
  if (!m || !t) {
    fmt::print(stderr, "indep_campaign: cannot write into {}\n", o.out);
    return 1;
  }
  return 0;
}
