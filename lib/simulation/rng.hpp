// Random numbers for the simulator. Every run draws from its own streams,
// derived from (seed, run index, stream id) by SplitMix64 hashing, so a run's
// result depends on nothing else: not on the thread count, on which SIMD lane
// computes it, or on how many runs are simulated.
//
//  - SplitMix64 (Steele, Lea & Flood 2014): seeding / hashing.
//  - xoshiro256++ (Blackman & Vigna 2019): the stream generator.
//  - Normal pairs by the Box-Muller transform (exact: a uniform radius
//    variate and a uniform direction), evaluated with the branch-free
//    polynomials of fast_math.hpp so the vectorised kernel and scalar code
//    produce the same numbers.
#pragma once

#include <bit>
#include <cstdint>

#include "simulation/fast_math.hpp"

namespace umbmark::sim {

/// One SplitMix64 step: advances *state and returns the next output.
inline std::uint64_t SplitMix64Next(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// Seed of the stream `stream` of run `run` under the user's `seed`.
inline std::uint64_t StreamSeed(std::uint64_t seed, std::uint64_t run, std::uint64_t stream) {
  std::uint64_t s = seed;
  std::uint64_t h = SplitMix64Next(s);
  s = h ^ (run * 0xD1B54A32D192ED03ull);
  h = SplitMix64Next(s);
  s = h ^ (stream * 0x8CB92BA72F3D8DD7ull);
  return SplitMix64Next(s);
}

/// Stream ids (documented so runs stay reproducible when effects are added:
/// a new effect takes a new stream id and leaves the others unchanged).
enum Stream : std::uint64_t {
  kStreamWheelNoise = 0,   ///< per-partition wheel noise (the hot loop)
  kStreamRunSetup = 1,     ///< initial pose (P0), encoder phases
};

/// xoshiro256++ state, seeded from a 64-bit value with SplitMix64.
struct Xoshiro256pp {
  std::uint64_t s[4];

  explicit Xoshiro256pp(std::uint64_t seed = 0) {
    std::uint64_t sm = seed;
    for (auto& v : s) v = SplitMix64Next(sm);
  }
  static constexpr std::uint64_t Rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::uint64_t Next() {
    const std::uint64_t result = Rotl(s[0] + s[3], 23) + s[0];
    const std::uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = Rotl(s[3], 45);
    return result;
  }
  /// Uniform on [0, 1) with 52 random bits.
  double Uniform() { return fm::Unit52(Next()); }
};

/// Two independent N(0, 1) variates from two 64-bit random words by
/// Box-Muller: radius sqrt(-2 ln u), u in (0, 1] from the 52 high bits of
/// `a`; direction uniform on the circle from `b` (3 bits pick the octant,
/// 52 bits the angle inside it). |z| <= sqrt(-2 ln 2^-52) < 8.5.
inline void NormalPairFromBits(std::uint64_t a, std::uint64_t b, double& z0, double& z1) {
  const double u = 2.0 - fm::One52(a);  // (0, 1]
  const double radius = fm::Sqrt(-2.0 * fm::LogUnit(u));
  const double angle = fm::Unit52(b) * (fm::kPi / 4.0);  // [0, pi/4)
  double c, s;
  fm::SinCosQuarter(angle, s, c);
  const bool swap = (b & 1u) != 0;
  const double p = swap ? s : c, q = swap ? c : s;
  z0 = fm::FlipSign(radius * p, (b >> 1) & 1u);
  z1 = fm::FlipSign(radius * q, (b >> 2) & 1u);
}

/// Largest |z| NormalPairFromBits can return (used to prove a fast path safe).
inline constexpr double kMaxAbsNormal = 8.5;

}  // namespace umbmark::sim
