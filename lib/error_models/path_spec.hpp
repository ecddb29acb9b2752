// Path SPEC of `umbmark predict` (contract): comma-separated segments
//   line:D                 both wheels roll D [m] (D < 0 reverses)
//   turn:ANGLE_RAD         spot turn about the axle centre (+ = left / ccw)
//   arc:L_LEFT:L_RIGHT     left / right wheel travel [m], any signs
// e.g. "line:10,line:-10". Whitespace around tokens is ignored.
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace umbmark {

struct PathSegment {
  enum class Kind { kLine, kTurn, kArc };
  Kind kind = Kind::kLine;
  double a = 0.0;  ///< line: D [m]; turn: angle [rad]; arc: left travel [m]
  double b = 0.0;  ///< arc: right travel [m]
};

/// Commanded wheel travels of one constant-curvature segment [m].
struct WheelSegment {
  double left_m = 0.0;
  double right_m = 0.0;
};

/// Parses a path SPEC. Throws InvalidOptions naming the segment (1-based),
/// its text and what is wrong (unknown kind, wrong field count, non-finite
/// or unparsable number, empty spec).
std::vector<PathSegment> ParsePathSpec(std::string_view spec);

/// Wheel travels of each segment for wheelbase B [m] (turn: L = -(B/2) a,
/// R = +(B/2) a).
std::vector<WheelSegment> ToWheelSegments(const std::vector<PathSegment>& path, double wheelbase_m);

/// The canonical text of a path ("line:10,line:-10").
std::string PathSpecToString(const std::vector<PathSegment>& path);

/// Convenience paths: D forward then D back (Chong & Kleeman section 6.3),
/// and a UMBmark square (four legs of `side_m`, four spot turns of -+pi/2
/// for cw / ccw).
std::vector<PathSegment> BackAndForthPath(double distance_m);
std::vector<PathSegment> SquarePath(double side_m, bool clockwise);

}  // namespace umbmark
