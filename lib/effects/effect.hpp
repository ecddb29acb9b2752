// One interface for every unmodelled effect (issue 28 item 4): the
// contract's fourteen (interface.md "Effects"), the two outside effects of
// the blind benchmark and the three parameter errors of `diagnose
// --baseline`. Each effect is one file lib/effects/<name>.cpp holding a
// class derived from Effect and a UMBMARK_EFFECT(Class) line that registers
// it (registry.hpp): its contract name, parameters and their ranges, class,
// typical size, practical floor at the campaign's own speeds, physical
// plausibility and advice with the fitted numbers.
//
// Layer 2.5 (scripts/check_layers.sh): includes core, kinematics and model
// only, so that both the simulator and the diagnosis can use it.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/pose2.hpp"
#include "core/robot.hpp"
#include "effects/run_hooks.hpp"
#include "effects/values.hpp"

namespace umbmark::effects {

/// The diagnosis' mean-model parameters (diagnosis/model.hpp ParamIndex has
/// the same values): the vocabulary in which an effect names those that
/// are its own (Descriptor::mean_terms).
enum MeanTerm : int {
  kTermEd = 0,     ///< E_d (the baseline's)
  kTermEb,         ///< E_b (the baseline's)
  kTermScale,      ///< a common factor of both wheels' travel
  kTermScrub,      ///< the heading lost in spot turns (also enters the covariance bases)
  kTermAsym,       ///< a factor of backward travel
  kTermKappa,      ///< a heading kick where a non-turn motion starts from standstill
  kTermDrift,      ///< the right wheel's factor per run
  kTermDx,         ///< the reported point, forward of the axle
  kTermDy,         ///< the reported point, left of the axle
  kTermTau,        ///< the ground truth's clock (checked on the moving samples alone)
  kTermSwivel,     ///< a heading kick after a spot turn
  kTermSlideD,     ///< a coast after a straight or arc motion (the campaign shows it only with such a stop)
  kTermSlideA,     ///< a coast after a spot turn (only with a stop after a turn)
  kTermSlideArc,   ///< a coast's turn after an arc (only with a stop on an arc)
  kTermSlideBack,  ///< a backward coast's extra length (only with forward and backward stops)
  kNumMeanTerms
};

/// The components of the diagnosis' piece noise model (diagnosis/
/// piece_noise.hpp) a noise effect switches on (Descriptor::noise_term).
enum class NoiseTerm {
  kNone,
  kCorrelated,   ///< correlation of the two wheels' noise
  kBumps,        ///< a mixture of rare bumps (its own fit)
  kStandstill,   ///< settling where a motion ends at a standstill
  kMotionFloor,  ///< slip where motions start and stop
  kRunTime,      ///< a clock offset of each run (run blocks)
  kWheelNoise,   ///< the wheel noise k_L, k_R of a given model
  /// A heading kick and a position slip of random size where a run's first
  /// motion, a straight or arc one, starts, and the scatter of the heading
  /// kick where a straight or arc motion starts after a spot turn (a mean
  /// effect's random parts: the variances enter the pieces that hold such a
  /// start).
  kFirstStart,
};

/// The fitted noise, as the diagnosis' piece noise model has it (variances
/// and the bump rate; Effect::FromNoise).
struct NoiseValues {
  double rho = 0.0;        ///< correlation of the wheels' noise
  double bumps_per_m = 0.0;  ///< bumps per metre of a wheel's travel
  double bump_var = 0.0;     ///< a bump's variance [m^2]
  double stand_xy2 = 0.0, stand_th2 = 0.0;  ///< settling [m^2, rad^2]
  double floor_s2 = 0.0;   ///< start / stop slip [m^2]
  double run_tau2 = 0.0;   ///< per-run clock [s^2]
  double kL2 = 0.0, kR2 = 0.0;  ///< wheel noise [m]
  double first_start_th2 = 0.0;  ///< heading kick at a run's first start [rad^2]
  double first_start_xy2 = 0.0;  ///< position slip there, per robot axis [m^2]
  double turn_start_th2 = 0.0;   ///< scatter of the heading kick after a spot turn [rad^2]
};

/// What an effect is: a property of the robot's motion (mechanism), of the
/// recording (measurement), or a random scatter (noise).
enum class EffectClass { kMechanism, kMeasurement, kNoise };

/// One parameter: its contract name, its field in Effects, its unit and a
/// typical size (the realistic ranges of the blind benchmark; 0: none).
struct Parameter {
  std::string_view name;
  double Effects::*field = nullptr;
  std::string_view unit;
  double typical = 0.0;
};

/// Fitted or given parameter values by contract name.
using Params = std::map<std::string, double>;

/// The campaign's own speeds and distances, which turn a parameter into a
/// pose size (the practical floors, docs/diagnosis.md "Practical floors").
/// The defaults give the fixed floors of before (a 1.5 ms clock at 0.2
/// m/s and 0.2 rad/s is 0.3 mm and 0.3 mrad; 0.03 % over 1 m is 0.3 mm).
struct CampaignScale {
  /// Typical driving speed [m/s] (median of the moving samples' |v|).
  double speed_mps = 0.2;
  /// Typical turn rate [rad/s] (median of the turning samples' |w|).
  double turn_rate_radps = 0.2;
  /// Typical length of one leg [m] (median over the straight and arc
  /// motions between two standstills).
  double motion_length_m = 1.0;
  /// DiagnoseOptions::negligible; the floors scale with negligible / 0.25
  /// (0 switches them off).
  double negligible = 0.25;

