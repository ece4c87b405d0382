#pragma once
// FNV-1a (64-bit) over raw bytes: digests that tell setups, pose lists and files apart (resuming a bake
// reuses a result only when its digest matches). Not cryptographic.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace swish {

struct Fnv1a {
  static constexpr uint64_t kOffsetBasis = 1469598103934665603ull;
  uint64_t h = kOffsetBasis;

  Fnv1a() = default;
  explicit Fnv1a(uint64_t seed) : h(seed) {}

  void bytes(const void* p, size_t n) {
    const auto* c = static_cast<const uint8_t*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 1099511628211ull;
  }
  template <class T>
  void value(const T& v) {
    bytes(&v, sizeof v);
  }
  // Dense Eigen matrices and vectors: their coefficients, in storage order.
  template <class M>
  void matrix(const M& m) {
    bytes(m.data(), size_t(m.size()) * sizeof(typename M::Scalar));
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    bytes(v.data(), v.size() * sizeof(T));
  }
};

inline uint64_t fnv1a(const void* p, size_t n) {
  Fnv1a f;
  f.bytes(p, n);
  return f.h;
}

}  // namespace swish
