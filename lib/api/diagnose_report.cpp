// Plots and report page of a diagnosis (see diagnose_report.hpp).
#include "api/diagnose_report.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <fmt/format.h>

#include "diagnosis/advice.hpp"
#include "diagnosis/explanation.hpp"
#include "report/html_report.hpp"
#include "report/svg_plot.hpp"

namespace umbmark::api {

namespace {

/// One component of one piece's standardised residual (JSON piece_residuals).
struct PieceMark {
  int experiment = 0;  ///< 1-based
  std::string run, type;
  double travel_start_m = 0.0;
  int component = 0;  ///< 0 x, 1 y, 2 theta
  double z = 0.0;
};

constexpr const char* kComponentNames[3] = {"x (along)", "y (lateral)", "theta"};

/// The `n` largest |z| over every piece and component, largest first.
std::vector<PieceMark> TopPieceResiduals(const nlohmann::json& j, std::size_t n) {
  std::vector<PieceMark> all;
  if (!j.contains("piece_residuals")) return all;
  for (const auto& p : j["piece_residuals"].value("pieces", nlohmann::json::array())) {
    const auto& z = p.at("z");
    for (int k = 0; k < 3; ++k) {
      if (!z[k].is_number()) continue;
      all.push_back({p.value("experiment", 0), p.value("run", ""), p.value("type", ""), p.value("travel_start_m", 0.0), k,
                     z[k].get<double>()});
    }
  }
  const std::size_t m = std::min(n, all.size());
  std::partial_sort(all.begin(), all.begin() + static_cast<std::ptrdiff_t>(m), all.end(),
                    [](const PieceMark& a, const PieceMark& b) { return std::abs(a.z) > std::abs(b.z); });
  all.resize(m);
  return all;
}

constexpr std::size_t kTopPieces = 8;

// One panel per experiment: every piece's standardised residual (x, y,
// theta) at its place along the experiment's runs laid end to end, against
// the band +-1.96 that holds 95 % of them when the baseline is right; the
// kTopPieces largest of the campaign ringed and numbered (listed in the
// report's table). Values beyond the axis limit (10 SE at most, so the band
// stays readable) are drawn at the edge and said so. Returns the bottom.
// One function: one pass per experiment gathers points, run starts, the
// fraction outside the band and the marks that the panel then draws.
double ResidualPanels(const nlohmann::json& j, double top, std::vector<std::string>& parts) {
  if (!j.contains("piece_residuals")) return top;
  const auto& pieces = j["piece_residuals"].value("pieces", nlohmann::json::array());
  const auto labels = j.value("experiments", nlohmann::json::array());
  const auto ranked = TopPieceResiduals(j, kTopPieces);
  int experiments = 0;
  for (const auto& p : pieces) experiments = std::max(experiments, p.value("experiment", 0));
  for (int e = 1; e <= experiments; ++e) {
    std::array<std::vector<io::SvgPoint>, 3> comp;
    std::vector<io::SvgPoint> clipped, marks;
    std::vector<double> run_starts;
    std::vector<std::pair<io::SvgPoint, int>> mark_labels;
    double offset = 0.0, run_end = 0.0, zmax = 0.0;
    std::string run;
    int total = 0, outside = 0;
    for (const auto& p : pieces) {
      if (p.value("experiment", 0) != e) continue;
      const std::string id = p.value("run", "");
      if (id != run) {
        if (!run.empty()) { offset = run_end; run_starts.push_back(offset); }
        run = id;
      }
      const double start = p.value("travel_start_m", 0.0), len = p.value("travel_m", 0.0);
      run_end = std::max(run_end, offset + start + len);
      const auto& z = p.at("z");
      for (int k = 0; k < 3; ++k) {
        if (!z[k].is_number()) continue;
        const double v = z[k].get<double>();
        ++total;
        outside += std::abs(v) > 1.96 ? 1 : 0;
        zmax = std::max(zmax, std::abs(v));
        comp[k].push_back({offset + start + 0.5 * len, v});
        for (std::size_t r = 0; r < ranked.size(); ++r)
          if (ranked[r].experiment == e && ranked[r].run == id && ranked[r].travel_start_m == start &&
              ranked[r].component == k && ranked[r].z == v)
            mark_labels.push_back({comp[k].back(), static_cast<int>(r + 1)});
      }
    }
    if (total == 0) continue;
    const double limit = std::clamp(1.1 * zmax, 4.0, 10.0);
    for (auto& c : comp)
      for (auto& pt : c)
        if (std::abs(pt.y) > limit) {
          pt.y = std::copysign(limit, pt.y);
          clipped.push_back(pt);
        }
    for (auto& [pt, r] : mark_labels) {
      pt.y = std::clamp(pt.y, -limit, limit);
      marks.push_back(pt);
    }
    const std::string label =
        e - 1 < static_cast<int>(labels.size()) ? labels[e - 1].get<std::string>() : fmt::format("{}", e);
    io::SvgPanel p(90, top + 24, 760, 220, fmt::format("Experiment {}: residual of every piece", label));
    const double right = std::max(run_end, 1e-3);
    p.SetExtent(-0.02 * right, 1.02 * right, -limit * 1.05, limit * 1.05, false);
    p.Band({{-0.02 * right, -1.96}, {1.02 * right, -1.96}}, {{-0.02 * right, 1.96}, {1.02 * right, 1.96}}, "#777", 0.22);
    p.Axes("travel along the experiment's runs, end to end [m] (file order; dotted: a run starts)",
           "residual [standard errors]");
    const io::SvgStyle run_line{"#999", "", "2,3", 0.8, false};
    for (double x : run_starts) p.VLine(x, run_line);
    const io::SvgStyle styles[3] = {{"#1f5fa8", "circle", "", 1.5, false},
                                    {"#c0601a", "square", "", 1.5, false},
                                    {"#222222", "triangle", "", 1.5, true}};
    for (int k = 0; k < 3; ++k) p.Points(comp[k], styles[k], 2.6, kComponentNames[k]);
    const io::SvgStyle mark_style{"#b02020", "circle", "", 1.5, false};
    p.Points(marks, mark_style, 8.0, "largest");
    // Numbers beside the rings, kept inside the panel for values at its edge.
    for (const auto& [pt, r] : mark_labels)
      p.Text({pt.x, std::clamp(pt.y, -0.9 * limit, 0.85 * limit)}, fmt::format("  {}", r), "#b02020", 12);
    std::vector<std::pair<io::SvgStyle, std::string>> legend = {
        {{"#777", "square", "", 1.5, true},
         fmt::format("95% band of the baseline (|z| <= 1.96): {:.1f}% of the values lie outside (5% expected)",
                     100.0 * outside / total)},
        {styles[0], "x: along the piece's start heading"},
        {styles[1], "y: lateral (to the left)"},
        {styles[2], "theta: heading"},
        {mark_style, fmt::format("the {} largest of the campaign (numbered as in the table)", ranked.size())}};
    if (!clipped.empty())
      legend.push_back({{"#999", "", "", 0.0, false},
                        fmt::format("{} value(s) beyond +-{:.0f} drawn at the edge", clipped.size(), limit)});
    p.Legend(legend);
    parts.push_back(p.Render());
    top = p.Bottom() + 16;
  }
  return top;
}

}  // namespace

// Plots of a diagnosis, from its JSON (so they follow whatever the diagnosis
// provides): the standardised size of each located discrepancy against the
// 95% band of the baseline model, largest marked, grouped by experiment;
// the held-out shrink of each candidate effect; and, when the diagnosis
// explains the gap by several effects, the cumulative held-out shrink as
// they are added.
std::string DiagnosePlotsSvg(const nlohmann::json& j) {
  std::vector<std::string> parts;
  double bottom = ResidualPanels(j, 0, parts) + 20;
  const auto& where = j.at("gap").value("where", nlohmann::json::array());
  if (!where.empty()) {
    io::SvgPanel p(90, bottom + 20, 760, 300, "Which statistics leave the model: ranked discrepancies (per subset of pieces)");
    std::vector<io::SvgPoint> in_band, out_band;
    double zmax = 3.0;
    std::vector<std::string> labels;
    for (std::size_t i = 0; i < where.size(); ++i) {
      const double z = where[i].value("size_se", 0.0);
      zmax = std::max(zmax, std::abs(z) + 1.0);
      (std::abs(z) > 1.96 ? out_band : in_band).push_back({static_cast<double>(i + 1), z});
    }
    const double right = static_cast<double>(where.size()) + 0.7;
    p.SetExtent(0.3, right, std::min(-zmax / 4, -2.5), zmax, false);
    p.Band({{0.3, -1.96}, {right, -1.96}}, {{0.3, 1.96}, {right, 1.96}}, "#777", 0.2);
    p.Axes("discrepancy rank (1 = largest)", "size [standard errors]");
    p.Points(in_band, {"#35608f", "circle", "", 1.5, false}, 4);
    p.Points(out_band, {"#b02020", "triangle", "", 1.5, true}, 5.5);
    for (std::size_t i = 0; i < std::min<std::size_t>(where.size(), 5); ++i) {
      const auto& w = where[i];
      p.Text({static_cast<double>(i + 1) + 0.15, w.value("size_se", 0.0)},
             fmt::format("{}: {} {} ({})", i + 1, w.value("statistic", ""), w.value("component", ""), w.value("subset", "")),
             "#111", 10);
    }
    p.Legend({{{"#777", "square", "", 1.5, true}, "95% band of the baseline model (|z| <= 1.96)"},
              {{"#b02020", "triangle", "", 1.5, true}, "discrepancy outside the band (top 5 labelled)"},
              {{"#35608f", "circle", "", 1.5, false}, "discrepancy within the band"}});
    parts.push_back(p.Render());
    bottom = p.Bottom() + 30;
  }
  std::vector<std::string> names;
  std::vector<double> shrink, heldout;
  for (const auto& c : j.value("candidates", nlohmann::json::array())) {
    if (names.size() >= 12) break;
    names.push_back(c.value("effect", "?"));
    shrink.push_back(c.contains("shrink") && c["shrink"].is_number() ? c["shrink"].get<double>() : NAN);
    heldout.push_back(c.contains("heldout_shrink") && c["heldout_shrink"].is_number() ? c["heldout_shrink"].get<double>() : NAN);
  }
  if (!names.empty()) {
    parts.push_back(fmt::format(R"svg(<g transform="translate(0,{:.0f})">)svg", bottom) +
                    io::SvgBarChart("How much of the gap each candidate effect closes (best first)", names,
                                    {heldout, shrink}, {"held-out shrink (runs not used to fit)", "in-sample shrink"},
                                    {"#1f5fa8", "#444444"}, "shrink = 1 - gap after / gap before (1: gap gone)") +
                    "</g>\n");
    bottom += 44 + (2 * 12 + 10) * static_cast<double>(names.size()) + 50 + 2 * 16 + 20;
  }
  const auto& ex = j.value("explanation", nlohmann::json::array());
  if (!ex.empty()) {
    std::vector<std::string> steps;
    std::vector<double> cum, cum_held;
    std::string so_far;
    for (const auto& e : ex) {
      so_far += (so_far.empty() ? "" : " + ") + e.value("effect", "?");
      steps.push_back(so_far);
      cum.push_back(e.value("cumulative_shrink", NAN));
      cum_held.push_back(e.value("cumulative_heldout_shrink", NAN));
    }
    parts.push_back(fmt::format(R"svg(<g transform="translate(0,{:.0f})">)svg", bottom) +
                    io::SvgBarChart("The explanation: gap closed as effects are added", steps, {cum_held, cum},
                                    {"cumulative held-out shrink", "cumulative in-sample shrink"}, {"#1f7a3a", "#444444"},
                                    "fraction of the gap closed") +
                    "</g>\n");
    bottom += 44 + (2 * 12 + 10) * static_cast<double>(steps.size()) + 50 + 2 * 16 + 20;
  }
  return io::SvgDocument(900, bottom + 10, parts);
}

namespace {

double Number(const nlohmann::json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : NAN;
}

/// "p = 0.0031" or "p < 1e-12".
std::string PText(double p) {
  const std::string v = diag::FormatPValue(p);
  return v.rfind("<", 0) == 0 ? "p " + v : "p = " + v;
}

/// The verdict's reason as a sentence after another: its first letter in
/// upper case (the reason starts in lower case: it follows "verdict: ..."
/// in the text report), unless it starts with a name (an effect's, such as
/// castor_kick, which is written as the contract spells it).
std::string Sentence(std::string s) {
  const std::string first = s.substr(0, s.find(' '));
  if (!s.empty() && s[0] >= 'a' && s[0] <= 'z' && first.find('_') == std::string::npos)
    s[0] = static_cast<char>(s[0] - 'a' + 'A');
  return s;
}

/// Fitted parameters with units (and standard errors when given).
std::string ParamsText(const nlohmann::json& params, const nlohmann::json& se, const std::string& effect) {
  std::string out;
  for (const auto& [k, val] : params.items()) {
    if (!val.is_number()) continue;
    const double e = se.contains(k) && se[k].is_number() ? se[k].get<double>() : NAN;
    out += (out.empty() ? "" : ", ") + diag::FormatEffectParam(k, val.get<double>(), e, effect);
  }
  return out;
}

std::string Percent(double v) {
  if (!std::isfinite(v)) return "-";
  const double pct = std::round(100.0 * v);
  return fmt::format("{:.0f}%", pct == 0.0 ? 0.0 : pct);  // no "-0%"
}

/// The baseline's numbers with units, and the explained model's calibration
/// (verdict.explained_model) beside them.
void BaselineTable(io::HtmlReport& rep, const nlohmann::json& j) {
  const nlohmann::json& b = j["baseline"];
  const nlohmann::json given = b.value("given", nlohmann::json());
  rep.Heading(given.is_object() ? fmt::format("Baseline model (your simulation, {})", given.value("source", "?"))
                                : std::string("Baseline model (fitted to these runs)"));
  std::vector<std::vector<std::string>> rows = {
      {"E_d (wheel diameter ratio)", fmt::format("{:.6f}", Number(b, "E_d"))},
      {"E_b (wheelbase factor)", fmt::format("{:.6f}", Number(b, "E_b"))},
      {"k_L, k_R (wheel noise)", fmt::format("{:.3g}, {:.3g} m^1/2 ({:.2f}, {:.2f} mm after 1 m)", Number(b, "k_L"),
                                             Number(b, "k_R"), 1e3 * Number(b, "k_L"), 1e3 * Number(b, "k_R"))},
      {fmt::format("ground truth noise ({})", b.value("ground_truth_noise_estimated", false) ? "estimated" : "as stated"),
       fmt::format("{:.3g} mm, {:.3g} mrad", 1e3 * Number(b, "sigma_xy_m"), 1e3 * Number(b, "sigma_theta_rad"))},
      {"runs, pieces compared", fmt::format("{}, {}", b.value("runs", 0), b.value("pieces", 0))}};
  const nlohmann::json e =
      j.contains("verdict") ? j["verdict"].value("explained_model", nlohmann::json()) : nlohmann::json();
  if (e.is_object()) {
    rows.push_back({"E_d, E_b with the explanation's effects fitted",
                    fmt::format("{:.6f}, {:.6f}", Number(e, "E_d"), Number(e, "E_b"))});
    rows.push_back({"the robot with them: wheelbase; wheel diameters (left, right)",
                    fmt::format("{:.5f} m; {:.5f}, {:.5f} m", Number(e, "wheelbase_m"),
                                Number(e, "wheel_diameter_left_m"), Number(e, "wheel_diameter_right_m"))});
  }
  rep.Table({"parameter", "value"}, rows);
  if (e.is_object())
    rep.Paragraph("The baseline fits E_d, E_b without any effect, so it takes in part of what the effects do (a marker "
                  "offset can move its E_b by tens of percent). The explained model fits them with the explanation's "
                  "effects: it is the robot with them accounted for (on the physics engine's campaigns within 0.001 of the "
                  "true E_b; with a 4-5 cm marker on real runs, within a few percent). To confirm it, fix or model the "
                  "effects, record again and calibrate.");
}

/// `diagnose --baseline`: the given model's parameters, and for each one
/// the verdict names as wrong, the value to set instead.
void GivenModelTable(io::HtmlReport& rep, const nlohmann::json& j) {
  const nlohmann::json given = j.contains("baseline") ? j["baseline"].value("given", nlohmann::json()) : nlohmann::json();
  if (!given.is_object()) return;
  std::map<std::string, double> corrected;
  for (const auto& c : j.value("corrections", nlohmann::json::array()))
    corrected[c.value("parameter", "")] = Number(c, "corrected");
  std::vector<std::vector<std::string>> rows;
  auto row = [&](const char* key, const char* unit, int digits) {
    if (!given.contains(key) || !given[key].is_number()) return;
    const auto it = corrected.find(key);
    rows.push_back({key, fmt::format("{:.{}f} {}", given[key].get<double>(), digits, unit),
                    it == corrected.end() ? std::string("keep") : fmt::format("set {:.{}f} {}", it->second, digits, unit)});
  };
  row("wheelbase_m", "m", 5);
  row("wheel_diameter_left_m", "m", 6);
  row("wheel_diameter_right_m", "m", 6);
  row("k_L", "m^1/2", 6);
  row("k_R", "m^1/2", 6);
  rep.Heading("Your simulation: what to change");
  rep.Table({"parameter", "your value", "the runs say"}, rows);
  if (!given.value("noise_given", false))
    rep.Paragraph("Wheel noise not given (--kl, --kr): it was fitted to the runs (baseline table above) and is not "
                  "checked.");
}

/// Why a candidate is never named although it may fit: a clock the moving
/// samples do not show, a noise effect whose footprint the runs contradict
/// (the evidence text of candidates[].clock_check / footprint_check).
std::string NeverNamed(const nlohmann::json& c) {
  if (c.contains("clock_check") && !c["clock_check"].value("supported", true))
    return c["clock_check"].value("evidence", std::string("the moving samples do not show it"));
  if (c.contains("footprint_check") && !c["footprint_check"].value("consistent", true))
    return c["footprint_check"].value("evidence", std::string("the runs contradict its footprint"));
  return {};
}

/// Candidate effects: parameters with units, shrink, evidence in words,
/// and the impossible fits flagged as symptoms.
void CandidateTable(io::HtmlReport& rep, const nlohmann::json& j) {
  rep.Heading("Candidate effects (best first)");
  rep.Paragraph("Each effect is fitted on top of the baseline. Shrink: the fraction of the gap it closes (1 = gap gone); "
                "held-out: measured on runs not used to fit it, which is what to trust. Evidence: held-out "
                "log-likelihood gain minus a penalty per parameter, graded on Kass & Raftery's scale for Bayes factors (none, weak, positive, strong, very strong). "
                "LR p: likelihood-ratio test against the baseline.");
  std::vector<std::vector<std::string>> rows;
  std::vector<std::vector<std::string>> symptoms, never;
  for (const auto& c : j.value("candidates", nlohmann::json::array())) {
    const double gain = Number(c, "heldout_loglik_gain_nats"), ev = Number(c, "evidence_nats");
    const std::string words = diag::EvidenceInWords(gain, ev, Number(c, "heldout_shrink"));
    const std::string unphysical = c.value("unphysical", "");
    const std::string effect = c.value("effect", "?");
    const std::string why_not = NeverNamed(c);
    if (!why_not.empty()) never.push_back({effect, Percent(Number(c, "heldout_shrink")), why_not});
    if (!unphysical.empty()) symptoms.push_back({effect, ParamsText(c.value("params", nlohmann::json::object()), nlohmann::json::object(), effect), unphysical});
    rows.push_back({effect, ParamsText(c.value("params", nlohmann::json::object()), c.value("params_se", nlohmann::json::object()), effect),
                    Percent(Number(c, "heldout_shrink")), Percent(Number(c, "shrink")),
                    words.substr(0, words.find(':')) + (std::isfinite(ev) ? fmt::format(" ({:+.1f} nats)", ev) : ""),
                    c.contains("lr_p_value") && c["lr_p_value"].is_number() ? diag::FormatPValue(c["lr_p_value"].get<double>())
                                                                           : std::string("-"),
                    (unphysical.empty() ? std::string("plausible") : "IMPOSSIBLE: a symptom") +
                        (why_not.empty() ? "" : "; never named")});
  }
  rep.Table({"effect", "fitted parameters", "held-out shrink", "shrink", "evidence", "LR p", "physically"}, rows, 2);
  if (!never.empty()) {
    rep.Heading("Fits that are never named: another mechanism's footprint");
    rep.Paragraph("These effects may close part of the gap, but the runs contradict how they act: a clock offset shows "
                  "on the samples taken while the robot moves (a slide or settling at the stops does not), and every "
                  "listed noise effect leaves the two halves of a leg independent (a bounded wheel-angle error, such "
                  "as an eccentric wheel, makes them cancel).");
    rep.Table({"effect", "held-out shrink", "why it is not the cause"}, never, 3);
  }
  if (!symptoms.empty()) {
    rep.Heading("Impossible fits: symptoms, not causes");
    rep.Paragraph("These effects fitted values no robot can have. The effect is not the cause: it bent itself to imitate "
                  "something else in the runs, so the gap is something else.");
    rep.Table({"effect", "fitted", "why no robot can have it"}, symptoms, 3);
  }
}

/// The stepwise explanation: cumulative shrink and size per step.
void ExplanationTable(io::HtmlReport& rep, const nlohmann::json& j) {
  const auto& ex = j.value("explanation", nlohmann::json::array());
  if (ex.empty()) return;
  rep.Heading("The explanation: effects added one at a time, fitted jointly");
  const double threshold = Number(j.at("verdict"), "negligible_threshold");
  std::vector<std::vector<std::string>> rows;
  int k = 0;
  for (const auto& e : ex) {
    // An impossible fit is marked as what it is: a symptom, never named.
    const std::string flag =
        e.contains("unphysical")         ? std::string(" (impossible value: a symptom)")
        : e.value("negligible", false)   ? std::string(" (negligible)")
        : e.value("not_decisive", false) ? fmt::format(" (not decisive: {:+.1f} nats given the others)",
                                                       Number(e, "earned_given_others_nats"))
        : e.contains("outside_range")    ? std::string(" (outside the physical range: not named)")
        : e.contains("spread_of_named")
            ? fmt::format(" ({}'s spread: not named)", e.value("spread_of_named", "?"))
            : std::string();
    // The flag goes with the effect's name (a text column, which wraps).
    rows.push_back({fmt::format("{}", ++k), e.value("effect", std::string("?")) + flag,
                    ParamsText(e.value("params", nlohmann::json::object()), nlohmann::json::object(), e.value("effect", "")),
                    Percent(Number(e, "cumulative_heldout_shrink")), Percent(Number(e, "cumulative_shrink")),
                    fmt::format("{:.2f} mm / {:.2f} mrad", Number(e, "size_mm"), Number(e, "size_mrad")),
                    // A noise effect's size: the growth of one piece type's spread.
                    e.contains("size_pieces")
                        ? fmt::format("+{:.0f}% sd of {} pieces", 100.0 * Number(e, "relative_size"),
                                      e.value("size_pieces", "?"))
                        : fmt::format("{:.{}f}", Number(e, "relative_size"),
                                      diag::RelativeSizeDecimals(Number(e, "relative_size"), threshold))});
  }
  rep.Table({"step", "effect", "parameters", "gap closed, held-out", "in-sample", "size over a run",
             "size / noise of one piece"},
            rows, 3);
  for (const auto& y : j.value("symptoms", nlohmann::json::array()))  // impossible fits: never steps
    rep.Paragraph(fmt::format("Symptom, not a step: {} {} ({}).", y.value("effect", "?"),
                              ParamsText(y.value("params", nlohmann::json::object()), nlohmann::json::object(),
                                         y.value("effect", "")),
                              y.value("why", "")));
  const auto& v = j.at("verdict");
  const std::string against =
      diag::ShrinkReferenceClause(v.value("shrink_reference", std::string("baseline")),
                                  v.value("heldout_shrink_against_baseline", 0.0));
  rep.Paragraph(fmt::format("{} of the gap stays unexplained on held-out runs{}. An effect is negligible when its size is "
                            "below {:.2g} x the noise of one piece (1 m of travel or a spot turn), or, for a noise "
                            "effect, when it widens the pose spread of the pieces it acts on by less than {:.0f}% "
                            "(median per piece type, the type it widens most): then it is reported but never the "
                            "verdict. An effect is not decisive when, given the other effects, the held-out runs are "
                            "less than 100 times more probable with it (after the penalty for its parameters): it "
                            "stays a step, but the verdict does not name it. A noise effect is a mechanism's spread "
                            "when the larger part of its scatter lies where that mechanism moves the mean, or scatters "
                            "by itself, at least as far: the mechanism varies from event to event about its value, "
                            "and the verdict names the mechanism alone.",
                            Percent(Number(v, "unexplained_fraction")), against, Number(v, "negligible_threshold"),
                            100.0 * Number(v, "negligible_threshold")));
}

/// What the explained model leaves (verdict.remaining_where): where to look
/// next when the verdict is not named.
void RemainingTable(io::HtmlReport& rep, const nlohmann::json& j) {
  const auto& v = j.at("verdict");
  const auto& left = v.value("remaining_where", nlohmann::json::array());
  if (left.empty()) return;
  rep.Heading("What is left after the explanation, where");
  rep.Paragraph(fmt::format("The gap statistics of the explained model (the baseline with the explanation's effects, "
                            "fitted jointly): G = {:.3g} left, where 0 is the model's own noise and {:.3g} the level "
                            "the gap test calls significant. The largest parts say where the runs still leave the model: "
                            "plot those pieces (umbmark evaluate --report) before adding effects.",
                            Number(v, "remaining_score"), Number(j.at("gap"), "null_quantile_1_minus_alpha")));
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < std::min<std::size_t>(left.size(), 8); ++i) {
    const auto& w = left[i];
    rows.push_back({w.value("experiment_label", std::string("?")), w.value("subset", std::string()),
                    w.value("statistic", std::string()), w.value("component", std::string()),
                    fmt::format("{}", w.value("n", 0)), fmt::format("{:+.1f}", Number(w, "size_se"))});
  }
  rep.Table({"experiment", "pieces", "statistic", "component", "n", "size [SE]"}, rows, 4);
}

/// The largest piece residuals, numbered as in the plot.
void TopPiecesTable(io::HtmlReport& rep, const nlohmann::json& j) {
  const auto top = TopPieceResiduals(j, kTopPieces);
  if (top.empty()) return;
  rep.Heading("The largest piece residuals (numbered as in the plot)");
  std::vector<std::vector<std::string>> rows;
  for (std::size_t i = 0; i < top.size(); ++i) {
    const auto& t = top[i];
    rows.push_back({fmt::format("{}", i + 1), fmt::format("{}", t.experiment), t.run, t.type,
                    fmt::format("{:.2f} m", t.travel_start_m), kComponentNames[t.component], fmt::format("{:+.2f}", t.z)});
  }
  rep.Table({"#", "experiment", "run", "piece", "starts after", "component", "residual [SE]"}, rows, 4);
}

/// Faulty runs (contract `run_faults`), left out of every fit: which run,
/// what is wrong with it and what to do, then the test.
void RunFaultTable(io::HtmlReport& rep, const nlohmann::json& j) {
  const auto faults = j.value("run_faults", nlohmann::json::array());
  if (faults.empty()) return;
  rep.Heading("Faulty runs (left out of every fit below)");
  std::vector<std::vector<std::string>> rows;
  for (const auto& f : faults) {
    const auto& run = f.at("run");
    rows.push_back({fmt::format("{}", f.value("experiment", 0)), run.is_string() ? run.get<std::string>() : run.dump(),
                    f.value("what", "")});
  }
  // No numeric column: the text wraps (a numeric cell does not).
  rep.Table({"experiment", "run", "what is wrong, what to do"}, rows, 3);
  rep.Paragraph("Test: " + j.value("run_fault_test", std::string()) + ".");
}

}  // namespace