  /// The pose floors [m, rad]: 0.3 mm and 0.3 mrad at the default
  /// negligible, scaled by negligible / 0.25.
  double FloorM() const { return 3e-4 * negligible / 0.25; }
  double FloorRad() const { return 3e-4 * negligible / 0.25; }
};

/// What the advice needs of the campaign and its baseline model.
struct AdviceContext {
  RobotParams robot;       ///< the campaign's nominal robot
  double E_d = 1.0;        ///< the explained model's diameter ratio (fitted with the named effects)
  double E_b = 1.0;        ///< the explained model's wheelbase factor
  int runs = 0;            ///< runs in the campaign
  /// E_d, E_b are the explained model's; false: the baseline's (no
  /// explanation) or the given model's (`--baseline`).
  bool explained = false;
};

/// What the campaign's design shows, for an effect's design note
/// (Effect::DesignNote).
struct DesignFacts {
  int spot_turns = 0;  ///< pieces that rotate on the spot (spot turns, a square's return)
  int arcs = 0;        ///< pieces that turn while driving
  /// The effect's candidate fit is told from E_d, E_b (identifiable and not
  /// weakly so).
  bool separable = true;
  double E_b = 1.0;  ///< the baseline's wheelbase factor
};

/// What a parameter error of a given model (`diagnose --baseline`) needs to
/// describe its fit and the change it asks for.
struct GivenContext {
  RobotParams recorded;  ///< the campaign's recorded robot
  RobotParams given;     ///< the given model's (what the simulation uses)
  /// The given model relative to `recorded` (the mean model's E_d, E_b and
  /// scale s).
  double E_d = 1.0, E_b = 1.0, scale = 0.0;
  double k_L = 0.0, k_R = 0.0;  ///< the given wheel noise [m^1/2]
};

/// One change of the given model that a parameter error asks for.
struct GivenCorrection {
  std::string parameter;  ///< e.g. "wheelbase_m"
  double given = 0.0;     ///< the simulation's value
  double corrected = 0.0; ///< what the runs show
  std::string unit;       ///< "m", "m^1/2"
  std::string text;       ///< one sentence: what is wrong, by how much, what to set
};

/// The experiment that tells an effect apart from others (the advice asks
/// for it, naming the effect, when a campaign lacks it).
enum class SeparatingExperiment {
  kNone,
  kBackAndForth,       ///< a straight line driven out and back
  kTurnsWhileDriving,  ///< free paths with arcs of different radii
  kStandstills,        ///< stops of 1-2 s between legs
};

/// Everything an effect is that needs no code.
struct Descriptor {
  std::string_view name;      ///< contract name (JSON key, --effect NAME)
  /// The built-in kind (transitional, values.hpp); leave it empty for an
  /// effect added at run time: Register gives it an id of its own
  /// (EffectKind::kFirstRunTime and up).
  std::optional<EffectKind> kind;
  /// Position in the contract's table (the catalogue order: contract
  /// effects 0-13, outside effects 100+, parameter errors 200+).
  int order = 0;
  EffectClass effect_class = EffectClass::kMechanism;
  /// Fitted as a variance component (a random effect per event or run),
  /// not as a mean shift.
  bool random = false;
  bool in_contract = true;
  /// A parameter error of a given model (`diagnose --baseline`): named by
  /// the diagnosis only, never simulated.
  bool parameter_error = false;
  /// A mechanism that acts once where a motion starts (a castor's kick) or
  /// stops (a coast): the verdict lets a qualifying one outrank a noise
  /// effect that takes its start-to-start scatter, and lets a stop's one
  /// yield to a clock the moving samples support (docs/diagnosis.md, "The
  /// verdict's rule").
  bool at_motion_starts = false;
  bool at_motion_stops = false;
  std::string_view definition;
  std::vector<Parameter> parameters;
  /// Its parameters in the diagnosis' mean model, in the order of
  /// `parameters` (empty: a noise effect, or one that predicts through
  /// PredictWheels).
  std::vector<int> mean_terms{};
  /// The noise component it switches on (a random effect; kNone else).
  NoiseTerm noise_term = NoiseTerm::kNone;
  /// A random effect that is the spread about a fixed effect's value (the
  /// runs' own clocks about the common one): the explanation tries it only
  /// after that effect, when that one may be a step (the mean before the
  /// variance about it; docs/diagnosis.md, "The verdict's rule").
  std::optional<EffectKind> spread_of{};
  /// The id of its own random stream in the simulator (StreamSeed of the
  /// seed and the run; RandomSource of StartRun). Part of every simulated
  /// campaign's bits: never change one. 0: 0x10000 + order.
  std::uint64_t sim_stream = 0;
  /// The experiment that tells it apart (the advice's sentence for a
  /// campaign that lacks it names the effects of that experiment in
  /// separated_rank order).
  SeparatingExperiment separated_by = SeparatingExperiment::kNone;
  int separated_rank = 0;
};

class Effect {
 public:
  explicit Effect(Descriptor d) : d_(std::move(d)) {}
  virtual ~Effect() = default;
  Effect(const Effect&) = delete;
  Effect& operator=(const Effect&) = delete;

