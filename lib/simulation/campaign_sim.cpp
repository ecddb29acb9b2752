// Campaign simulator (see campaign_sim.hpp): plans per experiment kind, the
// true robot per run, and the truth as JSON.
#include "simulation/campaign_sim.hpp"

#include <cmath>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "core/angles.hpp"
#include "core/errors.hpp"
#include "effects/registry.hpp"
#include "evaluation/return_error.hpp"
#include "kinematics/odometry.hpp"
#include "model/true_robot.hpp"
#include "simulation/campaign_run.hpp"
#include "simulation/effects_motion.hpp"

namespace umbmark::sim {

namespace {

PlannedMotion Pause(double seconds) {
  PlannedMotion m;
  m.pause = true;
  m.duration_s = seconds;
  return m;
}

PlannedMotion Move(MotionClass cls, double left_m, double right_m, double duration_s) {
  PlannedMotion m;
  m.cls = cls;
  m.left_m = left_m;
  m.right_m = right_m;
  m.duration_s = duration_s;
  m.from_standstill = true;
  return m;
}

/// Marks the moves that start from standstill (the contract's castor_kick):
/// the run's first move and every move right after a pause that lasts.
void MarkStandstillStarts(RunPlan& plan) {
  bool still = true;  // a run starts at rest
  for (PlannedMotion& m : plan.motions) {
    if (m.pause) {
      if (m.duration_s > 0.0) still = true;
      continue;
    }
    m.from_standstill = still;
    still = false;
  }
}

RunPlan SquarePlan(bool clockwise, double side_m, double wheelbase_m, const CampaignSimOptions& o) {
  RunPlan plan;
  plan.sample_rate_hz = o.sample_rate_hz;
  const double phi = clockwise ? -kPi / 2.0 : kPi / 2.0;
  const double wheel = 0.5 * wheelbase_m * phi;  // right wheel travel of the spot turn
  plan.motions.push_back(Pause(o.pause_s));
  for (int leg = 0; leg < 4; ++leg) {
    plan.motions.push_back(Move(MotionClass::kStraight, side_m, side_m, side_m / o.speed_m_s));
    plan.motions.push_back(Pause(o.pause_s));
    plan.motions.push_back(Move(MotionClass::kTurn, -wheel, wheel, std::abs(phi) / o.turn_rate_rad_s));
    plan.motions.push_back(Pause(o.pause_s));
  }
  MarkStandstillStarts(plan);
  return plan;
}

RunPlan BackAndForthPlan(double distance_m, const CampaignSimOptions& o) {
  RunPlan plan;
  plan.sample_rate_hz = o.sample_rate_hz;
  plan.motions.push_back(Pause(o.pause_s));
  plan.motions.push_back(Move(MotionClass::kStraight, distance_m, distance_m, distance_m / o.speed_m_s));
  plan.motions.push_back(Pause(o.pause_s));
  plan.motions.push_back(Move(MotionClass::kStraight, -distance_m, -distance_m, distance_m / o.speed_m_s));
  plan.motions.push_back(Pause(o.pause_s));
  MarkStandstillStarts(plan);
  return plan;
}

RunPlan FigureEightPlan(double radius_m, double wheelbase_m, const CampaignSimOptions& o) {
  RunPlan plan;
  plan.sample_rate_hz = o.sample_rate_hz;
  const double inner = 2.0 * kPi * (radius_m - 0.5 * wheelbase_m);
  const double outer = 2.0 * kPi * (radius_m + 0.5 * wheelbase_m);
  const double duration = outer / o.speed_m_s;
  const MotionClass cls = ClassifyMotion(inner, outer, wheelbase_m);
  plan.motions.push_back(Pause(o.pause_s));
  plan.motions.push_back(Move(cls, inner, outer, duration));
  plan.motions.push_back(Pause(o.pause_s));
  plan.motions.push_back(Move(cls, outer, inner, duration));
  plan.motions.push_back(Pause(o.pause_s));
  MarkStandstillStarts(plan);
  return plan;
}

/// A replayed step's place in its motion (castor_swivel, stop_slide): the
/// motion's start, its end when a standstill follows (the next motion
/// starts from standstill, as the diagnosis reads it, or none follows), its
/// sign, and the nominal wheel speeds at its end (the mean over up to three
/// full intervals before its last, partial one).
void MarkReplayedMotion(const WheelTravel& travel, const std::vector<double>& ts,
                        const std::vector<MotionSegment>& motions, std::size_t k, const MotionOptions& mo,
                        std::size_t i, PlannedMotion& step) {
  const MotionSegment& m = motions[k];
  step.sign = m.sign;
  step.motion_start = i == m.first_interval;
  step.motion_end = false;
  if (i != m.last_interval) return;
  step.motion_end = k + 1 == motions.size() ||
                    (motions[k + 1].first_interval - m.last_interval > static_cast<std::size_t>(mo.min_stand_intervals) &&
                     !motions[k + 1].after_brief_stop);
  const std::size_t hi = m.last_interval, lo = hi > m.first_interval + 3 ? hi - 3 : m.first_interval;
  if (hi > lo && ts[hi] > ts[lo]) {
    step.end_rate_left = (travel.left_m[hi] - travel.left_m[lo]) / (ts[hi] - ts[lo]);
    step.end_rate_right = (travel.right_m[hi] - travel.right_m[lo]) / (ts[hi] - ts[lo]);
  } else if (ts[m.EndSample()] > ts[m.FirstSample()]) {
    const double dt = ts[m.EndSample()] - ts[m.FirstSample()];
    step.end_rate_left = m.left_m / dt;
    step.end_rate_right = m.right_m / dt;
  }
}

/// Replays a recorded run: one planned step per sample interval with the
/// recorded nominal wheel travel and timing; motions and standstill as
/// SegmentMotions finds them.
RunPlan ReplayPlan(const TrajectoryRun& run, const RobotParams& robot) {
  const WheelTravel travel = ComputeWheelTravel(run, robot, robot);
  MotionOptions mo;
  if (run.has_ticks()) mo.stand_eps_m = 0.5 * std::min(robot.MetresPerTickLeft(), robot.MetresPerTickRight());
  const std::vector<MotionSegment> motions = SegmentMotions(travel.left_m, travel.right_m, robot.wheelbase_m, mo);
  RunPlan plan;
  const std::size_t n = run.size();
  plan.sample_times.resize(n);
  for (std::size_t j = 0; j < n; ++j) plan.sample_times[j] = run.t_s[j] - run.t_s[0];
  std::size_t next_motion = 0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const double dt = plan.sample_times[i + 1] - plan.sample_times[i];
    while (next_motion < motions.size() && motions[next_motion].last_interval < i) ++next_motion;
    const bool inside = next_motion < motions.size() && motions[next_motion].first_interval <= i;
    if (!inside) {
      plan.motions.push_back(Pause(dt));
      continue;
    }
    const MotionSegment& m = motions[next_motion];
    PlannedMotion step = Move(m.cls, travel.left_m[i + 1] - travel.left_m[i], travel.right_m[i + 1] - travel.right_m[i], dt);
    // From standstill: the run's first motion, or one after a standstill
    // (min_stand_intervals still intervals or more, what separates motions;
    // a motion that follows another back to back, or after a shorter still
    // stretch or a brief stop, does not start from standstill, whatever its
    // class). The diagnosis reads it the same way (diagnosis/pieces.cpp).
    step.from_standstill =
        i == m.first_interval &&
        (next_motion == 0 || (m.first_interval - motions[next_motion - 1].last_interval >
                                  static_cast<std::size_t>(mo.min_stand_intervals) &&
                              !m.after_brief_stop));
    if (step.from_standstill && m.cls != MotionClass::kTurn) {
      // The kick's direction is the motion's, not this first step's.
      const double sgn = m.left_m + m.right_m >= 0.0 ? 1.0 : -1.0;
      if ((step.left_m + step.right_m) * sgn < 0.0) step.from_standstill = false;
    }
    MarkReplayedMotion(travel, plan.sample_times, motions, next_motion, mo, i, step);
    plan.motions.push_back(step);
  }
  return plan;
}

/// One run to simulate: its plan, id and direction.
struct PlannedRun {
  RunPlan plan;
  std::string id, direction;
};

/// The runs of every experiment of `manifest`, in file order.
std::vector<std::vector<PlannedRun>> PlanCampaign(const Manifest& manifest, const CampaignSimOptions& options,
                                                  const std::vector<std::optional<TrajectoryData>>& free_templates) {
  const RobotParams& robot = manifest.robot;
  std::vector<std::vector<PlannedRun>> plans(manifest.experiments.size());
  for (std::size_t e = 0; e < manifest.experiments.size(); ++e) {
    const Experiment& ex = manifest.experiments[e];
    auto& list = plans[e];
    switch (ex.kind) {
      case ExperimentKind::kSquare:
        for (int i = 0; i < 2 * options.square_runs_per_direction; ++i) {
          const bool cw = i % 2 == 0;
          list.push_back({SquarePlan(cw, ex.side_m, robot.wheelbase_m, options), std::to_string(i + 1),
                          cw ? "cw" : "ccw"});
        }
        break;
      case ExperimentKind::kBackAndForth:
        for (int i = 0; i < options.back_and_forth_runs; ++i)
          list.push_back({BackAndForthPlan(ex.distance_m, options), std::to_string(i + 1), "fwd_back"});
        break;
      case ExperimentKind::kFree:
        if (e < free_templates.size() && free_templates[e]) {
          for (const TrajectoryRun& r : free_templates[e]->runs) {
            if (r.size() < 2) continue;
            list.push_back({ReplayPlan(r, robot), r.run, r.direction});
          }
          if (list.empty()) throw InvalidOptions(fmt::format("simulate: free experiment {} template has no runs", e + 1));
        } else {
          if (!(options.free_radius_m > 0.5 * robot.wheelbase_m))
            throw InvalidOptions(fmt::format("simulate: free_radius_m = {} must exceed half the wheelbase ({})",
                                             options.free_radius_m, 0.5 * robot.wheelbase_m));
          for (int i = 0; i < options.free_runs; ++i)
            list.push_back({FigureEightPlan(options.free_radius_m, robot.wheelbase_m, options), std::to_string(i + 1),
                            "figure_eight"});
        }
        break;
    }
  }
  return plans;
}

}  // namespace

