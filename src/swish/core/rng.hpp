#pragma once
// The one seeded random generator of the project (xoshiro256**, seeded by splitmix64). Every random
// choice takes one, so runs repeat exactly. std distributions are avoided on purpose: their output
// differs between standard libraries; these are defined here bit for bit.
#include <cmath>
#include <cstdint>
#include <limits>

namespace swish {

class Rng {
 public:
  explicit Rng(uint64_t seed = 0x5715'4u) { reseed(seed); }

  void reseed(uint64_t seed) {
    uint64_t x = seed;
    for (auto& s : s_) s = splitmix64(x);
    haveSpare_ = false;
  }

  uint64_t next() {
    const uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  // Uniform in [0, 1).
  double uniform() { return double(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  float uniformf(float lo, float hi) { return float(uniform(lo, hi)); }

  // Uniform integer in [0, n). n > 0. Lemire's nearly divisionless method would be faster; this
  // rejection loop is simple and unbiased.
  uint64_t below(uint64_t n) {
    const uint64_t limit = std::numeric_limits<uint64_t>::max() - std::numeric_limits<uint64_t>::max() % n;
    uint64_t r;
    do r = next();
    while (r >= limit);
    return r % n;
  }

  // Standard normal (Marsaglia polar method).
  double normal() {
    if (haveSpare_) {
      haveSpare_ = false;
      return spare_;
    }
    double u, v, s;
    do {
      u = uniform() * 2.0 - 1.0;
      v = uniform() * 2.0 - 1.0;
      s = u * u + v * v;
    } while (s >= 1.0 || s == 0.0);
    const double m = std::sqrt(-2.0 * std::log(s) / s);
    spare_ = v * m;
    haveSpare_ = true;
    return u * m;
  }
  double normal(double mean, double stddev) { return mean + stddev * normal(); }

  // A child generator whose stream is independent of this one's continuation (for parallel work:
  // derive one per task index, so results do not depend on the thread schedule).
  Rng split(uint64_t index) const {
    uint64_t x = s_[0] ^ (s_[3] * 0x9E3779B97F4A7C15ull) ^ (index * 0xD1B54A32D192ED03ull);
    return Rng(splitmix64(x));
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static uint64_t splitmix64(uint64_t& x) {
    uint64_t z = (x += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  uint64_t s_[4];
  double spare_ = 0.0;
  bool haveSpare_ = false;
};

}  // namespace swish
