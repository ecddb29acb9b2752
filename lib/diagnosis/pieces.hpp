// The campaign as the diagnosis sees it: every run of every experiment with
// its cumulative nominal wheel travel (from ticks or dist_*_m with the
// manifest's [robot]), its ground truth, its motions (effects_motion.hpp),
// and the PIECES the diagnosis compares with the model.
//
// A piece is a stretch of one run between two samples with ground truth:
// a standstill between motions, or a motion (straight leg, spot turn, arc),
// long motions split into pieces of at most max_piece_length_m of travel
// (max_piece_angle_rad of heading for turns). For each piece the observed
// relative motion Rel(GT_a, GT_b) = GT_a^-1 GT_b is compared with the
// model's prediction Rel(P_a, P_b) (at a standstill, GT and P are the mean
// poses over its samples, so the ground truth's noise averages down): frame-free (no start-frame
// re-expression needed) and, under the baseline model, nearly independent
// from piece to piece (wheel noise of disjoint stretches; only the ground
// truth's noise at a shared boundary sample couples neighbours).
//
// Endpoint runs (return errors of squares) become one piece each: a
// synthetic commanded square (commanded_square.hpp motions, one exact arc
// per motion, standstill between) whose "ground truth" is the odometry's
// final pose plus the measured return error (eq. 3.1).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "core/runs.hpp"
#include "core/pose2.hpp"
#include "simulation/effects_motion.hpp"

