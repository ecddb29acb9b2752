#include "arrays.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "core/errors.hpp"

namespace py = pybind11;

namespace umbmark::python {
namespace {

[[noreturn]] void Fail(const std::string& message) { throw InputError(kRunsName, message); }

/// Two consecutive cumulative counts further apart than this: a counter that
/// wrapped (the trajectory CSV reader's rule, 2^30 ticks).
constexpr std::int64_t kMaxTickJump = std::int64_t{1} << 30;

/// One dict of columns, as given.
struct Columns {
  std::string where;  ///< "runs[i]" or "runs"
  py::dict dict;
  std::string Cell(const char* column) const { return fmt::format("{}['{}']", where, column); }
  bool Has(const char* column) const { return dict.contains(column) && !dict[column].is_none(); }
};

/// A numeric column as doubles: a float64 buffer (numpy) is copied as is,
/// any other buffer or sequence element by element through float().
std::vector<double> Doubles(const Columns& c, const char* column) {
  const py::object obj = c.dict[column];
  if (py::isinstance<py::str>(obj) || py::isinstance<py::bytes>(obj))
    Fail(fmt::format("{} is text; give an array of numbers", c.Cell(column)));
  if (PyObject_CheckBuffer(obj.ptr())) {
    const py::buffer_info info = py::reinterpret_borrow<py::buffer>(obj).request();
    if (info.ndim != 1) Fail(fmt::format("{} has {} dimensions; give a 1-D array", c.Cell(column), info.ndim));
    if (info.format == "d" && info.itemsize == 8) {
      std::vector<double> out(static_cast<std::size_t>(info.shape[0]));
      const auto* base = static_cast<const char*>(info.ptr);
      if (info.strides[0] == 8) {
        if (!out.empty()) std::memcpy(out.data(), base, out.size() * sizeof(double));
      } else {
        for (std::size_t i = 0; i < out.size(); ++i)
          std::memcpy(&out[i], base + static_cast<std::ptrdiff_t>(i) * info.strides[0], sizeof(double));
      }
      return out;
    }
  }
  std::vector<double> out;
  try {
    for (const py::handle item : py::iter(obj)) out.push_back(py::cast<double>(item));
  } catch (const py::error_already_set&) {
    Fail(fmt::format("{} is not an array of numbers", c.Cell(column)));
  } catch (const py::cast_error&) {
    Fail(fmt::format("{} is not an array of numbers", c.Cell(column)));
  }
  return out;
}

/// Cumulative tick counts: whole numbers (integer arrays, or floats with no
/// fractional part) within signed 64 bits.
std::vector<std::int64_t> Counts(const Columns& c, const char* column) {
  const py::object obj = c.dict[column];
  if (PyObject_CheckBuffer(obj.ptr())) {
    const py::buffer_info info = py::reinterpret_borrow<py::buffer>(obj).request();
    if (info.ndim == 1 && info.itemsize == 8 && (info.format == "l" || info.format == "q")) {
      std::vector<std::int64_t> out(static_cast<std::size_t>(info.shape[0]));
      const auto* base = static_cast<const char*>(info.ptr);
      for (std::size_t i = 0; i < out.size(); ++i)
        std::memcpy(&out[i], base + static_cast<std::ptrdiff_t>(i) * info.strides[0], sizeof(std::int64_t));
      return out;
    }
  }
  const std::vector<double> values = Doubles(c, column);
  std::vector<std::int64_t> out(values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    if (!(std::isfinite(v) && v == std::floor(v) && std::abs(v) < 9.2e18))
      Fail(fmt::format("{}[{}] = {} is not a whole tick count", c.Cell(column), i, v));
    out[i] = static_cast<std::int64_t>(v);
  }
  return out;
}

/// A text column: one string for every sample (a vector of one), or one
/// per sample (`n`).
std::vector<std::string> Texts(const Columns& c, const char* column, std::size_t n) {
  const py::object obj = c.dict[column];
  if (py::isinstance<py::str>(obj) || py::isinstance<py::int_>(obj)) return {std::string(py::str(obj))};
  std::vector<std::string> out;
  for (const py::handle item : py::iter(obj)) out.push_back(py::str(item));
  if (out.size() != n) Fail(fmt::format("{} has {} values, t_s has {}", c.Cell(column), out.size(), n));
  return out;
}

/// The run column: one id for all samples, one per sample as text, or one
/// per sample as an integer array (compared as numbers, named only where a
/// run starts: a million-sample id column costs no million strings).
struct RunIds {
  std::vector<std::string> text;
  std::vector<std::int64_t> number;
  std::size_t size() const { return number.empty() ? text.size() : number.size(); }
  bool Same(std::size_t i, std::size_t j) const {
    if (!number.empty()) return number[i] == number[j];
    return text.size() == 1 || text[i] == text[j];
  }
  std::string Name(std::size_t i) const {
    if (!number.empty()) return std::to_string(number[i]);
    return text.size() == 1 ? text[0] : text[i];
  }
};

RunIds ReadRunIds(const Columns& c, std::size_t n) {
  RunIds ids;
  const py::object obj = c.dict["run"];
  if (PyObject_CheckBuffer(obj.ptr())) {
    const py::buffer_info info = py::reinterpret_borrow<py::buffer>(obj).request();
    if (info.ndim == 1 && info.itemsize == 8 && (info.format == "l" || info.format == "q")) {
      ids.number = Counts(c, "run");
      if (ids.number.size() != n) Fail(fmt::format("{} has {} values, t_s has {}", c.Cell("run"), ids.number.size(), n));
      return ids;
    }
  }
  ids.text = Texts(c, "run", n);
  return ids;
}

/// The numeric columns of one dict, checked for names and equal lengths.
struct Samples {
  std::vector<double> t, left, right, gt[3];
  std::vector<std::int64_t> ticks_left, ticks_right;
  bool ticks = false;
  std::size_t size() const { return t.size(); }
};

Samples ReadSamples(const Columns& c) {
  Samples s;
  s.ticks = c.Has("ticks_left") || c.Has("ticks_right");
  const bool dist = c.Has("dist_left_m") || c.Has("dist_right_m");
  if (s.ticks && dist) Fail(fmt::format("{} gives both ticks_* and dist_*_m; give one of the two", c.where));
  const std::vector<const char*> wheels = dist ? std::vector<const char*>{"dist_left_m", "dist_right_m"}
                                               : std::vector<const char*>{"ticks_left", "ticks_right"};
  for (const char* column : {"t_s", wheels[0], wheels[1], "x_gt_m", "y_gt_m", "theta_gt_rad"}) {
    if (!c.Has(column)) {
      Fail(fmt::format("{} has no column '{}'{}", c.where, column,
                       dist ? "" : (column == wheels[0] || column == wheels[1]) ? " (or give dist_left_m, dist_right_m)"
                                                                                 : ""));
    }
  }
  s.t = Doubles(c, "t_s");
  if (s.ticks) {
    s.ticks_left = Counts(c, "ticks_left");
    s.ticks_right = Counts(c, "ticks_right");
  } else {
    s.left = Doubles(c, "dist_left_m");
    s.right = Doubles(c, "dist_right_m");
  }
  const char* gt_names[3] = {"x_gt_m", "y_gt_m", "theta_gt_rad"};
  for (int k = 0; k < 3; ++k) s.gt[k] = Doubles(c, gt_names[k]);
  if (s.t.empty()) Fail(fmt::format("{}['t_s'] is empty", c.where));
  auto same = [&](std::size_t n, const char* column) {
    if (n != s.t.size()) Fail(fmt::format("{} has {} values, t_s has {}", c.Cell(column), n, s.t.size()));
  };
  same(s.ticks ? s.ticks_left.size() : s.left.size(), wheels[0]);
  same(s.ticks ? s.ticks_right.size() : s.right.size(), wheels[1]);
  for (int k = 0; k < 3; ++k) same(s.gt[k].size(), gt_names[k]);
  return s;
}

/// Samples [begin, end) of `s` as one run, with the CSV reader's checks.
/// The columns are copied in bulk, or moved when the run is all of `s`
/// (one dict per run): no sample is handled twice.
TrajectoryRun MakeRun(const Columns& c, Samples& s, std::size_t begin, std::size_t end, std::string id,
                      const std::vector<std::string>& direction) {
  TrajectoryRun r;
  r.run = std::move(id);
  r.direction = CanonicalDirection(direction.size() > 1 ? direction[begin] : direction[0]);
  const char* gt_names[3] = {"x_gt_m", "y_gt_m", "theta_gt_rad"};
  for (std::size_t i = begin; i < end; ++i) {
    if (direction.size() > 1 && direction[i] != direction[begin] && CanonicalDirection(direction[i]) != r.direction)
      Fail(fmt::format("{}[{}] = '{}' differs from the run's first direction '{}'", c.Cell("direction"), i,
                       direction[i], r.direction));  // (one text: the whole run's)
    if (!std::isfinite(s.t[i])) Fail(fmt::format("{}[{}] = {} is not a finite number", c.Cell("t_s"), i, s.t[i]));
    if (i > begin && !(s.t[i] > s.t[i - 1]))
      Fail(fmt::format("{}[{}] = {} does not increase (sample {} of run {} has {})", c.Cell("t_s"), i, s.t[i], i - 1,
                       r.run, s.t[i - 1]));
    if (s.ticks) {
      for (const auto* v : {&s.ticks_left, &s.ticks_right}) {
        if (i == begin) continue;
        const std::int64_t a = (*v)[i - 1], b = (*v)[i];
        std::int64_t delta = 0;
        if (__builtin_sub_overflow(b, a, &delta) || delta >= kMaxTickJump || delta <= -kMaxTickJump)
          Fail(fmt::format("{}[{}] jumps from {} to {} ticks: counter wrap-around?",
                           c.Cell(v == &s.ticks_left ? "ticks_left" : "ticks_right"), i, a, b));
      }
    } else {
      for (const auto* v : {&s.left, &s.right}) {
        if (!std::isfinite((*v)[i]))
          Fail(fmt::format("{}[{}] = {} is not a finite number",
                           c.Cell(v == &s.left ? "dist_left_m" : "dist_right_m"), i, (*v)[i]));
      }
    }
    int given = 0;
    for (int k = 0; k < 3; ++k) {
      if (std::isinf(s.gt[k][i])) Fail(fmt::format("{}[{}] is infinite", c.Cell(gt_names[k]), i));
      given += std::isnan(s.gt[k][i]) ? 0 : 1;
    }
    if (given != 0 && given != 3)
      Fail(fmt::format("{} sample {}: partial ground truth (give x_gt_m, y_gt_m, theta_gt_rad all or none; NaN = "
                       "not measured)", c.where, i));
    if (given == 0 && (i == begin || i + 1 == end))
      Fail(fmt::format("{} run {} has no ground truth at its {} sample ({}; each run needs x_gt_m, y_gt_m, "
                       "theta_gt_rad at its first and last sample)", c.where, r.run, i == begin ? "first" : "last", i));
  }
  const bool all = begin == 0 && end == s.size();
  auto take = [&](auto& from, auto& to) {
    if (all) {
      to = std::move(from);
    } else {
      to.assign(from.begin() + static_cast<std::ptrdiff_t>(begin), from.begin() + static_cast<std::ptrdiff_t>(end));
    }
  };
  take(s.t, r.t_s);
  if (s.ticks) {
    take(s.ticks_left, r.ticks_left);
    take(s.ticks_right, r.ticks_right);
  } else {
    take(s.left, r.dist_left_m);
    take(s.right, r.dist_right_m);
  }
  take(s.gt[0], r.gt_x_m);
  take(s.gt[1], r.gt_y_m);
  take(s.gt[2], r.gt_theta_rad);
  r.lines.resize(end - begin);
  for (std::size_t i = begin; i < end; ++i) r.lines[i - begin] = i + 1;  // 1-based sample number
  return r;
}

Columns AsColumns(const py::handle& obj, std::string where) {
  if (!py::isinstance<py::dict>(obj))
    Fail(fmt::format("{} is a {}; give a dict of arrays named as the trajectory CSV's columns", where,
                     std::string(py::str(py::type::of(obj).attr("__name__")))));
  return {std::move(where), py::reinterpret_borrow<py::dict>(obj)};
}

}  // namespace

TrajectoryData TrajectoryFromArrays(const py::handle& runs) {
  TrajectoryData data;
  data.path = kRunsName;
  std::map<std::string, std::string> seen;  // run id -> where it was given
  auto add = [&](TrajectoryRun r, const std::string& where) {
    if (const auto it = seen.find(r.run); it != seen.end())
      Fail(fmt::format("{}: run id '{}' was already given by {}; run ids must be unique", where, r.run, it->second));
    seen.emplace(r.run, where);
    data.runs.push_back(std::move(r));
  };
  if (py::isinstance<py::dict>(runs)) {
    // One table with a run column: the rows of a run are consecutive.
    const Columns c = AsColumns(runs, "runs");
    if (!c.Has("run")) Fail("runs: one dict of columns needs a 'run' column (or give a list of dicts, one per run)");
    if (!c.Has("direction")) Fail("runs has no column 'direction'");
    Samples s = ReadSamples(c);
    const RunIds ids = ReadRunIds(c, s.size());
    const std::vector<std::string> dirs = Texts(c, "direction", s.size());
    for (std::size_t begin = 0; begin < s.size();) {
      std::size_t end = begin + 1;
      while (end < s.size() && ids.Same(end, begin)) ++end;
      add(MakeRun(c, s, begin, end, ids.Name(begin), dirs), fmt::format("runs['run'][{}]", begin));
      begin = end;
    }
    return data;
  }
  if (py::isinstance<py::str>(runs) || !py::isinstance<py::sequence>(runs))
    Fail("runs= takes a list of dicts of arrays (one per run) or one dict with a 'run' column");
  const auto list = py::reinterpret_borrow<py::sequence>(runs);
  if (list.size() == 0) Fail("runs= is an empty list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Columns c = AsColumns(list[i], fmt::format("runs[{}]", i));
    if (!c.Has("direction")) Fail(fmt::format("{} has no column 'direction' (cw or ccw for squares)", c.where));
    Samples s = ReadSamples(c);
    const std::vector<std::string> dirs = Texts(c, "direction", s.size());
    std::string id = std::to_string(i + 1);
    if (c.Has("run")) {
      const RunIds ids = ReadRunIds(c, s.size());
      for (std::size_t k = 1; k < ids.size(); ++k)
        if (!ids.Same(k, 0))
          Fail(fmt::format("{}['run'][{}] = '{}' differs from '{}': one dict holds one run", c.where, k, ids.Name(k),
                           ids.Name(0)));
      id = ids.Name(0);
    }
    add(MakeRun(c, s, 0, s.size(), std::move(id), dirs), c.where);
  }
  return data;
}

namespace {

/// A text cell, quoted when it holds a comma, a quote or a line break.
void AppendText(std::string& out, const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) {
    out += text;
    return;
  }
  out += '"';
  for (const char ch : text) {
    if (ch == '"') out += '"';
    out += ch;
  }
  out += '"';
}

}  // namespace

