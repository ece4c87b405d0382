#include "swish/bake/cloth/constraint_schedule.hpp"

#include <algorithm>
#include <numeric>

namespace swish::bake {
namespace {

constexpr size_t kLanes = 8;

// Constraint order by level, stable (within a level the sweep's own order), and the levels' starts.
std::vector<uint32_t> levelOrder(const std::vector<uint32_t>& level, std::vector<uint32_t>& levelStart) {
  const uint32_t levels = level.empty() ? 0u : *std::max_element(level.begin(), level.end()) + 1u;
  levelStart.assign(size_t(levels) + 1, 0u);
  for (uint32_t l : level) ++levelStart[size_t(l) + 1];
  std::partial_sum(levelStart.begin(), levelStart.end(), levelStart.begin());
  std::vector<uint32_t> order(level.size()), next(levelStart.begin(), levelStart.end() - 1);
  for (uint32_t k = 0; k < level.size(); ++k) order[next[level[k]]++] = k;
  return order;
}

DistanceSchedule scheduleDistance(const std::vector<DistanceConstraint>& in, const std::vector<float>& w) {
  std::vector<uint32_t> vertices;
  vertices.reserve(2 * in.size());
  for (const DistanceConstraint& c : in) vertices.insert(vertices.end(), {c.i, c.j});
  const std::vector<uint32_t> level = dependencyLevels(w.size(), in.size(), 2, vertices.data());
  DistanceSchedule s;
  for (uint32_t k : levelOrder(level, s.levelStart)) {
    const DistanceConstraint& c = in[k];
    s.constraints.push_back(c);
    s.i3.push_back(int32_t(3 * c.i));
    s.j3.push_back(int32_t(3 * c.j));
    s.rest.push_back(c.rest);
    s.tensionCompliance.push_back(c.tensionCompliance);
    s.compressionCompliance.push_back(c.compressionCompliance);
    s.wi.push_back(w[c.i]);
    s.wj.push_back(w[c.j]);
    s.wsum.push_back((w[c.i] + w[c.j]) / (c.rest * c.rest));  // projectDistance's wsum, the same operations
  }
  return s;
}

ShearSchedule scheduleShear(const std::vector<ShearConstraint>& in, const std::vector<float>& w) {
  std::vector<uint32_t> vertices;
  vertices.reserve(3 * in.size());
  for (const ShearConstraint& c : in) vertices.insert(vertices.end(), {c.v[0], c.v[1], c.v[2]});
  const std::vector<uint32_t> level = dependencyLevels(w.size(), in.size(), 3, vertices.data());
  ShearSchedule s;
  for (uint32_t k : levelOrder(level, s.levelStart)) {
    const ShearConstraint& c = in[k];
    s.constraints.push_back(c);
    for (int corner = 0; corner < 3; ++corner) {
      s.v3[corner].push_back(int32_t(3 * c.v[corner]));
      s.w[corner].push_back(w[c.v[corner]]);
    }
    s.a.push_back(c.a);
    s.b.push_back(c.b);
    s.c.push_back(c.c);
    s.d.push_back(c.d);
    s.compliance.push_back(c.compliance);
  }
  return s;
}

// Runs each level: whole groups of eight in the vector kernel, the rest one by one.
template <class Schedule, class Scalar, class Vector>
void sweepLevels(const Schedule& s, bool vector, Scalar scalar, Vector kernel) {
  for (size_t l = 0; l + 1 < s.levelStart.size(); ++l) {
    const size_t begin = s.levelStart[l], end = s.levelStart[l + 1];
    size_t k = begin;
    if (vector) {
      const size_t whole = begin + (end - begin) / kLanes * kLanes;
      if (whole > begin) kernel(begin, whole);
      k = whole;
    }
    for (; k < end; ++k) scalar(k);
  }
}

template <class Schedule>
size_t vectorisedOf(const Schedule& s) {
  size_t n = 0;
  for (size_t l = 0; l + 1 < s.levelStart.size(); ++l) n += (s.levelStart[l + 1] - s.levelStart[l]) / kLanes * kLanes;
  return n;
}

}  // namespace

std::vector<uint32_t> dependencyLevels(size_t vertexCount, size_t constraintCount, int verticesPerConstraint,
                                       const uint32_t* vertices) {
  // last[v]: one more than the level of the latest constraint so far that touches v (0: none).
  std::vector<uint32_t> last(vertexCount, 0u), level(constraintCount);
  for (size_t k = 0; k < constraintCount; ++k) {
    const uint32_t* v = vertices + k * size_t(verticesPerConstraint);
    uint32_t l = 0;
    for (int n = 0; n < verticesPerConstraint; ++n) l = std::max(l, last[v[n]]);
    level[k] = l;
    for (int n = 0; n < verticesPerConstraint; ++n) last[v[n]] = l + 1;
  }
  return level;
}

ConstraintSchedule buildConstraintSchedule(const ClothConstraints& cc) {
  ConstraintSchedule s;
  s.stretch = scheduleDistance(cc.stretch, cc.inverseMass);
  s.bending = scheduleDistance(cc.bending, cc.inverseMass);
  s.shear = scheduleShear(cc.shear, cc.inverseMass);
  s.inverseMass = cc.inverseMass;
  return s;
}

size_t ConstraintSchedule::vectorised() const {
  if (!constraintSweepVectorised()) return 0;
  return vectorisedOf(stretch) + vectorisedOf(shear) + vectorisedOf(bending);
}

bool constraintSweepVectorised() {
  static const bool available = detail::avx2Available();
  return available;
}

void ConstraintSchedule::sweep(float* x, float invDt2, float* lambda, bool vector) const {
  const float* w = inverseMass.data();
  vector = vector && constraintSweepVectorised();
  // The blocks' sweeps, each as `for (c : constraints) project(c, x, w, invDt2, lambda[k++])` in its
  // scheduled order.
  auto distance = [&](const DistanceSchedule& s, float* l) {
    sweepLevels(
        s, vector, [&](size_t k) { projectDistance(s.constraints[k], x, w, invDt2, l[k]); },
        [&](size_t begin, size_t end) { detail::sweepDistanceAvx2(s, begin, end, x, invDt2, l); });
  };
  distance(stretch, lambda);
  float* l = lambda + stretch.constraints.size();
  sweepLevels(
      shear, vector, [&](size_t k) { projectShear(shear.constraints[k], x, w, invDt2, l[k]); },
      [&](size_t begin, size_t end) { detail::sweepShearAvx2(shear, begin, end, x, invDt2, l); });
  distance(bending, l + shear.constraints.size());
}

}  // namespace swish::bake
