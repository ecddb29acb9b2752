// What a person reads into a diagnosis: parameters in the units an engineer
// uses, p-values no finer than the computation can vouch for, the held-out
// evidence in words, fits that took physically impossible values (a
// symptom: the gap is something else than that effect), and, when the gap
// stays unexplained, which experiment to add and what to look at next.
// Used by the text report (report.cpp), the JSON (`next_steps`,
// `candidates[].unphysical`) and the HTML page (apps/diagnose_report.cpp).
#pragma once

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "diagnosis/pieces.hpp"
#include "diagnosis/plausibility.hpp"

namespace umbmark::diag {

struct DiagnoseSummary;

/// "name = value unit": mm (dx, dy, sigma, sigma_xy), mrad (kappa,
/// sigma_theta), ms (tau, tau_sd), per metre (rate), per run (r);
/// percent (s, a); dimensionless factors (k, rho) as they are. `se`: its
/// standard error in the same unit, when finite. `effect`: the effect the
/// parameter belongs to, where a name means two things (stop_slide's d in
/// s^2/m and a in s^2/rad; direction_asymmetry's a in percent).
std::string FormatEffectParam(const std::string& name, double value, double se = NAN,
                              const std::string& effect = "");

/// "< 1e-12" below 1e-12 (beyond what the chi^2 and bootstrap
/// approximations can vouch for), else three significant digits.
std::string FormatPValue(double p);

/// The held-out evidence in words. `heldout_gain_nats`: log-likelihood
/// gained on runs not used to fit; `evidence_nats`: the same minus the
/// complexity penalty; `heldout_shrink`: fraction of the gap closed held
/// out. Grades on the evidence in nats (Kass & Raftery 1995, on ln B):
/// < 0 none, < 1 weak, < 3 positive, < 5 strong, else very strong.
/// `noise_effect` (IsNoiseEffect: correlated_noise, bump_outliers,
/// standstill_motion, motion_noise_floor, run_time_offset,
/// wheel_noise_error): the sentence leads with the held-out likelihood and
/// says the mean gap is not what such an effect changes.
std::string EvidenceInWords(double heldout_gain_nats, double evidence_nats, double heldout_shrink,
                            bool noise_effect = false);

/// What the explanation's shrinks are measured against, as a clause for
/// the line that gives the unexplained share (text and HTML reports): empty
/// for `reference` "baseline", else the reference (docs/diagnosis.md, "The
/// shrink's reference") and the share left against the baseline itself
/// (`against_baseline`: DiagnoseSummary::heldout_shrink_against_baseline).
std::string ShrinkReferenceClause(const std::string& reference, double against_baseline);

/// What to do next, in order: for `none`, use the model; for a named
/// verdict, model the effects; for `unexplained`, the largest discrepancy
/// to look at, the experiments the campaign lacks to tell effects apart,
/// and the fits that came out unphysical.
std::vector<std::string> AdviseNextSteps(const CampaignData& c, const DiagnoseSummary& s);

/// What is wrong with the robot or the recording and what to do, in plain
/// words and the explained model's numbers, no statistics: the report's
/// first paragraph (text, HTML; JSON `summary`). Faulty runs first, then
/// the named effects (the recording's: marker, clocks; the robot's: the
/// others), or that nothing matters (`none`), or, for `unexplained`, where
/// the runs leave the model and what part the listed effects explain.
/// Needs s.next_steps (AdviseNextSteps) filled.
std::string PlainSummary(const DiagnoseSummary& s);

}  // namespace umbmark::diag