  const Descriptor& Describe() const { return d_; }
  std::string_view Name() const { return d_.name; }
  EffectClass Class() const { return d_.effect_class; }
  bool Random() const { return d_.random; }
  bool Simulated() const { return !d_.parameter_error; }
  /// A random scatter of the robot or its sensors (class noise, fitted as a
  /// variance): not a clock of the recording.
  bool PureNoise() const { return d_.random && d_.effect_class == EffectClass::kNoise; }
  const std::vector<Parameter>& Parameters() const { return d_.parameters; }
  /// The typical size of parameter `name` (0 when it has none).
  double TypicalSize(std::string_view name) const;

  /// Empty when the effect's values in `e` are valid, else a message
  /// naming the field ("NAME.PARAM = v must be ..."). Default: every
  /// parameter finite, then Range.
  virtual std::string Check(const Effects& e) const;
  /// Whether the effect is present in `e`. Default: a parameter non-zero.
  virtual bool Active(const Effects& e) const;

  /// Why fitted values this small are negligible whatever the noise (in
  /// words with the number and the floor), or empty. Default: never.
  virtual std::string PracticalFloor(const Params& /*p*/, const CampaignScale& /*s*/) const { return {}; }
  /// Why fitted values are physically impossible or implausible (a symptom,
  /// not a cause), or empty. `runs`: the campaign's; `se`: standard errors.
  virtual std::string Unphysical(const Params& /*p*/, int /*runs*/, const Params& /*se*/) const { return {}; }
  /// Why a random effect fitted at zero explains nothing, or empty.
  virtual std::string NullFit(const Params& /*p*/) const { return {}; }
  /// The concrete change to make, with the fitted numbers, or empty.
  virtual std::string ConcreteChange(const Params& /*p*/, const AdviceContext& /*c*/) const { return {}; }
  /// `diagnose --baseline`: the fitted values `raw` (the mean model's names:
  /// E_d, E_b, s, k_L, k_R, ...) as the effect reports them against the
  /// given model (e.g. the wheelbase in metres). Default: raw.
  virtual Params DescribeGiven(const Params& raw, const GivenContext& /*g*/) const { return raw; }
  /// `diagnose --baseline`: their standard errors likewise. Default: raw_se.
  virtual Params DescribeGivenErrors(const Params& raw_se, const GivenContext& /*g*/) const { return raw_se; }
  /// `diagnose --baseline`: the changes of the given model it asks for,
  /// from DescribeGiven's values `d`; `negligible`: the practical threshold
  /// (DiagnoseOptions::negligible). Default: none.
  virtual std::vector<GivenCorrection> GivenCorrections(const Params& /*d*/, const GivenContext& /*g*/,
                                                        double /*negligible*/) const {
    return {};
  }
  /// The effect as a plain statement with the numbers. Default: "NAME is off".
  virtual std::string PlainProblem(const Params& p) const;
  /// Simulation: multiplies the true left and right wheel's size (any
  /// quantity proportional to it: metres per tick, diameter) in run
  /// `run_index` (0-based, campaign order) by what the effect makes of it.
  /// The simulator applies every effect in catalogue order. Default: none.
  virtual void TrueWheels(const Effects& /*e*/, int /*run_index*/, double& /*left*/, double& /*right*/) const {}
  /// Simulation: how much later than its stamp a ground-truth sample of
  /// this run shows the true pose [s] (a clock offset), summed over the
  /// effects; `draw` gives one N(0, 1) number of the run's own clock stream
  /// (call it only when needed: the stream is the run's). Default: 0.
  virtual double GroundTruthDelay(const Effects& /*e*/, double (*draw)(void*), void* /*state*/) const {
    (void)draw;
    return 0.0;
  }
  /// Simulation: adds to the point the ground truth reports, in the robot
  /// frame (dx, dy [m]), and to its heading (dtheta [rad]). Default: none.
  virtual void GroundTruthPoint(const Effects& /*e*/, double& /*dx*/, double& /*dy*/, double& /*dtheta*/) const {}
  /// Simulation: the effect's state in one run (run_hooks.hpp RunEffect:
  /// kicks where motions start, what it adds to each step's wheel travel,
  /// a drift of the chassis, a move as the robot comes to a standstill), or
  /// nullptr (the default: nothing per motion or step). Called once per run
  /// when Active(e); `rng`: its own stream (Descriptor::sim_stream), to be
  /// drawn from only when needed.
  virtual std::unique_ptr<RunEffect> StartRun(const Effects& /*e*/, RandomSource& /*rng*/) const { return nullptr; }
  /// Simulation: a factor of a wheel's true travel while it turns backwards
  /// (the simulator multiplies the effects' factors). Default: 1.
  virtual double BackwardFactor(const Effects& /*e*/) const { return 1.0; }
  /// Simulation: a factor of the true heading change in spot turns
  /// (multiplied over the effects). Default: 1.
  virtual double TurnHeadingFactor(const Effects& /*e*/) const { return 1.0; }
  /// Simulation: the correlation of the two wheels' noise it adds (summed
  /// over the effects). Default: 0.
  virtual double WheelNoiseCorrelation(const Effects& /*e*/) const { return 0.0; }
  /// Simulation: a coast after a stop (run_hooks.hpp SimCoast) that ends a
  /// spot turn (`turn`) or a straight or arc motion whose wheels ended at
  /// true speeds rate_l, rate_r [m/s] on a robot of true wheelbase b [m].
  /// False: none (the first effect that answers true coasts). Default: none.
  virtual bool StopCoast(const Effects& /*e*/, bool /*turn*/, double /*rate_l*/, double /*rate_r*/, double /*b*/,
                         SimCoast& /*c*/) const {
    return false;
  }
  /// Simulation: why a campaign of `runs` runs cannot have these values
  /// (e.g. a drift that shrinks a wheel to nothing), or empty.
  virtual std::string CheckCampaign(const Effects& /*e*/, int /*runs*/) const { return {}; }