std::string CampaignTruth::Check() const {
  if (auto e = TrueRobot{E_d, E_b, 0.0}.Check(); !e.empty()) return e;
  if (!(k_L >= 0.0) || !std::isfinite(k_L)) return fmt::format("k_L = {} must be a finite number >= 0", k_L);
  if (!(k_R >= 0.0) || !std::isfinite(k_R)) return fmt::format("k_R = {} must be a finite number >= 0", k_R);
  return {};
}

std::string CampaignSimOptions::Check() const {
  if (auto e = truth.Check(); !e.empty()) return "truth: " + e;
  if (auto e = effects.Check(); !e.empty()) return e;
  if (square_runs_per_direction < 1)
    return fmt::format("square_runs_per_direction = {} must be >= 1", square_runs_per_direction);
  if (back_and_forth_runs < 1) return fmt::format("back_and_forth_runs = {} must be >= 1", back_and_forth_runs);
  if (free_runs < 1) return fmt::format("free_runs = {} must be >= 1", free_runs);
  auto positive = [](const char* name, double v) -> std::string {
    if (!(v > 0.0) || !std::isfinite(v)) return fmt::format("{} = {} must be a finite number > 0", name, v);
    return {};
  };
  if (auto e = positive("sample_rate_hz", sample_rate_hz); !e.empty()) return e;
  if (auto e = positive("speed_m_s", speed_m_s); !e.empty()) return e;
  if (auto e = positive("turn_rate_rad_s", turn_rate_rad_s); !e.empty()) return e;
  if (auto e = positive("free_radius_m", free_radius_m); !e.empty()) return e;
  if (!(pause_s >= 0.0) || !std::isfinite(pause_s)) return fmt::format("pause_s = {} must be >= 0", pause_s);
  if (!(max_samples > 0.0)) return fmt::format("max_samples = {} must be > 0", max_samples);
  if (ground_truth) {
    if (!(ground_truth->sigma_xy_m >= 0.0) || !std::isfinite(ground_truth->sigma_xy_m))
      return fmt::format("ground_truth.sigma_xy_m = {} must be >= 0", ground_truth->sigma_xy_m);
    if (!(ground_truth->sigma_theta_rad >= 0.0) || !std::isfinite(ground_truth->sigma_theta_rad))
      return fmt::format("ground_truth.sigma_theta_rad = {} must be >= 0", ground_truth->sigma_theta_rad);
  }
  return {};
}

