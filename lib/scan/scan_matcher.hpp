// 2-D scan registration: point-to-line ICP (Censi's PL-ICP family) with
// projective data association. The model (the scan registered against) is
// kept per beam with a surface normal fitted to its neighbouring beams; a
// point of the other scan, moved by the current pose estimate, is paired
// with the nearest model point among the beams around its bearing, and the
// pose minimises the robust (Huber) sum of squared point-to-line distances
// by Gauss-Newton. Frames (sensor frames, x forward, y left):
//
//     model frame  --pose-->  scan frame      p_model = R(theta) p_scan + t
//
// The result carries the normal matrix J^T J (the information about x, y and
// heading the scene gives) so a caller can refuse a scene that does not pin
// the pose (a corridor, walls beyond the range).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "core/pose2.hpp"
#include "scan/laser_scan.hpp"

namespace umbmark::scan {

struct Point2 {
  double x = 0.0, y = 0.0;
};

/// The valid beams of a scan as points in its sensor frame.
std::vector<Point2> ScanPoints(const LaserScan& scan);

/// A scan prepared as a registration target.
class ScanModel {
 public:
  explicit ScanModel(const LaserScan& scan);
  std::size_t beams() const { return points_.size(); }
  /// Model points with a usable normal.
  std::size_t usable() const { return usable_; }

 private:
  friend struct MatchKernel;
  std::vector<Point2> points_;   ///< per beam; NaN when no return
  std::vector<Point2> normals_;  ///< per beam; NaN when no line fits the neighbours
  std::vector<unsigned char> shadow_;  ///< per beam: next to a beam nearer by more than 0.1 m (an occluder's edge behind)
  double angle_min_ = 0.0, angle_increment_ = 0.0;
  bool full_circle_ = false;
  std::size_t usable_ = 0;
};

/// Registration settings; the defaults suit an indoor lidar with about 1 cm
/// range noise and 0.25 - 1 deg beam spacing.
struct MatchOptions {
  int max_iterations = 60;
  int search_beams = 6;           ///< beams searched either side of a point's bearing
  double max_pair_distance_m = 0.5;  ///< a pair farther apart is no pair
  double initial_gate_m = 0.25;   ///< point-to-line gate of the first iteration, shrinking to final_gate
  double min_gate_m = 0.03;       ///< smallest point-to-line gate
  double huber_k = 1.345;         ///< Huber threshold in robust standard deviations
  double min_noise_m = 0.001;     ///< floor of the robust residual scale
  double tolerance_m = 1e-7;      ///< stop when the step moves a point at 1 m less than this
  /// No pairs with model points within 2 beams of a beam more than 0.1 m
  /// nearer (the background beside an occluder's edge, where the other scan
  /// sees the surface the occluder hides). Off by default (the squares
  /// import's accuracy was measured without it); calibrate-lidar's
  /// registrations turn it on (lidar_pairs.hpp).
  bool skip_shadow_edges = false;
  /// Empty when valid, else a message naming the bad field.
  std::string Validate() const;
};

struct MatchResult {
  Pose2 pose;  ///< model_T_scan
  /// J^T J of the point-to-line residuals over the final pairs (row-major,
  /// x, y, theta), in the model frame, unweighted.
  std::array<double, 9> information{};
  double residual_sd_m = 0.0;  ///< sqrt(sum r^2 / (pairs - 3))
  std::size_t pairs = 0, points = 0;
  int iterations = 0;
  bool converged = false;
  double PairedFraction() const { return points == 0 ? 0.0 : static_cast<double>(pairs) / static_cast<double>(points); }
  /// residual_sd^2 * information^-1 (row-major); huge where the scene does not pin the pose.
  std::array<double, 9> Covariance() const;
};

/// Registers `points` (in the scan's sensor frame) against `model` starting
/// from `guess` (model_T_scan).
MatchResult MatchScan(const ScanModel& model, const std::vector<Point2>& points, const Pose2& guess,
                      const MatchOptions& options = {});

/// Directions a registration leaves undetermined, judged from its
/// information matrix against a well-posed scene with the same number of
/// pairs (dilution of precision: each direction's standard deviation times
/// sqrt(pairs / 2) over the range noise, a heading's at a 1 m lever). The
/// information is rotated by `frame_yaw` first (sensor -> robot frame), so
/// x and y are the robot's. Returns the names ("along x", "along y",
/// "heading") whose dilution exceeds `max_dilution`, worst first.
std::vector<std::string> UndeterminedDirections(const std::array<double, 9>& information, std::size_t pairs,
                                                double frame_yaw, double max_dilution);

}  // namespace umbmark::scan