  /// Model prediction (the diagnosis' mean model, diagnosis/model.hpp):
  /// whether the diagnosis fits this effect through PredictWheels, with
  /// Parameters() as its fitted values (in their order, starting at 0). An
  /// effect that answers true is a mean candidate of `diagnose` with no
  /// other file touched. Built-in effects whose prediction is still written
  /// out in diagnosis/model.cpp answer false (transitional). Default: false.
  virtual bool PredictsMean() const { return false; }
  /// Model prediction: multiplies the true left and right wheel travel the
  /// model predicts for run `run_index` (0-based, campaign order) by what
  /// the effect makes of it with values `v` (v[k]: Parameters()[k]): the
  /// fitted counterpart of TrueWheels. Called once per run and prediction,
  /// never per sample. Default: none.
  virtual void PredictWheels(const double* /*v*/, int /*run_index*/, double& /*left*/, double& /*right*/) const {}

  /// Model prediction of what follows a stop (the counterpart of
  /// StopCoast) for an effect with mean_terms and at_motion_stops: whether
  /// values `v` (v[k]: the fitted value of mean_terms[k]) move anything
  /// after a stop. Default: false.
  virtual bool PredictsStop(const double* /*v*/) const { return false; }
  /// Model prediction: the pose q moved on by what happens between tau0
  /// and tau1 seconds after the wheels stopped at the end of motion m, at
  /// values v (as PredictsStop). Called per interval at or after a stop,
  /// only when PredictsStop(v). Default: q.
  virtual Pose2 PredictStop(const double* /*v*/, const StopMotion& /*m*/, Pose2 q, double /*tau0*/,
                            double /*tau1*/) const {
    return q;
  }