double EstimateCampaignSamples(const Manifest& manifest, const CampaignSimOptions& o,
                               const std::vector<std::optional<TrajectoryData>>& free_templates) {
  const double b = manifest.robot.wheelbase_m, rate = o.sample_rate_hz;
  double total = 0.0;
  for (std::size_t e = 0; e < manifest.experiments.size(); ++e) {
    const Experiment& ex = manifest.experiments[e];
    switch (ex.kind) {
      case ExperimentKind::kSquare:
        total += 2.0 * o.square_runs_per_direction *
                 ((4.0 * ex.side_m / o.speed_m_s + 2.0 * kPi / o.turn_rate_rad_s + 9.0 * o.pause_s) * rate + 1.0);
        break;
      case ExperimentKind::kBackAndForth:
        total += o.back_and_forth_runs * ((2.0 * ex.distance_m / o.speed_m_s + 3.0 * o.pause_s) * rate + 1.0);
        break;
      case ExperimentKind::kFree:
        if (e < free_templates.size() && free_templates[e]) {
          for (const auto& r : free_templates[e]->runs) total += static_cast<double>(r.size());
        } else {
          const double outer = 2.0 * kPi * (o.free_radius_m + 0.5 * b);
          total += o.free_runs * ((2.0 * outer / o.speed_m_s + 3.0 * o.pause_s) * rate + 1.0);
        }
        break;
    }
  }
  return total;
}

