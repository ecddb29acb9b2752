// Importer for one dataset folder of the OptiOdom project (Sousa et al.,
// J Intell Robot Syst 2022; data under MIT licence):
//   <id>_metadata.csv   key,value rows padded with commas: ngear, encRes
//                       (ticks per wheel rev = ngear * encRes), Li (wheelbase,
//                       m), Di (right, left diameters, m), N (runs), L
//                       (square side, m; empty for other paths), ...
//   <id>_run-NN.csv     no header: time [s], x_gt [m], y_gt [m], theta_gt
//                       [rad, unwrapped], right ticks, left ticks; ticks are
//                       increments since the previous row, so the first row's
//                       belong to before the run.
// The result is the contract's robot + one experiment (square with its side,
// or free) and trajectory runs with cumulative ticks (0 at the first sample).
#pragma once

#include <optional>
#include <string>

#include "core/runs.hpp"

namespace umbmark::io {

struct OptiOdomDataset {
  std::string id;        ///< folder name, e.g. 230620202042
  std::string category;  ///< square | circular | ivanjko | free (parent folder name)
  RobotParams robot;     ///< Li, Di, ngear * encRes
  Experiment experiment;  ///< square (side from L) or free; file = "runs.csv"
  TrajectoryData runs;   ///< direction cw/ccw for squares (from GT rotation), else the category
};

/// Reads the folder. The category is the parent folder's name when it is one
/// of square/circular/ivanjko/free, else `category` must be given (or it is
/// "square" when L is set, "free" otherwise). Square run directions come from
/// the ground-truth total rotation (about -2 pi is cw), never from file
/// order. Throws InputError (file, line, column) on any fault.
OptiOdomDataset ImportOptiOdom(const std::string& dir, const std::optional<std::string>& category = std::nullopt);

}  // namespace umbmark::io