  /// A note for the report when the campaign's design cannot show the
  /// effect apart from the baseline and it is not named: why, and which
  /// experiment to add; empty otherwise. Default: none.
  virtual std::string DesignNote(const DesignFacts& /*f*/) const { return {}; }
  /// A noise effect's contract parameters from the fitted noise (empty for
  /// the others).
  virtual Params FromNoise(const NoiseValues& /*n*/) const { return {}; }

  /// How a fitted parameter reads: {factor, unit} (value x factor, unit),
  /// e.g. {1e3, " mm"}; {0, ""} leaves it to the generic reading.
  virtual std::pair<double, const char*> ParamUnit(std::string_view /*param*/) const { return {0.0, ""}; }

 protected:
  /// Effect-specific range checks after the finite check (default: none).
  virtual std::string Range(const Effects& /*e*/) const { return {}; }
  /// A fitted parameter, 0 when absent.
  static double Get(const Params& p, const char* name);
  /// A parameter, `fallback` when absent.
  static double GetOr(const Params& p, const char* name, double fallback) {
    const auto it = p.find(name);
    return it == p.end() ? fallback : it->second;
  }
  /// A fitted parameter's magnitude, +inf when absent (never below a floor).
  static double Size(const Params& p, const char* name);
  /// The practical floor of a heading jump (parameter `name`, rad): it is a
  /// pose size already, so below the heading floor it is negligible.
  static std::string HeadingJumpFloor(const Params& p, const CampaignScale& c, const char* name);
  /// "N mm of noise per event (KEY): ..." when parameter `key` is over 50 mm.
  static std::string NoisePerEventTooLarge(const Params& p, const char* key);
  /// The null-fit sentence when every parameter of `zero` is present and at
  /// most its value in magnitude ("fitted at a = 0, b = 0: ..."), else empty.
  static std::string FittedAtZero(const Params& p, const std::vector<std::pair<const char*, double>>& zero);

 private:
  // Register gives an effect added at run time its kind (an id).
  friend void Register(std::unique_ptr<Effect> effect);
  Descriptor d_;
};

}  // namespace umbmark::effects

/// Registers a built-in effect (one line at the end of its file; the build
/// collects these lines into the registry's list, registry.hpp).
#define UMBMARK_EFFECT(Class)                                              \
  namespace umbmark::effects::registered {                                 \
  const ::umbmark::effects::Effect& Class##Instance() {                    \
    static const Class instance;                                           \
    return instance;                                                       \
  }                                                                        \
  }