SimulatedCampaign SimulateCampaign(const Manifest& manifest, const CampaignSimOptions& options,
                                   const std::vector<std::optional<TrajectoryData>>& free_templates) {
  if (auto e = options.Check(); !e.empty()) throw InvalidOptions("simulate: " + e);
  const RobotParams& robot = manifest.robot;
  if (auto e = robot.Check(); !e.empty()) throw InvalidOptions("simulate: robot: " + e);
  // Resource bound first: a tiny speed or a huge run count must be refused
  // before any run is planned or any memory taken.
  const double samples = EstimateCampaignSamples(manifest, options, free_templates);
  if (!(samples <= options.max_samples)) {
    throw InvalidOptions(fmt::format(
        "simulate: the campaign would hold about {:.3g} samples (about {:.3g} GB), more than the limit of {:.3g}; "
        "lower the run counts or the sample rate, or raise the speed",
        samples, samples * 150e-9, options.max_samples));
  }
  const bool ticks = robot.ticks_per_rev.has_value();

  // Run plans per experiment, then the campaign's run count (drift check).
  const std::vector<std::vector<PlannedRun>> plans = PlanCampaign(manifest, options, free_templates);
  int total = 0;
  for (const auto& l : plans) total += static_cast<int>(l.size());
  for (const effects::Effect* fx : effects::All())
    if (const std::string why = fx->CheckCampaign(options.effects, total); !why.empty())
      throw InvalidOptions("simulate: " + why);

  const CampaignTruth& tr = options.truth;
  const double c_L = CorrectionLeft(tr.E_d), c_R = CorrectionRight(tr.E_d);
  GroundTruthNoise gt;
  if (options.ground_truth)
    gt = *options.ground_truth;
  else if (manifest.ground_truth)
    gt = *manifest.ground_truth;

  SimulatedCampaign out;
  out.manifest = manifest;
  out.manifest.ground_truth = options.state_ground_truth ? std::optional<GroundTruthNoise>(gt) : std::nullopt;
  out.ground_truth_noise = gt;
  out.total_runs = total;
  out.seed = options.seed;
  out.bumps.resize(manifest.experiments.size());

  RunTruth truth;
  truth.ticks = ticks;
  truth.nominal_per_tick_left = ticks ? robot.MetresPerTickLeft() : 1.0;
  truth.nominal_per_tick_right = ticks ? robot.MetresPerTickRight() : 1.0;
  truth.true_wheelbase_m = tr.E_b * robot.wheelbase_m;
  truth.k_L = tr.k_L;
  truth.k_R = tr.k_R;
  truth.effects = options.effects;
  truth.gt_sigma_xy_m = gt.sigma_xy_m;
  truth.gt_sigma_theta_rad = gt.sigma_theta_rad;

  std::uint64_t run_index = 0;
  for (std::size_t e = 0; e < manifest.experiments.size(); ++e) {
    const Experiment& ex = manifest.experiments[e];
    TrajectoryData data;
    data.path = ex.file;
    for (const PlannedRun& pr : plans[e]) {
      // The effects that change the true wheels (each effect's TrueWheels).
      truth.true_per_tick_left = truth.nominal_per_tick_left * c_L;
      truth.true_per_tick_right = truth.nominal_per_tick_right * c_R;
      for (const effects::Effect* fx : effects::All())
        fx->TrueWheels(options.effects, static_cast<int>(run_index), truth.true_per_tick_left,
                       truth.true_per_tick_right);
      SimulatedRun sr = SimulateLoggedRun(pr.plan, truth, options.seed, run_index, pr.id, pr.direction);
      out.bumps[e].push_back(sr.bumps_left + sr.bumps_right);
      data.runs.push_back(std::move(sr.run));
      ++run_index;
    }
    if (ex.kind == ExperimentKind::kSquare && options.endpoint_squares) {
      EndpointData ep;
      ep.path = ex.file;
      ep.runs = ReturnErrorsFromTrajectories(data, robot, robot, Integrator::kArc);
      out.data.emplace_back(std::move(ep));
    } else {
      out.data.emplace_back(std::move(data));
    }
  }
  return out;
}

