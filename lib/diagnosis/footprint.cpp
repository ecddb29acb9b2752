// Footprint check of the noise effects (see footprint.hpp).
#include "diagnosis/footprint.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <fmt/format.h>

namespace umbmark::diag {

namespace {

/// Ranks 0..n-1 of v (ties broken by position: continuous residuals).
std::vector<double> Ranks(const std::vector<double>& v) {
  std::vector<std::size_t> idx(v.size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::sort(idx.begin(), idx.end(), [&](std::size_t a, std::size_t b) { return v[a] < v[b]; });
  std::vector<double> r(v.size());
  for (std::size_t k = 0; k < idx.size(); ++k) r[idx[k]] = static_cast<double>(k);
  return r;
}

double Pearson(const std::vector<double>& a, const std::vector<double>& b) {
  const double n = static_cast<double>(a.size());
  double ma = 0.0, mb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) ma += a[i] / n, mb += b[i] / n;
  double sab = 0.0, saa = 0.0, sbb = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    sab += (a[i] - ma) * (b[i] - mb);
    saa += (a[i] - ma) * (a[i] - ma);
    sbb += (b[i] - mb) * (b[i] - mb);
  }
  return saa > 0.0 && sbb > 0.0 ? sab / std::sqrt(saa * sbb) : 0.0;
}

}  // namespace

FootprintCheck CheckNoiseFootprint(const CampaignData& c, const std::vector<double>& eps,
                                   const std::vector<PieceBases>& bases, const NoiseParams& n) {
  FootprintCheck out;
  std::vector<double> first, second;
  double sum_r0 = 0.0;
  for (std::size_t j = 0; j + 1 < c.pieces.size(); ++j) {
    const Piece &p = c.pieces[j], &q = c.pieces[j + 1];
    if (p.run != q.run || p.b != q.a || q.motion_first || p.ends_at_standstill || q.starts_from_standstill) continue;
    if (p.type != PieceType::kStraight || q.type != PieceType::kStraight || p.components != 3 || q.components != 3)
      continue;
    const double vp = PieceCovariance(bases[j], n)(2, 2), vq = PieceCovariance(bases[j + 1], n)(2, 2);
    if (!(vp > 0.0 && vq > 0.0)) continue;
    first.push_back(eps[3 * j + 2]);
    second.push_back(eps[3 * j + 5]);
    sum_r0 += std::max(-1.0, -n.sth2 / std::sqrt(vp * vq));
  }
  out.pairs = static_cast<int>(first.size());
  if (out.pairs < 8) return out;
  out.checked = true;
  // Spearman's rank correlation (bumps make the residuals heavy-tailed: a
  // few large products would swing Pearson's), against the Gaussian
  // model's rank correlation (6 / pi) asin(r0 / 2); Fisher's z with the
  // rank correlation's variance factor 1.06.
  const double kPi = 3.14159265358979323846;
  out.correlation = Pearson(Ranks(first), Ranks(second));
  out.expected_correlation = 6.0 / kPi * std::asin(0.5 * sum_r0 / out.pairs);
  out.z = (std::atanh(std::clamp(out.correlation, -0.999, 0.999)) - std::atanh(out.expected_correlation)) /
          std::sqrt(1.06 / (out.pairs - 3));
  // Significant and large: the errors of a motion cancel (an eccentric
  // wheel: -0.7 to -0.9), not a sampling wobble of independent ones.
  out.consistent = !(out.z < -kFootprintZ && out.correlation < out.expected_correlation - 0.3);
  out.text = out.consistent
                 ? fmt::format("adjacent stretches of the legs have independent heading errors, as a noise effect "
                               "gives (rank correlation {:.2f}, {:.2f} expected from the ground truth's noise; z = {:.1f} "
                               "over {} pairs)",
                               out.correlation, out.expected_correlation, out.z, out.pairs)
                 : fmt::format("adjacent stretches of the legs have heading errors that cancel (rank correlation {:.2f}, "
                               "{:.2f} expected from the ground truth's noise; z = {:.1f} over {} pairs): the error "
                               "comes and goes within a motion (a bounded error such as an eccentric or out-of-round "
                               "wheel), which no noise effect on the list does; never named",
                               out.correlation, out.expected_correlation, out.z, out.pairs);
  return out;
}

}  // namespace umbmark::diag