std::string TrajectoryCsv(const TrajectoryData& data) {
  const bool ticks = !data.runs.empty() && data.runs.front().has_ticks();
  std::string out = ticks ? "run,direction,t_s,ticks_left,ticks_right,x_gt_m,y_gt_m,theta_gt_rad\n"
                          : "run,direction,t_s,dist_left_m,dist_right_m,x_gt_m,y_gt_m,theta_gt_rad\n";
  std::size_t samples = 0;
  for (const auto& r : data.runs) samples += r.size();
  out.reserve(samples * 120);
  auto back = std::back_inserter(out);
  for (const auto& r : data.runs) {
    if (r.has_ticks() != ticks) Fail("every run must give ticks_* or every run dist_*_m, not a mix");
    std::string prefix;
    AppendText(prefix, r.run);
    prefix += ',';
    AppendText(prefix, r.direction);
    prefix += ',';
    for (std::size_t i = 0; i < r.size(); ++i) {
      out += prefix;
      if (ticks) {
        fmt::format_to(back, "{},{},{},", r.t_s[i], r.ticks_left[i], r.ticks_right[i]);
      } else {
        fmt::format_to(back, "{},{},{},", r.t_s[i], r.dist_left_m[i], r.dist_right_m[i]);
      }
      if (r.HasGroundTruth(i)) {
        fmt::format_to(back, "{},{},{}\n", r.gt_x_m[i], r.gt_y_m[i], r.gt_theta_rad[i]);
      } else {
        out += ",,\n";
      }
    }
  }
  return out;
}

}  // namespace umbmark::python
