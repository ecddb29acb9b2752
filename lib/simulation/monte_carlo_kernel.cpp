// Monte Carlo run kernel: kSimLanes runs per call, vectorised across runs;
// see monte_carlo_kernel.hpp for the model and the numerics.
//
// Floating-point contraction (a*b+c -> fma) is switched off for this file so
// that the baseline, AVX2 and AVX-512 builds of the kernel give identical
// bits, which keeps every run reproducible from (seed, run index) on any x86
// CPU. It must come before the includes so the inline helpers get it too.
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off", "no-trapping-math")
#endif

#include "simulation/monte_carlo_kernel.hpp"

#include <cmath>
#include <algorithm>
#include <atomic>
#include <string>
#include <cstring>

#include <Eigen/Eigenvalues>

#include "kinematics/diff_drive.hpp"
#include "simulation/fast_math.hpp"
#include "simulation/rng.hpp"

namespace umbmark::sim {
namespace {

constexpr int W = kSimLanes;

/// Lane state of one block of runs.
struct alignas(64) BlockState {
  double x[W], y[W], th[W], c[W], s[W];
  std::uint64_t r0[W], r1[W], r2[W], r3[W];
};

/// One segment with its per-lane partition means and noise.
struct alignas(64) LaneSegment {
  double ml[W], mr[W];  ///< mean true travel per partition [m]
  double sl[W], sr[W];  ///< noise standard deviation per partition [m]
  int partitions = 1;
  /// Largest possible half angle |h| of a partition: <= 1/16 (kTiny),
  /// <= pi/4 (kQuarter), else the libm path (kGeneral).
  enum class Path { kTiny, kQuarter, kGeneral } path = Path::kTiny;
};

/// Where a traced block writes its samples (nullptr: no recording).
struct Recorder {
  int every = 1;
  std::vector<RunTrace>* traces = nullptr;  ///< W entries
  int lanes = W;                            ///< valid lanes
  void Store(const BlockState& b, int segment, int partition) const {
    for (int j = 0; j < lanes; ++j) {
      RunTrace& t = (*traces)[j];
      t.segment.push_back(segment);
      t.partition.push_back(partition);
      t.truth.push_back({b.x[j], b.y[j], b.th[j]});
    }
  }
};

#define UMBMARK_INLINE [[gnu::always_inline]] inline

UMBMARK_INLINE std::uint64_t Rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

/// Partitions whose normals are generated ahead in one batch: the normal
/// generator (long dependency chains: log, square root) and the pose update
/// (a short chain carried from partition to partition) run as two loops so
/// the CPU overlaps many independent normal computations (software
/// pipelining). 2 x 32 x kSimLanes doubles = 8 KiB, in L1.
constexpr int kChunk = 32;

/// The fast path of one segment for all lanes (branch-free, vectorisable).
/// kTiny: every half angle |h| <= 1/16 (short polynomials), else <= pi/4.
template <bool kRecord, bool kTiny>
UMBMARK_INLINE void FastSegment(BlockState& __restrict b, const LaneSegment& __restrict seg, double inv_b,
                                int seg_index, const Recorder* rec) {
  const double half_inv_b = 0.5 * inv_b;
  alignas(64) double z0[kChunk][W], z1[kChunk][W];
  for (int p0 = 0; p0 < seg.partitions; p0 += kChunk) {
    const int n = std::min(kChunk, seg.partitions - p0);
    // 1. Normals for n partitions (xoshiro256++, two outputs per pair).
    for (int q = 0; q < n; ++q) {
#pragma GCC unroll 1
      for (int j = 0; j < W; ++j) {
        std::uint64_t s0 = b.r0[j], s1 = b.r1[j], s2 = b.r2[j], s3 = b.r3[j];
        const std::uint64_t ra = Rotl(s0 + s3, 23) + s0;
        std::uint64_t t = s1 << 17;
        s2 ^= s0;
        s3 ^= s1;
        s1 ^= s2;
        s0 ^= s3;
        s2 ^= t;
        s3 = Rotl(s3, 45);
        const std::uint64_t rb = Rotl(s0 + s3, 23) + s0;
        t = s1 << 17;
        s2 ^= s0;
        s3 ^= s1;
        s1 ^= s2;
        s0 ^= s3;
        s2 ^= t;
        s3 = Rotl(s3, 45);
        b.r0[j] = s0;
        b.r1[j] = s1;
        b.r2[j] = s2;
        b.r3[j] = s3;
        NormalPairFromBits(ra, rb, z0[q][j], z1[q][j]);
      }
    }
    // 2. The exact arc of every partition.
    for (int q = 0; q < n; ++q) {
#pragma GCC unroll 1
      for (int j = 0; j < W; ++j) {
        // Wheel travel of this partition (eq. 4) and the exact arc.
        const double l = fm::Fma(seg.sl[j], z0[q][j], seg.ml[j]);
        const double r = fm::Fma(seg.sr[j], z1[q][j], seg.mr[j]);
        const double h = (r - l) * half_inv_b;
        double sinc, ch;
        if constexpr (kTiny) {
          fm::SincCosTiny(h, sinc, ch);
        } else {
          fm::SincCosQuarter(h, sinc, ch);
        }
        const double sh = h * sinc;
        const double chord = 0.5 * (l + r) * sinc;
        const double c = b.c[j], s = b.s[j];
        const double cm = fm::Fma(c, ch, -s * sh), sm = fm::Fma(s, ch, c * sh);
        b.x[j] = fm::Fma(chord, cm, b.x[j]);
        b.y[j] = fm::Fma(chord, sm, b.y[j]);
        b.c[j] = fm::Fma(cm, ch, -sm * sh);
        b.s[j] = fm::Fma(sm, ch, cm * sh);
        b.th[j] = fm::Fma(r - l, inv_b, b.th[j]);
      }
      if constexpr (kRecord) {
        const int p = p0 + q;
        if ((p + 1) % rec->every == 0 || p + 1 == seg.partitions) rec->Store(b, seg_index, p + 1);
      }
    }
  }
}

/// The general path (any per-partition angle): libm sin/cos, scalar.
template <bool kRecord>
void GeneralSegment(BlockState& b, const LaneSegment& seg, double wheelbase, int seg_index, const Recorder* rec) {
  for (int p = 0; p < seg.partitions; ++p) {
    for (int j = 0; j < W; ++j) {
      Xoshiro256pp g(0);
      g.s[0] = b.r0[j];
      g.s[1] = b.r1[j];
      g.s[2] = b.r2[j];
      g.s[3] = b.r3[j];
      const std::uint64_t ra = g.Next(), rb = g.Next();
      b.r0[j] = g.s[0];
      b.r1[j] = g.s[1];
      b.r2[j] = g.s[2];
      b.r3[j] = g.s[3];
      double z0, z1;
      NormalPairFromBits(ra, rb, z0, z1);
      const double l = seg.ml[j] + seg.sl[j] * z0;
      const double r = seg.mr[j] + seg.sr[j] * z1;
      const Pose2 next = DiffDriveStep(Pose2{b.x[j], b.y[j], b.th[j]}, l, r, wheelbase, Integrator::kArc);
      b.x[j] = next.x;
      b.y[j] = next.y;
      b.th[j] = next.theta;
    }
    if constexpr (kRecord) {
      if ((p + 1) % rec->every == 0 || p + 1 == seg.partitions) rec->Store(b, seg_index, p + 1);
    }
  }
}

template <bool kRecord>
UMBMARK_INLINE void RunBlockImpl(BlockState& b, const LaneSegment* segs, int nseg, double wheelbase,
                                 const Recorder* rec) {
  const double inv_b = 1.0 / wheelbase;
  for (int k = 0; k < nseg; ++k) {
    if (segs[k].path == LaneSegment::Path::kTiny) {
      FastSegment<kRecord, true>(b, segs[k], inv_b, k, rec);
    } else if (segs[k].path == LaneSegment::Path::kQuarter) {
      FastSegment<kRecord, false>(b, segs[k], inv_b, k, rec);
    } else {
      GeneralSegment<kRecord>(b, segs[k], wheelbase, k, rec);
    }
    for (int j = 0; j < W; ++j) {  // re-synchronise the unit heading vector
      b.c[j] = std::cos(b.th[j]);
      b.s[j] = std::sin(b.th[j]);
    }
  }
}

using BlockFn = void (*)(BlockState&, const LaneSegment*, int, double, const Recorder*);

void RunBlockBaseline(BlockState& b, const LaneSegment* s, int n, double wb, const Recorder* r) {
  if (r) RunBlockImpl<true>(b, s, n, wb, r);
  else RunBlockImpl<false>(b, s, n, wb, r);
}

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define UMBMARK_SIM_DISPATCH 1
[[gnu::target("avx2,fma")]] void RunBlockAvx2(BlockState& b, const LaneSegment* s, int n, double wb,
                                               const Recorder* r) {
  if (r) RunBlockImpl<true>(b, s, n, wb, r);
  else RunBlockImpl<false>(b, s, n, wb, r);
}
[[gnu::target("avx512f,avx512dq,avx512vl,avx2,fma")]] void RunBlockAvx512(BlockState& b, const LaneSegment* s,
                                                                         int n, double wb, const Recorder* r) {
  if (r) RunBlockImpl<true>(b, s, n, wb, r);
  else RunBlockImpl<false>(b, s, n, wb, r);
}
#endif

struct Kernel {
  BlockFn fn;
  const char* name;
};

/// The kernels this CPU can run, best first.
std::vector<Kernel> AvailableKernels() {
  std::vector<Kernel> out;
#ifdef UMBMARK_SIM_DISPATCH
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") && __builtin_cpu_supports("avx512vl"))
    out.push_back({&RunBlockAvx512, "avx512"});
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) out.push_back({&RunBlockAvx2, "avx2"});
#endif
  out.push_back({&RunBlockBaseline, "baseline"});
  return out;
}

std::atomic<const Kernel*>& CurrentKernel() {
  static const std::vector<Kernel> kernels = AvailableKernels();
  static std::atomic<const Kernel*> current{&kernels.front()};
  return current;
}

const Kernel& TheKernel() { return *CurrentKernel().load(); }

/// Square root of P0 (P0 = S S^T) via the symmetric eigen-decomposition
/// (works for semidefinite P0).
Eigen::Matrix3d CovarianceSqrt(const PoseCovariance& P0) {
  if (P0.squaredNorm() == 0.0) return Eigen::Matrix3d::Zero();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(P0);
  const Eigen::Vector3d d = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return es.eigenvectors() * d.asDiagonal();
}

/// Per-run set-up of one block: start poses, encoder phases, RNG streams and
/// per-lane segment numbers. Lanes past `count` simulate dummy runs.
void SetupBlock(const SimPlan& plan, const Eigen::Matrix3d& sqrt_p0, std::uint64_t seed, std::int64_t first_run,
                BlockState& b, std::vector<LaneSegment>& segs, RunTrace* traces, int valid) {
  const std::size_t nseg = plan.segments.size();
  segs.resize(nseg);
  for (std::size_t k = 0; k < nseg; ++k) {
    const SimSegment& s = plan.segments[k];
    segs[k].partitions = s.partitions;
  }
  for (int j = 0; j < W; ++j) {
    const auto run = static_cast<std::uint64_t>(first_run + j);
    // Stream kRunSetup: two normal pairs (start pose), then two uniforms (phases).
    Xoshiro256pp setup(StreamSeed(seed, run, kStreamRunSetup));
    double z[4];
    NormalPairFromBits(setup.Next(), setup.Next(), z[0], z[1]);
    NormalPairFromBits(setup.Next(), setup.Next(), z[2], z[3]);
    const Eigen::Vector3d start = sqrt_p0 * Eigen::Vector3d(z[0], z[1], z[2]);
    const double phase_l = plan.quantised ? setup.Uniform() : 0.0;
    const double phase_r = plan.quantised ? setup.Uniform() : 0.0;
    b.x[j] = start.x();
    b.y[j] = start.y();
    b.th[j] = start.z();
    b.c[j] = std::cos(b.th[j]);
    b.s[j] = std::sin(b.th[j]);
    const Xoshiro256pp noise(StreamSeed(seed, run, kStreamWheelNoise));
    b.r0[j] = noise.s[0];
    b.r1[j] = noise.s[1];
    b.r2[j] = noise.s[2];
    b.r3[j] = noise.s[3];
    if (traces && j < valid) {
      traces[j].run = first_run + j;
      traces[j].start = {b.x[j], b.y[j], b.th[j]};
      traces[j].phase_left = phase_l;
      traces[j].phase_right = phase_r;
    }
    for (std::size_t k = 0; k < nseg; ++k) {
      const SimSegment& s = plan.segments[k];
      double left = s.left_m, right = s.right_m;
      if (static_cast<int>(k) == plan.phase_segment_left) left -= phase_l * plan.true_metres_per_tick_left;
      if (static_cast<int>(k) == plan.phase_segment_right) right -= phase_r * plan.true_metres_per_tick_right;
      const double ml = left / s.partitions, mr = right / s.partitions;
      segs[k].ml[j] = ml;
      segs[k].mr[j] = mr;
      segs[k].sl[j] = plan.noise.k_L * std::sqrt(std::abs(ml));  // eq. 4 per partition
      segs[k].sr[j] = plan.noise.k_R * std::sqrt(std::abs(mr));
    }
  }
  // Fast path only when every partition's half angle provably stays within
  // pi/4 (largest Box-Muller variate: kMaxAbsNormal).
  for (std::size_t k = 0; k < nseg; ++k) {
    double worst = 0.0;
    for (int j = 0; j < W; ++j) {
      const double bound = std::abs(segs[k].mr[j] - segs[k].ml[j]) + kMaxAbsNormal * (segs[k].sl[j] + segs[k].sr[j]);
      worst = std::max(worst, bound / (2.0 * plan.true_wheelbase_m));
    }
    segs[k].path = worst <= 1.0 / 16.0 ? LaneSegment::Path::kTiny
                   : worst <= 0.78    ? LaneSegment::Path::kQuarter  // < pi/4
                                      : LaneSegment::Path::kGeneral;
  }
}

}  // namespace

