#pragma once
// Greedy pose thinning (paper, section 2.2): walk the samples in order and keep one only if it is
// farther than a tolerance (Euclidean distance of Theta vectors) from every pose kept so far. Every
// pair of kept poses is then farther apart than the tolerance, and every rejected pose lies within the
// tolerance of a kept one. Or: given a target count, find the tolerance by bisection.
//
// Speed: the paper's volume is ~800,000 samples thinned to ~700. Two things make a pass cheap:
//  - temporal coherence: consecutive samples of a recording are close, so the kept pose that covered
//    the previous sample is tried first and usually covers this one too;
//  - a band search on the samples' principal axes: projecting onto a unit vector never increases
//    distances, so only kept poses whose projections on the first three principal axes all lie within
//    the tolerance need an (early-exit) distance check; kept poses are sorted by the first projection.
// Neither changes the result: it is exactly the plain greedy pass over the samples in order.
//
// Growing a thinned set: a pass can start from poses already kept (`keepFirst`, for example the set a
// smaller bake thinned to). They stay first, in their order, and the pass adds the samples farther
// than the tolerance from every pose kept so far. A bake that grows its pose count this way keeps the
// earlier poses' ids, so their simulations are reused (part1.thinning.grow_from).
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "swish/bake/poses/pose_sampling.hpp"

namespace swish::bake {

struct ThinningResult {
  std::vector<uint32_t> kept;  // sample indices: keepFirst as given, then ascending (the greedy order)
  float tolerance = 0.f;
  bool truncated = false;     // stopped early because more than maxKept poses were kept
  size_t distanceChecks = 0;  // full (early-exit) distance evaluations, for benchmarks
  int passes = 1;             // greedy passes run (thinPosesToCount: the search's iterations)
};

// One greedy pass. maxKept stops the pass once that many are kept, keepFirst included (used by the
// bisection to give up quickly on tolerances that are far too small); the result is then marked
// truncated. keepFirst: sample indices kept before the pass starts (distinct, each < samples.size()).
ThinningResult thinPoses(const PoseSamples& samples, float tolerance, size_t maxKept = SIZE_MAX,
                         std::span<const uint32_t> keepFirst = {});

struct ThinToCountOptions {
  double relativeSlack = 0.02;  // stop when |kept - target| <= slack * target
  int maxIterations = 60;
  std::vector<uint32_t> keepFirst;  // kept before every pass (see above); the target counts them
};

// Search on the tolerance for `target` kept poses (bisection in log space, sped up by log-log
// interpolation of the counts). The greedy count is not strictly monotone in the
// tolerance, so the result is the closest count found; within the slack for any realistic cloud.
// Euclidean distance from `x` (samples.dim values) to the nearest of the `kept` samples; infinity when
// none is kept. A brute-force scan: for a handful of extra poses, not for thinning itself.
float nearestKeptDistance(const PoseSamples& samples, const std::vector<uint32_t>& kept, std::span<const float> x);

ThinningResult thinPosesToCount(const PoseSamples& samples, size_t target, const ThinToCountOptions& options = {});

}  // namespace swish::bake