// The page: verdict and next steps first (from the diagnosis' own
// next_steps), then the numbers (gap, baseline, candidates with units and
// evidence in words, explanation, largest residuals), then the plots.
std::string DiagnoseReportHtml(const nlohmann::json& j, const std::string& manifest) {
  io::HtmlReport rep("umbmark diagnose", manifest);
  const auto& v = j.at("verdict");
  const std::string effect = v.value("effect", "?");
  const auto& gap = j.at("gap");
  const double p = Number(gap, "p_value");
  // What is wrong and what to do in plain words first (the diagnosis'
  // `summary`); the verdict's statistics follow the next steps.
  const std::string plain = j.value("summary", std::string());
  std::string stats;
  if (effect == "none") {
    stats = fmt::format("No gap that matters between the runs and the model ({}). {}", PText(p), Sentence(v.value("reason", "")));
  } else if (effect == "unexplained") {
    stats = fmt::format("The runs leave the model ({}) and no known effect explains it. {}", PText(p), Sentence(v.value("reason", "")));
  } else {
    stats = fmt::format("The runs leave the model ({}); the cause: {}. {}", PText(p), effect, Sentence(v.value("reason", "")));
  }
  rep.Headline(plain.empty() ? stats : plain, effect == "none"          ? io::HtmlReport::Level::kGood
                                              : effect == "unexplained" ? io::HtmlReport::Level::kBad
                                                                        : io::HtmlReport::Level::kWarn);
  std::vector<std::string> steps;
  for (const auto& s : j.value("next_steps", nlohmann::json::array()))
    if (s.is_string()) steps.push_back(s.get<std::string>());
  rep.NextSteps(steps);
  if (!plain.empty()) rep.Paragraph("Verdict: " + stats);
  RunFaultTable(rep, j);
  std::vector<std::string> warnings;
  for (const auto& w : j.value("warnings", nlohmann::json::array())) warnings.push_back(w.get<std::string>());
  for (const auto& w : j.value("notes", nlohmann::json::array()))
    if (w.is_string()) warnings.push_back(w.get<std::string>());
  for (const auto& w : j.value("indistinguishable", nlohmann::json::array()))
    if (w.is_string()) warnings.push_back("cannot tell apart: " + w.get<std::string>());
  rep.Warnings(warnings);
  rep.Heading("Gap");
  rep.Table({"quantity", "value"},
            {{"gap score G (0 = the model's own noise)",
              fmt::format("{:.3g} (null median {:.3g})", Number(gap, "score"), Number(gap, "null_median"))},
             {"p-value (combined: G and the likelihood-ratio tests)", diag::FormatPValue(p)},
             {"p-value of G alone", diag::FormatPValue(Number(gap, "score_p_value"))},
             {"null simulations; alpha", fmt::format("{}; {}", gap.value("null_simulations", 0), Number(gap, "alpha"))}});
  if (j.contains("baseline")) BaselineTable(rep, j);
  GivenModelTable(rep, j);
  CandidateTable(rep, j);
  ExplanationTable(rep, j);
  RemainingTable(rep, j);
  TopPiecesTable(rep, j);
  rep.Heading("Plots");
  rep.Figure(DiagnosePlotsSvg(j),
             "First: every piece's residual under the baseline, per experiment, in standard errors, against the band "
             "that holds 95% of them when the model is right; the largest are ringed and numbered. Then: the ranked "
             "discrepancies per subset of pieces, how much of the gap each effect closes, and the explanation.");
  return rep.Render();
}

}  // namespace umbmark::api
