// Parser and helpers for the predict path SPEC (see path_spec.hpp).
#include "error_models/path_spec.hpp"

#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "core/angles.hpp"
#include "core/errors.hpp"

namespace umbmark {
namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> Split(std::string_view s, char sep) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t pos = s.find(sep, start);
    if (pos == std::string_view::npos) {
      out.push_back(s.substr(start));
      return out;
    }
    out.push_back(s.substr(start, pos - start));
    start = pos + 1;
  }
}

}  // namespace

std::vector<PathSegment> ParsePathSpec(std::string_view spec) {
  if (Trim(spec).empty()) throw InvalidOptions("path spec is empty (expected e.g. line:10,line:-10)");
  std::vector<PathSegment> path;
  const auto tokens = Split(spec, ',');
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string_view tok = Trim(tokens[i]);
    auto fail = [&](const std::string& why) {
      return InvalidOptions(fmt::format("path segment {} '{}': {}", i + 1, tok, why));
    };
    const auto fields = Split(tok, ':');
    const std::string_view kind = Trim(fields[0]);
    std::vector<double> values;
    for (std::size_t f = 1; f < fields.size(); ++f) {
      const std::string_view t = Trim(fields[f]);
      double v = 0.0;
      const auto res = std::from_chars(t.data(), t.data() + t.size(), v);
      if (t.empty() || res.ec != std::errc() || res.ptr != t.data() + t.size())
        throw fail(fmt::format("'{}' is not a number", t));
      if (!std::isfinite(v)) throw fail(fmt::format("'{}' is not finite", t));
      values.push_back(v);
    }
    PathSegment seg;
    if (kind == "line") {
      if (values.size() != 1) throw fail("expected line:D");
      seg = {PathSegment::Kind::kLine, values[0], 0.0};
    } else if (kind == "turn") {
      if (values.size() != 1) throw fail("expected turn:ANGLE_RAD");
      seg = {PathSegment::Kind::kTurn, values[0], 0.0};
    } else if (kind == "arc") {
      if (values.size() != 2) throw fail("expected arc:L_LEFT:L_RIGHT");
      seg = {PathSegment::Kind::kArc, values[0], values[1]};
    } else {
      throw fail("unknown segment kind (expected line, turn or arc)");
    }
    path.push_back(seg);
  }
  return path;
}

std::vector<WheelSegment> ToWheelSegments(const std::vector<PathSegment>& path, double wheelbase_m) {
  std::vector<WheelSegment> out;
  out.reserve(path.size());
  for (const PathSegment& s : path) {
    switch (s.kind) {
      case PathSegment::Kind::kLine: out.push_back({s.a, s.a}); break;
      case PathSegment::Kind::kTurn: out.push_back({-0.5 * wheelbase_m * s.a, 0.5 * wheelbase_m * s.a}); break;
      case PathSegment::Kind::kArc: out.push_back({s.a, s.b}); break;
    }
  }
  return out;
}

std::string PathSpecToString(const std::vector<PathSegment>& path) {
  std::string out;
  for (const PathSegment& s : path) {
    if (!out.empty()) out += ',';
    switch (s.kind) {
      case PathSegment::Kind::kLine: out += fmt::format("line:{}", s.a); break;
      case PathSegment::Kind::kTurn: out += fmt::format("turn:{}", s.a); break;
      case PathSegment::Kind::kArc: out += fmt::format("arc:{}:{}", s.a, s.b); break;
    }
  }
  return out;
}

std::vector<PathSegment> BackAndForthPath(double distance_m) {
  return {{PathSegment::Kind::kLine, distance_m, 0.0}, {PathSegment::Kind::kLine, -distance_m, 0.0}};
}

std::vector<PathSegment> SquarePath(double side_m, bool clockwise) {
  std::vector<PathSegment> p;
  for (int k = 0; k < 4; ++k) {
    p.push_back({PathSegment::Kind::kLine, side_m, 0.0});
    p.push_back({PathSegment::Kind::kTurn, clockwise ? -kPi / 2.0 : kPi / 2.0, 0.0});
  }
  return p;
}

}  // namespace umbmark
