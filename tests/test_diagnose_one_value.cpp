// Issue 28, item 5: one value per quantity, a monotone explanation, and
// impossible fits as symptoms, checked on what a user reads. The example
// campaign (data/examples/diagnose.toml, a castor that kicks at every
// start) is diagnosed through the command line; every parameter of every
// explanation step must show the same value, formatted the same way, in the
// text report, the JSON, the HTML page and the suggested `simulate`
// command. The explanation must add held-out evidence at every step (more
// than the penalty of 2 nats per parameter); no step may be a fit no robot
// can have or a noise effect fitted at zero, and no candidate fitted at
// zero is credited with shrink (before: standstill_motion at sigma 0 showed
// 24 % held-out shrink here). And the report opens with the plain-words
// summary, before the statistics.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "diagnosis/advice.hpp"
#include "report/xml_escape.hpp"
#include "support/run_cli.hpp"

using namespace umbmark;

namespace {
const std::filesystem::path kEx = std::filesystem::path(UMBMARK_SOURCE_DIR) / "data/examples";
}  // namespace

TEST_CASE("diagnose: one value per quantity in text, JSON, HTML and simulate; a monotone explanation",
          "[diagnose][report][cli]") {
  using testing::Q;
  const auto dir = testing::TempDir("diagnose-one-value");
  const auto r = testing::RunCli("diagnose " + Q(kEx / "diagnose.toml") + " --null-sims 50 --report " +
                                 Q(dir / "d.html") + " --json " + Q(dir / "d.json"));
  INFO(r.err);
  REQUIRE(r.status == 0);
  const auto j = nlohmann::json::parse(testing::Slurp((dir / "d.json").string()));
  const std::string html = testing::Slurp((dir / "d.html").string());
  const std::string& text = r.out;
  std::string steps;
  for (const auto& s : j.at("next_steps")) steps += s.get<std::string>() + "\n";
  const auto& ex = j.at("explanation");
  REQUIRE_FALSE(ex.empty());
  CHECK(j.at("verdict").at("effect") == "castor_kick");
  // What is left, where: the gap statistics of the explained model, whose G
  // the explanation's last step computed in its own fit (FitSet), largest
  // first, in the JSON and the text.
  const auto& left = j.at("verdict").at("remaining_where");
  REQUIRE_FALSE(left.empty());
  CHECK(j.at("verdict").at("remaining_score").get<double>() ==
        Approx(ex.back().at("gap_after").get<double>()).epsilon(1e-9));
  for (std::size_t i = 1; i < left.size(); ++i)
    CHECK(std::abs(left[i - 1].at("size_se").get<double>()) >= std::abs(left[i].at("size_se").get<double>()));
  CHECK(text.find("what is left after the explanation, where (G = " +
                  fmt::format("{:.1f}", j.at("verdict").at("remaining_score").get<double>())) != std::string::npos);
  for (const auto& e : ex) {
    const std::string effect = e.at("effect");
    INFO(effect);
    // Every step gains held-out likelihood beyond its penalty.
    CHECK(e.at("heldout_gain_nats").get<double>() > 2.0 * static_cast<double>(e.at("params").size()));
    // No symptom as a step: neither an impossible value nor a noise effect
    // whose every variance is zero.
    CHECK_FALSE(e.contains("unphysical"));
    std::map<std::string, double> params;
    for (const auto& [k, v] : e.at("params").items()) params[k] = v.get<double>();
    CHECK(diag::UnphysicalFit(effect, params, j.at("baseline").at("runs").get<int>()).empty());
    if (effect == "standstill_motion") CHECK(params.at("sigma_xy") + params.at("sigma_theta") > 1e-6);
    if (effect == "motion_noise_floor") CHECK(params.at("sigma") > 1e-6);
    // One value: the same formatted value in the text, the HTML and the
    // simulate command (for the effects the verdict names).
    for (const auto& [k, v] : params) {
      const std::string shown = diag::FormatEffectParam(k, v, NAN, effect);
      INFO(shown);
      CHECK(text.find(shown) != std::string::npos);
      CHECK(html.find(io::XmlEscape(shown)) != std::string::npos);
      if (!e.at("negligible").get<bool>()) CHECK(steps.find(fmt::format("{}={:.4g}", k, v)) != std::string::npos);
    }
  }
  // A noise candidate fitted at zero is credited with nothing.
  for (const auto& c : j.at("candidates")) {
    std::map<std::string, double> params;
    for (const auto& [k, v] : c.at("params").items()) params[k] = v.get<double>();
    if (diag::NullNoiseFit(c.at("effect"), params).empty()) continue;
    INFO(c.dump());
    CHECK(c.at("heldout_shrink").get<double>() == 0.0);
    CHECK(c.at("heldout_loglik_gain_nats").get<double>() == 0.0);
  }
  // The kick in the plain summary is the explanation's kick, in mrad.
  double kappa = NAN;
  for (const auto& e : ex)
    if (e.at("effect") == "castor_kick") kappa = e.at("params").at("kappa").get<double>();
  REQUIRE(std::isfinite(kappa));
  const std::string summary = j.at("summary");
  CHECK(summary.find(fmt::format("{:.1f} mrad", 1e3 * std::abs(kappa))) != std::string::npos);
  // Plain words first: the summary opens the text and the page, before the
  // statistics (the baseline section, the gap table).
  const auto in_text = text.find("In short: " + summary);
  REQUIRE(in_text != std::string::npos);
  CHECK(in_text < text.find("1. Baseline"));
  CHECK(in_text < text.find("p ="));
  const auto in_html = html.find(io::XmlEscape(summary));
  REQUIRE(in_html != std::string::npos);
  CHECK(in_html < html.find("<h2>Gap</h2>"));
  CHECK(summary.find("castor") != std::string::npos);
}