const char* SimKernelName() { return TheKernel().name; }

std::vector<std::string> SimKernelsAvailable() {
  std::vector<std::string> names;
  for (const Kernel& k : AvailableKernels()) names.push_back(k.name);
  return names;
}

bool SelectSimKernel(const std::string& name) {
  static const std::vector<Kernel> kernels = AvailableKernels();
  for (const Kernel& k : kernels) {
    if (name == k.name) {
      CurrentKernel().store(&k);
      return true;
    }
  }
  return false;
}

void SimulateFinalPoses(const SimPlan& plan, std::uint64_t seed, std::int64_t first_run, std::int64_t count, Pose2* out) {
  const Eigen::Matrix3d sqrt_p0 = CovarianceSqrt(plan.initial_covariance);
  const BlockFn fn = TheKernel().fn;
  BlockState b;
  std::vector<LaneSegment> segs;
  for (std::int64_t done = 0; done < count; done += W) {
    const int valid = static_cast<int>(std::min<std::int64_t>(W, count - done));
    SetupBlock(plan, sqrt_p0, seed, first_run + done, b, segs, nullptr, valid);
    fn(b, segs.data(), static_cast<int>(segs.size()), plan.true_wheelbase_m, nullptr);
    for (int j = 0; j < valid; ++j) out[done + j] = {b.x[j], b.y[j], b.th[j]};
  }
}