namespace umbmark::diag {

enum class PieceType { kStraight, kTurn, kArc, kStand, kReturn };

/// How a wheel rests within its encoder tick after the controller stops a
/// motion (docs/diagnosis.md, "Stops"; stop_model.hpp).
enum class StopModel {
  kWheelEdge,  ///< each wheel stopped on its own tick (per-wheel count targets)
  kBody,       ///< the robot stopped on its odometry: one wheel on its tick, the other anywhere in its tick
};

const char* PieceTypeToString(PieceType t);

struct Piece {
  int run = 0;            ///< index into CampaignData::runs
  std::size_t a = 0, b = 0;  ///< sample indices (ground truth at both)
  /// Ground-truth samples whose mean pose stands for the start / end:
  /// [a_lo, a_hi] and [b_lo, b_hi] (those with ground truth; a_lo = a_hi = a
  /// otherwise). A motion that starts or ends at a standstill is measured
  /// from / to the standstill's mean pose -- the robot is still, so the
  /// ground truth's noise there averages down -- and `a_weight`, `b_weight`
  /// (1 / samples averaged) scale that noise's variance.
  std::size_t a_lo = 0, a_hi = 0, b_lo = 0, b_hi = 0;
  double a_weight = 1.0, b_weight = 1.0;
  PieceType type = PieceType::kStand;
  /// straight / arc: +1 forward, -1 backward; turn: +1 ccw, -1 cw; else 0.
  int sign = 0;
  bool motion_first = false;  ///< first piece of its motion
  /// First piece of a motion that starts from standstill (or the run's
  /// start), and last piece of a motion that ends at a standstill: where
  /// motion_noise_floor's start / stop slip and standstill_motion's
  /// settling show.
  bool starts_from_standstill = false, ends_at_standstill = false;
  int components = 3;         ///< 2 for return errors without heading
  double travel_m = 0.0;      ///< nominal (|dL| + |dR|) / 2 over the piece
  /// Subsets the piece belongs to (CampaignData::subsets): its own, e.g.
  /// "cw, straight (first piece)"; its experiment's pooled one, e.g. "all
  /// runs, straight"; and the campaign's, e.g. "all experiments, straight".
  int subset = 0;
  int pooled_subset = -1;
  int campaign_subset = -1;
  int fold = 0;  ///< cross-validation fold (by run)
};

struct DiagRun {
  int experiment = 0;           ///< 0-based manifest index
  int index_in_experiment = 0;  ///< file order
  int campaign_index = 0;       ///< experiments in manifest order, runs in file order (parameter_drift)
  std::string id, direction;
  bool endpoint = false;
  /// Samples: time, cumulative nominal wheel travel, raw ground truth (NaN
  /// where not measured).
  std::vector<double> t, left, right;
  std::vector<Pose2> gt;
  std::vector<bool> has_gt;
  std::vector<sim::MotionSegment> motions;
  /// Per interval (sample i -> i+1): class index (-1 still, else
  /// MotionClass), castor kick sign (+1 / -1 / 0), and the active window
  /// [u0, u1] (fractions of the interval) in which the wheels turned: a
  /// motion's first interval moves late, its last one early, at the speed of
  /// the neighbouring interval (constant-speed motion, as commanded).
  std::vector<signed char> interval_class;
  std::vector<signed char> kick;
  /// castor_swivel per interval: the sign of the spot turn before the
  /// straight or arc motion that begins in it (+1 ccw, -1 cw), else 0. A
  /// start after a reversal kicks with a random sign: no mean, so it is not
  /// marked (the fit sees those kicks as heading noise).
  std::vector<signed char> swivel;
  /// castor_swivel: 1 at the first interval of a straight or arc motion
  /// that reverses the drive direction of the one before (no spot turn
  /// between), where the swivel kicks with a random sign.
  std::vector<char> reversal;
  /// 1 at the first interval of the run's first motion when it is a
  /// straight or arc one (effects::NoiseTerm::kFirstStart: a heading kick
  /// of random size where the run begins to drive).
  std::vector<char> first_start;
  /// stop_slide: a motion that ends at a stop (the next motion starts from
  /// standstill, or none follows) with its nominal wheel speeds at the end
  /// [m/s] (over up to three full intervals before its last one) and its
  /// class; stop_of[i] indexes `stops` for the motion's last interval i
  /// (-1 elsewhere). Endpoint runs have none (no timing). The chassis
  /// coasts from the moment the wheels stop, decelerating uniformly (Coulomb
  /// friction) at 1/(2 d): the slide d v^2 takes 2 d |v| seconds and goes on
  /// into the still intervals after the stop (coast_of).
  struct Stop {
    std::size_t interval = 0;
    double rate_left = 0.0, rate_right = 0.0;
    double turn_m = 0.0;  ///< the motion's |R - L| (nominal wheel travel): its heading change x b
    double t_stop = 0.0;  ///< when the wheels stopped (within the stop interval, its active window's end)
    signed char cls = 0;
  };
  std::vector<Stop> stops;
  std::vector<int> stop_of;
  /// The stop whose coast may still go on in still interval i (the last
  /// stop before it, until the next motion starts), else -1.
  std::vector<int> coast_of;
  std::vector<float> window_start, window_end;
  /// Junctions of motions back to back (no pause): the interval in which
  /// motion A ends and B begins is two steps, A's direction then B's. For
  /// such an interval i, junctions holds {i, ...}: the nominal travel of
  /// A's part, the fraction of the interval's time it takes (at each
  /// motion's speed) and the two classes. B starts back to back, not from
  /// standstill: no castor kick.
  struct Junction {
    std::size_t interval = 0;
    double left_m = 0.0, right_m = 0.0;  ///< A's part
    double time_fraction = 0.5;
    signed char class_a = 0, class_b = 0;
  };
  std::vector<Junction> junctions;
  /// Index into `junctions` per interval (-1: a plain interval).
  std::vector<int> junction_of;
  /// Encoder quantisation per sample and wheel: the cumulative travel above
  /// is the count plus the expected fraction of a tick the wheel has turned
  /// beyond it (contract: counts are whole ticks of true rotation, and the
  /// controller stops a wheel the instant its count reaches the target):
  /// 0 after a stop moving forward (p = T), 1 after a stop moving backward
  /// (p just below T + 1), 1/2 while moving or before the first motion
  /// (unknown start phase); q_sd_* is the standard deviation of what is left
  /// [m]: tick / sqrt(12), or 0 after a stop. This is the tick-exact
  /// reading of the stop; WithBodyStops (stop_model.hpp) makes the other.
  std::vector<double> q_sd_left, q_sd_right;
  /// Covariance of the two wheels' count errors [m^2] (non-zero only at a
  /// joint stop under the body stop model, stop_model.hpp).
  std::vector<double> q_cov_lr;
  /// At a joint stop (both wheels rest after the same motion): each wheel's
  /// direction in that motion (+1 forward, -1 backward), else 0.
  std::vector<signed char> stop_dir_left, stop_dir_right;
  /// Still intervals that separate motions (castor kicks; MotionOptions).
  int min_stand_intervals = 2;
  bool has_heading = true;  ///< endpoint runs: etheta_rad measured
};

struct ExperimentInfo {
  ExperimentKind kind = ExperimentKind::kFree;
  std::string file;
  double side_m = 0.0, distance_m = 0.0;
  bool endpoint = false;
  int runs = 0;
};

struct SubsetInfo {
  int experiment = 0;  ///< -1: campaign-wide
  std::string name;  ///< e.g. "cw, straight (first piece)"
};

struct PieceOptions {
  /// Longest piece of a straight leg or arc [m of travel] (> 0). Default 1.0.
  double max_piece_length_m = 1.0;
  /// Largest heading change of a spot-turn piece [rad] (> 0). Default 1.8
  /// (a 90 deg turn stays one piece, a 180 deg spin becomes two).
  double max_piece_angle_rad = 1.8;
  /// Cross-validation folds over runs (>= 2). Default 5.
  int folds = 5;
  /// Measure motions from / to the mean ground-truth pose of the adjacent
  /// standstills (see Piece). Default true.
  bool average_standstills = true;
  /// A motion from standstill whose start the encoders do
  /// not locate (its first count may come more than start_lead_fraction of
  /// a sample interval after the start, see pieces.cpp StartAmbiguous)
  /// starts at the last sample whose counts read still, one before its
  /// first moving interval: the castor kick (contract: at the start of the
  /// motion) may already show there. False: every motion starts at its
  /// first moving interval (the placement before; kept for comparison).
  /// Default true.
  bool start_before_first_count = true;
  /// See start_before_first_count (> 0). Default 0.1: with counts of the
  /// faster wheel n < 121 in the first moving interval.
  double start_lead_fraction = 0.1;
  sim::MotionOptions motion;  ///< stand_eps_m is set from the encoder tick

