// Standardised piece residuals of the baseline (see piece_residuals.hpp).
#include "diagnosis/piece_residuals.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <nlohmann/json.hpp>

#include "diagnosis/baseline.hpp"
#include "diagnosis/piece_noise.hpp"

namespace umbmark::diag {

std::vector<PieceResidual> StandardisedPieceResiduals(const CampaignData& c, const BaselineFit& b) {
  // Campaign order: runs are already in experiment / file order; pieces of
  // one run sorted by their start sample.
  std::vector<std::size_t> order(c.pieces.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t i, std::size_t j) {
    const Piece &p = c.pieces[i], &q = c.pieces[j];
    const int ei = c.runs[p.run].experiment, ej = c.runs[q.run].experiment;
    if (ei != ej) return ei < ej;
    if (p.run != q.run) return p.run < q.run;
    return p.a < q.a;
  });
  std::vector<PieceResidual> out;
  out.reserve(order.size());
  std::vector<double> along(c.runs.size(), 0.0);
  for (std::size_t j : order) {
    const Piece& piece = c.pieces[j];
    const Eigen::Matrix3d cov = PieceCovariance(b.bases[j], b.noise);
    PieceResidual r;
    r.run = piece.run;
    r.experiment = c.runs[piece.run].experiment;
    r.run_id = c.runs[piece.run].id;
    r.type = piece.type;
    r.travel_start_m = along[piece.run];
    r.travel_m = piece.travel_m;
    along[piece.run] += piece.travel_m;
    for (int k = 0; k < 3; ++k) {
      const double sd = std::sqrt(std::max(cov(k, k), 0.0));
      const bool measured = k < piece.components;
      r.z[k] = measured && sd > 0.0 ? b.eps[3 * j + k] / sd : NAN;
    }
    out.push_back(std::move(r));
  }
  return out;
}

nlohmann::json PieceResidualsToJson(const std::vector<PieceResidual>& r) {
  // Three decimals of a standard error are plenty for a plot and keep the
  // file small on campaigns with thousands of pieces.
  auto z = [](double v) -> nlohmann::json {
    if (!std::isfinite(v)) return nullptr;
    return std::round(v * 1000.0) / 1000.0;
  };
  nlohmann::json pieces = nlohmann::json::array();
  for (const auto& p : r) {
    pieces.push_back({{"experiment", p.experiment + 1},
                      {"run", p.run_id},
                      {"type", PieceTypeToString(p.type)},
                      {"travel_start_m", std::round(p.travel_start_m * 1e4) / 1e4},
                      {"travel_m", std::round(p.travel_m * 1e4) / 1e4},
                      {"z", {z(p.z[0]), z(p.z[1]), z(p.z[2])}}});
  }
  return {{"components", {"x (along the piece's start heading)", "y (to its left)", "theta"}},
          {"band95", 1.96},
          {"pieces", pieces}};
}

}  // namespace umbmark::diag
