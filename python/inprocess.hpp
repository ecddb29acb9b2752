// The Python module's functions that run in the interpreter's own process,
// over the library's lib/api calls (the same calls the command line
// makes): keyword arguments named as the command's long options become the
// <Command>Options, `runs=` arrays become in-memory data (no CSV), and the
// GIL is released while the library computes. Errors become the exceptions
// of the command line's exit statuses with its messages.
#pragma once

#include <pybind11/pybind11.h>

#include "result.hpp"

namespace umbmark::python {

/// umbmark.calibrate(*inputs, **options): api::Calibrate.
Result CalibrateInProcess(const pybind11::args& inputs, const pybind11::kwargs& options);
/// umbmark.predict(**options): api::Predict.
Result PredictInProcess(const pybind11::args& inputs, const pybind11::kwargs& options);
/// umbmark.fit_noise(*inputs, **options): api::FitNoise (with plot=,
/// report=, ros2= or runs=, the executable, which writes those).
Result FitNoiseInProcess(const pybind11::args& inputs, const pybind11::kwargs& options);
/// umbmark.summarize(*inputs, **options): api::Summarize (with csv= or
/// report=, the executable).
Result SummarizeInProcess(const pybind11::args& inputs, const pybind11::kwargs& options);
/// umbmark.simulate(manifest, **options): api::Simulate.
Result SimulateInProcess(const pybind11::args& inputs, const pybind11::kwargs& options);
/// umbmark.diagnose(manifest, **options): api::Diagnose (with plot= or
/// report=, the executable, which draws them).
Result DiagnoseInProcess(const pybind11::args& inputs, const pybind11::kwargs& options);

}  // namespace umbmark::python