  std::string Check() const;
};

struct CampaignData {
  std::string path;  ///< manifest (for messages)
  RobotParams robot;
  std::optional<GroundTruthNoise> ground_truth;
  /// Nominal metres per tick (0 when the runs give distances): quantisation.
  double tick_left_m = 0.0, tick_right_m = 0.0;
  /// The stop reading the runs' quantisation follows (stop_model.hpp).
  StopModel stop_model = StopModel::kWheelEdge;
  std::vector<ExperimentInfo> experiments;
  std::vector<DiagRun> runs;
  std::vector<Piece> pieces;
  std::vector<SubsetInfo> subsets;
  int folds = 5;
  /// The experiments' data as read (the refined calibration works on them).
  std::vector<std::variant<EndpointData, TrajectoryData>> files;
};

/// Interval classes, castor kicks, active windows and junctions of a run
/// from its motions and wheel travel (again after the travel changes).
void AnnotateRun(DiagRun& r);

/// Builds the diagnosis' view of a loaded campaign. `files[i]` is experiment
/// i's data (io::ReadRunFile). Throws InputError when a run cannot be used
/// (a free experiment given as endpoint CSV, a square endpoint run whose
/// direction is not cw/ccw, a trajectory run without ground truth at its
/// first and last sample, or no piece at all).
CampaignData BuildCampaign(const Manifest& manifest, const std::vector<std::variant<EndpointData, TrajectoryData>>& files,
                           const PieceOptions& options = {});

/// Reads the manifest and every experiment file, then BuildCampaign.
CampaignData LoadCampaign(const std::string& manifest_path, const PieceOptions& options = {});

}  // namespace umbmark::diag
