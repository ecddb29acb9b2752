// `umbmark diagnose` as one library call (lib/api, see calibrate.hpp for
// the pattern): where a campaign leaves the baseline model (E_d, E_b, k_L,
// k_R), which contract effect causes the gap, and how far it shrinks once
// that effect is modelled (lib/diagnosis/diagnose.hpp), with the data's
// warnings. The --plot and --report pages are drawn from ToJson() by the
// command line (apps/diagnose_report.hpp).
//
//   api::DiagnoseOptions o;
//   o.manifest = "campaign.toml";
//   o.diag.null_simulations = 200;
//   const api::DiagnoseResult r = api::Diagnose(o);   // r.summary.verdict
//   nlohmann::json j = api::ToJson(r);                 // == `--json` of the command
//
// Errors: InvalidOptions (Check()'s message), InputError (a bad manifest or
// data, a design that cannot determine the baseline, a --baseline of
// another robot).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "diagnosis/diagnose.hpp"

namespace umbmark::api {

/// Every option of `umbmark diagnose` but the output files (the flag in
/// brackets).
struct DiagnoseOptions {
  std::string manifest;  ///< [MANIFEST] campaign manifest (required)
  /// [--null-sims] (20 to 10^6), [--alpha] (1e-6 to 0.5),
  /// [--min-heldout-shrink] (0.01 to 1), [--penalty] (>= 0), [--folds] (2
  /// to 100), [--piece-length] (0.01 to 1000 m), [--no-likelihood-tests],
  /// [--no-standstill-averaging], [--negligible] (>= 0), [--max-effects] (1
  /// to 12), [--seed], [--threads] (1 to 256), [--where] (>= 0); `effects`,
  /// `given` and `progress` are set from the fields here.
  diag::DiagnoseOptions diag;
  /// [--effects] effect names to try; empty = the contract's fourteen (with
  /// a baseline also its parameter errors).
  std::vector<std::string> effects;
  std::string baseline;               ///< [--baseline] a `calibrate` JSON: your simulation's parameters
  bool baseline_other_robot = false;  ///< [--baseline-other-robot] accept another robot's baseline
  /// [--kl, --kr] with a baseline: your simulation's wheel noise [m^1/2]
  /// (both or neither; unset: fitted).
  std::optional<double> k_L, k_R;
  ProgressCallback progress;  ///< thousandths (DiagnoseOptions::progress); empty = none

  /// "" when valid, else a message naming the bad field by its flag.
  std::string Check() const;
};

struct DiagnoseResult {
  std::string manifest;             ///< JSON `manifest`
  diag::DiagnoseSummary summary;    ///< gap, candidates, explanation, verdict, ... (diag::DiagnoseToJson)
  std::vector<std::string> data_warnings;  ///< degenerate data, per file (appended to JSON `warnings`)
};

DiagnoseResult Diagnose(const DiagnoseOptions& options);
/// The JSON `--json` writes.
nlohmann::json ToJson(const DiagnoseResult& result);

}  // namespace umbmark::api