nlohmann::json CampaignTruthJson(const SimulatedCampaign& campaign, const CampaignSimOptions& options) {
  const CampaignTruth& tr = options.truth;
  const RobotParams& robot = campaign.manifest.robot;
  const double c_L = CorrectionLeft(tr.E_d), c_R = CorrectionRight(tr.E_d);
  // Run 0's true wheels: the corrections times what the effects make of them.
  double true_c_L = c_L, true_c_R = c_R;
  for (const effects::Effect* fx : effects::All()) fx->TrueWheels(options.effects, 0, true_c_L, true_c_R);
  nlohmann::json effects = nlohmann::json::array();
  for (EffectKind k : options.effects.ActiveKinds()) {
    const EffectDescriptor& d = Describe(k);
    nlohmann::json params = nlohmann::json::object();
    for (const auto& p : d.parameters) params[std::string(p.name)] = options.effects.*(p.field);
    effects.push_back({{"effect", std::string(d.name)}, {"params", params}, {"in_contract", d.in_contract}});
  }
  nlohmann::json experiments = nlohmann::json::array();
  for (std::size_t e = 0; e < campaign.manifest.experiments.size(); ++e) {
    const auto& d = campaign.data[e];
    const std::size_t runs = std::holds_alternative<TrajectoryData>(d) ? std::get<TrajectoryData>(d).runs.size()
                                                                       : std::get<EndpointData>(d).runs.size();
    experiments.push_back({{"kind", ExperimentKindToString(campaign.manifest.experiments[e].kind)},
                           {"file", campaign.manifest.experiments[e].file},
                           {"runs", runs}});
  }
  return {{"seed", campaign.seed},
          {"truth",
           {{"E_d", tr.E_d},
            {"E_b", tr.E_b},
            {"k_L", tr.k_L},
            {"k_R", tr.k_R},
            {"c_L", c_L},
            {"c_R", c_R},
            {"true_robot_run0",
             {{"wheelbase_m", tr.E_b * robot.wheelbase_m},
              {"wheel_diameter_left_m", true_c_L * robot.wheel_diameter_left_m},
              {"wheel_diameter_right_m", true_c_R * robot.wheel_diameter_right_m}}}}},
          {"effects", effects},
          {"ground_truth",
           {{"sigma_xy_m", campaign.ground_truth_noise.sigma_xy_m},
            {"sigma_theta_rad", campaign.ground_truth_noise.sigma_theta_rad},
            {"stated_in_manifest", campaign.manifest.ground_truth.has_value()}}},
          {"total_runs", campaign.total_runs},
          {"experiments", experiments},
          {"motion",
           {{"sample_rate_hz", options.sample_rate_hz},
            {"speed_m_s", options.speed_m_s},
            {"turn_rate_rad_s", options.turn_rate_rad_s},
            {"pause_s", options.pause_s},
            {"free_radius_m", options.free_radius_m}}}};
}

Manifest StandardCampaignManifest(const RobotParams& robot, double side_m, double distance_m,
                                  const std::optional<GroundTruthNoise>& ground_truth) {
  Manifest m;
  m.robot = robot;
  Experiment sq;
  sq.kind = ExperimentKind::kSquare;
  sq.side_m = side_m;
  sq.file = sq.resolved_file = "square.csv";
  Experiment bf;
  bf.kind = ExperimentKind::kBackAndForth;
  bf.distance_m = distance_m;
  bf.file = bf.resolved_file = "fwd_back.csv";
  m.experiments = {sq, bf};
  m.ground_truth = ground_truth;
  return m;
}

}  // namespace umbmark::sim