namespace {

/// Encoder readings of a trace at its samples (see RunTrace).
void AddEncoderReadings(const SimPlan& plan, RunTrace& t) {
  const std::size_t n = t.segment.size();
  t.wheel_left_m.resize(n);
  t.wheel_right_m.resize(n);
  if (plan.quantised) {
    t.ticks_left.resize(n);
    t.ticks_right.resize(n);
  }
  // Cumulative odometry travel and wheel positions at every segment start.
  std::vector<double> odo_l(plan.segments.size() + 1, 0.0), odo_r(plan.segments.size() + 1, 0.0);
  std::vector<double> pos_l(plan.segments.size() + 1, t.phase_left), pos_r(plan.segments.size() + 1, t.phase_right);
  std::vector<std::int64_t> cnt_l(plan.segments.size() + 1, 0), cnt_r(plan.segments.size() + 1, 0);
  for (std::size_t k = 0; k < plan.segments.size(); ++k) {
    const SimSegment& s = plan.segments[k];
    odo_l[k + 1] = odo_l[k] + s.odo_left_m;
    odo_r[k + 1] = odo_r[k] + s.odo_right_m;
    const bool moved_l = plan.phase_segment_left >= 0 && static_cast<int>(k) >= plan.phase_segment_left;
    const bool moved_r = plan.phase_segment_right >= 0 && static_cast<int>(k) >= plan.phase_segment_right;
    pos_l[k + 1] = moved_l ? s.stop_left_ticks : t.phase_left;
    pos_r[k + 1] = moved_r ? s.stop_right_ticks : t.phase_right;
    cnt_l[k + 1] = s.ticks_left;
    cnt_r[k + 1] = s.ticks_right;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(t.segment[i]);
    const SimSegment& s = plan.segments[k];
    const double f = static_cast<double>(t.partition[i]) / s.partitions;
    if (!plan.quantised) {
      t.wheel_left_m[i] = odo_l[k] + f * s.odo_left_m;
      t.wheel_right_m[i] = odo_r[k] + f * s.odo_right_m;
      continue;
    }
    // Whole ticks of the continuous wheel position; exactly the target at
    // the segment end (where a backward stop sits just below T + 1).
    auto count = [&](const std::vector<double>& pos, const std::vector<std::int64_t>& cnt) {
      if (t.partition[i] == s.partitions) return cnt[k + 1];
      return static_cast<std::int64_t>(std::floor(pos[k] + f * (pos[k + 1] - pos[k])));
    };
    t.ticks_left[i] = count(pos_l, cnt_l);
    t.ticks_right[i] = count(pos_r, cnt_r);
    t.wheel_left_m[i] = static_cast<double>(t.ticks_left[i]) * plan.nominal_metres_per_tick_left;
    t.wheel_right_m[i] = static_cast<double>(t.ticks_right[i]) * plan.nominal_metres_per_tick_right;
  }
}

}  // namespace

std::vector<RunTrace> SimulateTraces(const SimPlan& plan, std::uint64_t seed, std::int64_t first_run,
                                     std::int64_t count, int record_every) {
  const Eigen::Matrix3d sqrt_p0 = CovarianceSqrt(plan.initial_covariance);
  const BlockFn fn = TheKernel().fn;
  std::vector<RunTrace> all;
  BlockState b;
  std::vector<LaneSegment> segs;
  for (std::int64_t done = 0; done < count; done += W) {
    const int valid = static_cast<int>(std::min<std::int64_t>(W, count - done));
    std::vector<RunTrace> traces(W);
    SetupBlock(plan, sqrt_p0, seed, first_run + done, b, segs, traces.data(), valid);
    Recorder rec;
    rec.every = std::max(1, record_every);
    rec.traces = &traces;
    rec.lanes = valid;
    fn(b, segs.data(), static_cast<int>(segs.size()), plan.true_wheelbase_m, &rec);
    for (int j = 0; j < valid; ++j) {
      AddEncoderReadings(plan, traces[j]);
      all.push_back(std::move(traces[j]));
    }
  }
  return all;
}

}  // namespace umbmark::sim
