#pragma once
// Angular error between tangent-space normal maps stored as X, Y (Z = sqrt(1 - X^2 - Y^2)): how the
// bake scores the database, the selection and the VQ/BC5 compression. Degrees.
#include <cstdint>
#include <vector>

#include "swish/bake/dataset/dataset.hpp"

namespace swish::bake {

struct AngularErrorStats {
  double meanDegrees = 0.0;
  double p95Degrees = 0.0;
  double maxDegrees = 0.0;
  uint64_t texels = 0;
};

// Accumulates per-texel angles into a fine histogram (0.01 degree bins) so that percentiles need no
// storage per texel and accumulators merge exactly.
class AngularErrorAccumulator {
 public:
  AngularErrorAccumulator();
  void add(double degrees);
  // Every texel of two maps of the same size (throws Error otherwise).
  void addMaps(const NormalMapImage& truth, const NormalMapImage& approx);
  void merge(const AngularErrorAccumulator& other);
  AngularErrorStats stats() const;

 private:
  std::vector<uint64_t> bins_;
  double sum_ = 0.0, max_ = 0.0;
  uint64_t count_ = 0;
};

// Angle in degrees between the normals of two XY texels.
double texelAngleDegrees(float x0, float y0, float x1, float y1);

AngularErrorStats angularError(const NormalMapImage& truth, const NormalMapImage& approx);

}  // namespace swish::bake
