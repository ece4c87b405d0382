#include "swish/replay/gpu_check.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace swish::replay {

namespace {

// Angle between two directions in degrees; a NaN on either side counts as 180 (it must not hide).
double angleDeg(const Vec3f& a, const Vec3f& b) {
  if (!a.allFinite() || !b.allFinite()) return (a.hasNaN() && b.hasNaN()) ? 0.0 : 180.0;
  const double na = a.cast<double>().norm(), nb = b.cast<double>().norm();
  if (na == 0 || nb == 0) return na == nb ? 0.0 : 180.0;
  const double c = std::clamp(a.cast<double>().dot(b.cast<double>()) / (na * nb), -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

}  // namespace

CharacterCheck compareInstance(const runtime::ReferenceFrameOutputs& gpu, const runtime::ReferenceFrameOutputs& cpu,
                               uint32_t i, uint32_t character) {
  CharacterCheck c;
  c.character = character;
  const Points3f& gp = gpu.positions.at(i);
  const Points3f& cp = cpu.positions.at(i);
  for (Eigen::Index v = 0; v < gp.rows(); ++v) {
    const double d = (gp.row(v).cast<double>() - cp.row(v).cast<double>()).norm() * 1000.0;
    c.maxPositionErrorMm = std::max(c.maxPositionErrorMm, std::isfinite(d) ? d : 1e30);
  }
  if (i < gpu.normals.size() && i < cpu.normals.size())
    for (Eigen::Index v = 0; v < gp.rows(); ++v) {
      c.maxNormalErrorDeg = std::max(c.maxNormalErrorDeg, angleDeg(gpu.normals[i].row(v), cpu.normals[i].row(v)));
      c.maxTangentErrorDeg =
          std::max(c.maxTangentErrorDeg, angleDeg(gpu.tangents[i].row(v).head<3>(), cpu.tangents[i].row(v).head<3>()));
    }
  if (i < gpu.normalMaps.size() && i < cpu.normalMaps.size()) {
    const auto& a = gpu.normalMaps[i].xy;
    const auto& b = cpu.normalMaps[i].xy;
    for (size_t t = 0; t < std::min(a.size(), b.size()); ++t)
      c.maxMapErrorSteps = std::max(c.maxMapErrorSteps, std::abs(int(a[t]) - int(b[t])));
    if (a.size() != b.size()) c.maxMapErrorSteps = 65535;
  }
  c.ok = c.maxPositionErrorMm <= kPositionToleranceMm && c.maxNormalErrorDeg <= kFrameToleranceDeg &&
         c.maxTangentErrorDeg <= kFrameToleranceDeg && c.maxMapErrorSteps <= kMapToleranceSteps;
  return c;
}

}  // namespace swish::replay
