#include "swish/bake/cloth/body_collider.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <map>
#include <unordered_map>

#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace swish::bake {
namespace {

// Which feature of a triangle holds the closest point: the face, a vertex (0..2) or a side
// (0: ab, 1: bc, 2: ca). The sign test needs the pseudo-normal of exactly that feature.
enum class Feature { Face, Vertex, Edge };
struct ClosestOnTriangle {
  Vec3f point;
  Feature feature;
  int index;
};

// Ericson, Real-Time Collision Detection, 5.1.5, keeping track of the Voronoi region.
ClosestOnTriangle closestOnTriangle(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.f && d2 <= 0.f) return {a, Feature::Vertex, 0};
  const Vec3f bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.f && d4 <= d3) return {b, Feature::Vertex, 1};
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.f && d1 >= 0.f && d3 <= 0.f) return {a + ab * (d1 / (d1 - d3)), Feature::Edge, 0};
  const Vec3f cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.f && d5 <= d6) return {c, Feature::Vertex, 2};
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.f && d2 >= 0.f && d6 <= 0.f) return {a + ac * (d2 / (d2 - d6)), Feature::Edge, 2};
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.f && (d4 - d3) >= 0.f && (d5 - d6) >= 0.f)
    return {b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), Feature::Edge, 1};
  const float denom = va + vb + vc;
  if (!(std::abs(denom) > 0.f)) return {a, Feature::Vertex, 0};  // degenerate triangle
  const float v = vb / denom, w = vc / denom;
  return {a + ab * v + ac * w, Feature::Face, 0};
}

}  // namespace

BodyCollider::BodyCollider(const Mesh& body, float cellSize, const std::string& what,
                           const std::vector<uint8_t>& jointRegion)
    : restPositions_(body.positions), skin_(body.skin), cellSize_(cellSize) {
  body.validate(what);
  if (body.triangleCount() == 0) throw Error(what + ": the collider body has no triangles");
  // One surface point per position: a mesh split at its UV seams (as glTF stores it) is closed only
  // once its seam copies are welded. Unwelded, every seam edge would count as open, its pseudo-normal
  // would be that of one side alone, its part would look open (no winding-number check) and, where the
  // seams run (neck, armpits, the sides), points outside would be answered "inside".
  triangles_ = trianglesWeldedByPosition(restPositions_, body.triangles);
  if (!(cellSize > 0.f) || !std::isfinite(cellSize)) throw Error(what + ": collider cell size must be positive");
  // Edge numbering: shared sides get one index, so their pseudo-normal sums both faces.
  std::unordered_map<uint64_t, uint32_t> edgeIndex;
  std::vector<uint32_t> edgeUses;
  triangleEdges_.resize(size_t(triangles_.rows()) * 3);
  for (Eigen::Index t = 0; t < triangles_.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      uint32_t a = triangles_(t, k), b = triangles_(t, (k + 1) % 3);
      if (a > b) std::swap(a, b);
      auto [it, inserted] = edgeIndex.try_emplace((uint64_t(a) << 32) | b, uint32_t(edgeTriangles_.size()));
      if (inserted)
        edgeTriangles_.push_back({int32_t(t), -1}), edgeUses.push_back(0);
      else if (edgeTriangles_[it->second][1] < 0)
        edgeTriangles_[it->second][1] = int32_t(t);
      ++edgeUses[it->second];
      triangleEdges_[size_t(t) * 3 + k] = it->second;
    }
  openEdges_ = size_t(std::count_if(edgeUses.begin(), edgeUses.end(), [](uint32_t u) { return u != 2; }));
  const std::vector<uint32_t> part = connectedParts(triangles_, size_t(restPositions_.rows()));
  triangleComponent_.resize(size_t(triangles_.rows()));
  for (Eigen::Index t = 0; t < triangles_.rows(); ++t) triangleComponent_[size_t(t)] = part[triangles_(t, 0)];
  partTriangles_.resize(size_t(triangles_.rows()));
  for (uint32_t t = 0; t < uint32_t(triangles_.rows()); ++t) partTriangles_[t] = t;
  std::stable_sort(partTriangles_.begin(), partTriangles_.end(),
                   [&](uint32_t x, uint32_t y) { return triangleComponent_[x] < triangleComponent_[y]; });
  for (uint32_t i = 0; i < partTriangles_.size();) {
    const uint32_t id = triangleComponent_[partTriangles_[i]];
    uint32_t j = i;
    bool closed = true;
    for (; j < partTriangles_.size() && triangleComponent_[partTriangles_[j]] == id; ++j)
      for (int k = 0; k < 3; ++k) closed &= edgeUses[triangleEdges_[size_t(partTriangles_[j]) * 3 + k]] == 2;
    partRanges_.push_back({id, i, j, closed});
    i = j;
  }
  splitRegions(jointRegion);
  positions_ = restPositions_;
  rebuild();
}

void BodyCollider::splitRegions(const std::vector<uint8_t>& jointRegion) {
  triangleRegion_ = triangleComponent_;
  const size_t nt = size_t(triangles_.rows());
  const int k = skin_.influences;
  if (jointRegion.empty() || skin_.vertexCount() != size_t(restPositions_.rows()) || k <= 0) return;
  const size_t groups = size_t(*std::max_element(jointRegion.begin(), jointRegion.end())) + 1;
  if (groups < 2) return;
  // Each triangle's joint group: the one holding most of its corners' weights (ties: the lower group).
  std::vector<uint8_t> group(nt, 0);
  std::vector<float> sum(groups);
  for (size_t t = 0; t < nt; ++t) {
    std::fill(sum.begin(), sum.end(), 0.f);
    for (int c = 0; c < 3; ++c) {
      const size_t v = triangles_(Eigen::Index(t), c);
      for (int i = 0; i < k; ++i) {
        const uint16_t j = skin_.joints[v * size_t(k) + size_t(i)];
        sum[j < jointRegion.size() ? jointRegion[j] : 0] += skin_.weights[v * size_t(k) + size_t(i)];
      }
    }
    group[t] = uint8_t(std::max_element(sum.begin(), sum.end()) - sum.begin());
  }
  // Triangles per (part, group) and per group. A limb group is split off a part that holds most of
  // the group's triangles and more trunk (group 0) triangles than the group's: the limb is in the part
  // but is not the part (a mannequin's arm tube is a part of its own and stays whole, and so does its
  // torso with the few arm-weighted triangles at its shoulders).
  std::map<std::pair<uint32_t, uint8_t>, uint32_t> count;
  std::vector<uint32_t> groupTotal(groups, 0);
  for (size_t t = 0; t < nt; ++t) ++count[{triangleComponent_[t], group[t]}], ++groupTotal[group[t]];
  uint32_t next = *std::max_element(triangleComponent_.begin(), triangleComponent_.end()) + 1;
  std::map<std::pair<uint32_t, uint8_t>, uint32_t> regionOf;
  for (const auto& [key, n] : count) {
    if (key.second == 0 || 2 * size_t(n) <= groupTotal[key.second]) continue;
    const auto trunk = count.find({key.first, uint8_t(0)});
    if (trunk == count.end() || trunk->second <= n) continue;
    regionOf[key] = next++;
  }
  if (regionOf.empty()) return;
  splitsParts_ = true;
  for (size_t t = 0; t < nt; ++t)
    if (const auto r = regionOf.find({triangleComponent_[t], group[t]}); r != regionOf.end())
      triangleRegion_[t] = r->second;
}

void BodyCollider::pose(const std::vector<Mat4f>& skinMatrices) {
  if (skin_.vertexCount() != size_t(restPositions_.rows()))
    throw Error("body collider: the body has no skin weights, it cannot be posed");
  positions_ = skinPositions(restPositions_, skin_, skinMatrices);
  rebuild();
}

void BodyCollider::rebuild() {
  const size_t nt = size_t(triangles_.rows()), nv = size_t(positions_.rows());
  if (!positions_.allFinite()) throw Error("body collider: posed body has non-finite positions");
  faceNormals_.assign(nt, Vec3f::Zero());
  vertexNormals_.assign(nv, Vec3f::Zero());
  edgeNormals_.assign(edgeTriangles_.size(), Vec3f::Zero());
  // Each triangle's bounding sphere (centre + radius), copied per cell below for the queries' reject.
  std::vector<Vec4f> spheres(nt);
  for (size_t t = 0; t < nt; ++t) {
    const Vec3f p[3] = {positions_.row(triangles_(t, 0)), positions_.row(triangles_(t, 1)),
                        positions_.row(triangles_(t, 2))};
    const Vec3f n = (p[1] - p[0]).cross(p[2] - p[0]);
    const float len = n.norm();
    faceNormals_[t] = len > 0.f ? Vec3f(n / len) : Vec3f::Zero();
    for (int k = 0; k < 3; ++k) {
      // Angle-weighted vertex pseudo-normal.
      const Vec3f e1 = p[(k + 1) % 3] - p[k], e2 = p[(k + 2) % 3] - p[k];
      const float d = e1.norm() * e2.norm();
      const float angle = d > 0.f ? std::acos(std::clamp(e1.dot(e2) / d, -1.f, 1.f)) : 0.f;
      vertexNormals_[triangles_(t, k)] += angle * faceNormals_[t];
      edgeNormals_[triangleEdges_[t * 3 + k]] += faceNormals_[t];
    }
    const Vec3f centre = (p[0] + p[1] + p[2]) / 3.f;
    const float r = std::max({(p[0] - centre).norm(), (p[1] - centre).norm(), (p[2] - centre).norm()});
    spheres[t] =
        Vec4f(centre.x(), centre.y(), centre.z(), r);  // not "<< centre, r": GCC 12 warns (-Warray-bounds) on that
  }
  for (auto& n : vertexNormals_) n.normalize();
  for (auto& n : edgeNormals_) n.normalize();

  // Grid over the posed body's bounds; capped at ~4M cells so a scattered body cannot eat memory.
  const Vec3f lo = positions_.colwise().minCoeff().transpose(), hi = positions_.colwise().maxCoeff().transpose();
  float h = cellSize_;
  const Vec3f extent = (hi - lo).cwiseMax(Vec3f::Constant(1e-6f));
  while ((extent / h).array().ceil().prod() > 4e6f) h *= 1.5f;
  gridOrigin_ = lo;
  cellSize_ = h;
  for (int k = 0; k < 3; ++k) gridDims_[k] = std::max(1, int(std::ceil(extent[k] / h)));
  const size_t cells = size_t(gridDims_.prod());
  auto cellRange = [&](size_t t, Eigen::Vector3i& a, Eigen::Vector3i& b) {
    Vec3f tlo = positions_.row(triangles_(t, 0)), thi = tlo;
    for (int k = 1; k < 3; ++k) {
      tlo = tlo.cwiseMin(positions_.row(triangles_(t, k)).transpose());
      thi = thi.cwiseMax(positions_.row(triangles_(t, k)).transpose());
    }
    for (int k = 0; k < 3; ++k) {
      a[k] = std::clamp(int((tlo[k] - lo[k]) / h), 0, gridDims_[k] - 1);
      b[k] = std::clamp(int((thi[k] - lo[k]) / h), 0, gridDims_[k] - 1);
    }
  };
  cellStart_.assign(cells + 1, 0);
  Eigen::Vector3i a, b;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<uint32_t> fill;
    if (pass == 1) {
      for (size_t c = 0; c < cells; ++c) cellStart_[c + 1] += cellStart_[c];
      cellTriangles_.resize(cellStart_[cells]);
      for (auto& a : cellSpheres_) a.assign(cellStart_[cells] + kSphereLanes, 0.f);
      fill.assign(cellStart_.begin(), cellStart_.end() - 1);
    }
    for (size_t t = 0; t < nt; ++t) {
      cellRange(t, a, b);
      for (int z = a[2]; z <= b[2]; ++z)
        for (int y = a[1]; y <= b[1]; ++y)
          for (int x = a[0]; x <= b[0]; ++x) {
            const size_t c = (size_t(z) * gridDims_[1] + y) * gridDims_[0] + x;
            if (pass == 0)
              ++cellStart_[c + 1];
            else {
              for (int k = 0; k < 4; ++k) cellSpheres_[size_t(k)][fill[c]] = spheres[t][k];
              cellTriangles_[fill[c]++] = uint32_t(t);
            }
          }
    }
  }
}

size_t BodyCollider::closestParts(const Vec3f& p, float maxDistance, std::span<Hit> out, int onlyPart,
                                  int skipPart) const {
  return closestKeyed(p, maxDistance, out, onlyPart, skipPart, false);
}

size_t BodyCollider::closestRegions(const Vec3f& p, float maxDistance, std::span<Hit> out) const {
  return closestKeyed(p, maxDistance, out, -1, -1, splitsParts_);
}

size_t BodyCollider::closestKeyed(const Vec3f& p, float maxDistance, std::span<Hit> out, int onlyPart, int skipPart,
                                  bool byRegion) const {
  if (out.empty() || !p.allFinite() || !(maxDistance > 0.f)) return 0;
  Eigen::Vector3i a, b;
  for (int k = 0; k < 3; ++k) {
    const float lo = (p[k] - maxDistance - gridOrigin_[k]) / cellSize_;
    const float hi = (p[k] + maxDistance - gridOrigin_[k]) / cellSize_;
    if (hi < 0.f || lo >= float(gridDims_[k])) return 0;  // the search ball misses the grid
    a[k] = std::clamp(int(std::floor(lo)), 0, gridDims_[k] - 1);
    b[k] = std::clamp(int(std::floor(hi)), 0, gridDims_[k] - 1);
  }
  // The closest triangle of each part (or region) met within the ball (a query meets a handful).
  struct PartBest {
    uint32_t key;  // the part, or the region when byRegion
    uint32_t part;
    float distance;
    int tri;
    ClosestOnTriangle point;
  };
  constexpr size_t kMaxParts = 16;
  std::array<PartBest, kMaxParts> parts;
  size_t partCount = 0;
  // The rejects below only skip triangles that cannot be within maxDistance (or cannot beat the best
  // answer so far): the answer does not depend on which triangles are visited beyond those, nor in
  // what order (ties go to the lower triangle), so they change its cost, never its value (with at most
  // kMaxParts parts or regions within reach: 8 parts make the default mannequin, 3 regions a glTF body;
  // beyond that which ones are dropped depends on the order). Both rejects are conservative by a margin
  // far above float rounding (kSlack), so a triangle at the bound is visited.
  constexpr float kSlack = 1e-4f;  // metres, and a relative 1e-4 on squared distances
  const float reachSq = (maxDistance + kSlack) * (maxDistance + kSlack);
  // Each triangle is binned in every cell its box overlaps, so a query meets most of its near ones in
  // several cells: the exact closest point is computed once per triangle and query (a later visit would
  // compute the same answer, which the tie rule below keeps as it is). The marks are per thread (queries
  // run in parallel on a const collider) and per query: a mark equal to this query's number is this
  // query's own, whichever collider set it before.
  thread_local std::vector<uint32_t> visited;
  thread_local uint32_t queryNumber = 0;
  if (visited.size() < size_t(triangles_.rows())) visited.resize(size_t(triangles_.rows()), 0);
  if (++queryNumber == 0) {  // wrapped: no old mark may equal the numbers from here on
    std::fill(visited.begin(), visited.end(), 0u);
    queryNumber = 1;
  }
  const uint32_t query = queryNumber;
  uint32_t* const mark = visited.data();
  // Squared distance from p to a slab of cells along one axis (0 inside it).
  auto slabSq = [&](int k, int i) {
    const float lo = gridOrigin_[k] + float(i) * cellSize_, hi = lo + cellSize_;
    const float d = p[k] < lo ? lo - p[k] : (p[k] > hi ? p[k] - hi : 0.f);
    return d * d;
  };
  // Sphere reject on squared distances (no square root): |p - centre| > maxDistance + r. Bit j of the
  // answer: sphere i0 + j passes (is not rejected), and centreSq[j] is its |p - centre|^2 for the bound
  // reject below; kSphereLanes at a time, each lane computing what the scalar expression does, in the same
  // order (the arrays are padded, the caller masks the lanes past a cell's end).
  const float* const sx = cellSpheres_[0].data();
  const float* const sy = cellSpheres_[1].data();
  const float* const sz = cellSpheres_[2].data();
  const float* const sr = cellSpheres_[3].data();
#if defined(__SSE2__)
  const __m128 px = _mm_set1_ps(p.x()), py = _mm_set1_ps(p.y()), pz = _mm_set1_ps(p.z());
  const __m128 maxD = _mm_set1_ps(maxDistance), onePlusSlack = _mm_set1_ps(1.f + kSlack),
               slackSq = _mm_set1_ps(kSlack * kSlack);
  auto passing = [&](uint32_t i0, float* centreSqOut) -> uint32_t {
    const __m128 dx = _mm_sub_ps(px, _mm_loadu_ps(sx + i0)), dy = _mm_sub_ps(py, _mm_loadu_ps(sy + i0)),
                 dz = _mm_sub_ps(pz, _mm_loadu_ps(sz + i0));
    const __m128 centreSq = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    const __m128 reach = _mm_add_ps(maxD, _mm_loadu_ps(sr + i0));
    const __m128 bound = _mm_add_ps(_mm_mul_ps(_mm_mul_ps(reach, reach), onePlusSlack), slackSq);
    _mm_storeu_ps(centreSqOut, centreSq);
    return uint32_t(_mm_movemask_ps(_mm_cmpngt_ps(centreSq, bound)));
  };
#else
  auto passing = [&](uint32_t i0, float* centreSqOut) -> uint32_t {
    uint32_t bits = 0;
    for (uint32_t j = 0; j < kSphereLanes; ++j) {
      const uint32_t i = i0 + j;
      const float reach = maxDistance + sr[i];
      centreSqOut[j] = (p - Vec3f(sx[i], sy[i], sz[i])).squaredNorm();
      if (!(centreSqOut[j] > reach * reach * (1.f + kSlack) + kSlack * kSlack)) bits |= 1u << j;
    }
    return bits;
  };
#endif
  // The triangles binned in cell c (rejects, then the exact closest point).
  auto visitCell = [&](size_t c) {
    const uint32_t begin = cellStart_[c], end = cellStart_[c + 1];
    for (uint32_t i0 = begin; i0 < end; i0 += kSphereLanes) {
      float centreSqs[kSphereLanes];
      uint32_t bits = passing(i0, centreSqs);
      if (end - i0 < kSphereLanes) bits &= (1u << (end - i0)) - 1u;
      for (; bits != 0; bits &= bits - 1u) {
        const uint32_t lane = uint32_t(std::countr_zero(bits)), i = i0 + lane;
        const float centreSq = centreSqs[lane], radius = sr[i];
        const uint32_t t = cellTriangles_[i];
        // Met in another cell already: computed, or rejected below by what stays true for this query (the
        // part filters, and a part's best answer, which only shrinks).
        if (mark[t] == query) continue;
        mark[t] = query;
        const uint32_t part = triangleComponent_[t];
        if ((onlyPart >= 0 && part != uint32_t(onlyPart)) || (skipPart >= 0 && part == uint32_t(skipPart))) continue;
        const uint32_t key = byRegion ? triangleRegion_[t] : part;
        size_t slot = 0;
        while (slot < partCount && parts[slot].key != key) ++slot;
        // (|p - centre| - r > best, on squares and with the same slack as the sphere reject: no square root.)
        if (slot < partCount) {
          const float bound = parts[slot].distance + radius;
          if (centreSq > bound * bound * (1.f + kSlack) + kSlack * kSlack) continue;
        }
        const ClosestOnTriangle q = closestOnTriangle(
            p, positions_.row(triangles_(t, 0)), positions_.row(triangles_(t, 1)), positions_.row(triangles_(t, 2)));
        const float d = (p - q.point).norm();
        if (!(d <= maxDistance)) continue;
        if (slot == partCount) {
          if (partCount == kMaxParts) {
            // More parts within reach than kept: replace the farthest answer if this is nearer.
            size_t worst = 0;
            for (size_t k = 1; k < partCount; ++k)
              if (parts[k].distance > parts[worst].distance) worst = k;
            if (!(d < parts[worst].distance)) continue;
            parts[worst] = {key, part, d, int(t), q};
            continue;
          }
          parts[partCount++] = {key, part, d, int(t), q};
          continue;
        }
        // Ties (two triangles sharing the closest feature) keep the lowest triangle index, so the answer
        // does not depend on the visiting order.
        PartBest& pb = parts[slot];
        if (d < pb.distance || (d == pb.distance && int(t) < pb.tri)) pb = {key, part, d, int(t), q};
      }
    }
  };
  // The cell holding p first: its triangles are usually the nearest, and once a part has an answer the
  // reject of triangles that cannot beat it skips most of the others.
  const Eigen::Vector3i home =
      ((p - gridOrigin_) / cellSize_).array().floor().cast<int>().max(a.array()).min(b.array());
  visitCell((size_t(home[2]) * gridDims_[1] + home[1]) * gridDims_[0] + home[0]);
  for (int z = a[2]; z <= b[2]; ++z) {
    const float dz = slabSq(2, z);
    for (int y = a[1]; y <= b[1]; ++y) {
      const float dzy = dz + slabSq(1, y);
      if (dzy > reachSq) continue;
      for (int x = a[0]; x <= b[0]; ++x) {
        // A cell the search ball does not reach (a corner of the ball's box) holds nothing within
        // reach that another visited cell does not also hold: each triangle is binned in every cell
        // its box overlaps, so its point nearest p is in a cell at most that far from p.
        if (dzy + slabSq(0, x) > reachSq || (x == home[0] && y == home[1] && z == home[2])) continue;
        visitCell((size_t(z) * gridDims_[1] + y) * gridDims_[0] + x);
      }
    }
  }
  // Each part's signed distance from its own closest feature's pseudo-normal. A region of a split part
  // is an open patch, its closest feature not always the part's: a point outside the part (by the
  // part's closest region, confirmed as ever) is outside each of its patches; a point inside it is
  // answered by the part's closest region alone, pushed out of the body the shortest way as by an
  // unsplit part (planes of both walls of a pinch that skinning closed, or made pass through each
  // other, would push it back and forth between them and tear the cloth).
  std::array<Hit, kMaxParts> hits;
  std::array<float, kMaxParts> signs;
  std::array<bool, kMaxParts> keep;
  keep.fill(true);
  auto pseudoNormal = [&](const PartBest& pb) -> Vec3f {
    switch (pb.point.feature) {
      case Feature::Face:
        return faceNormals_[size_t(pb.tri)];
      case Feature::Vertex:
        return vertexNormals_[triangles_(pb.tri, pb.point.index)];
      default:
        return edgeNormals_[triangleEdges_[size_t(pb.tri) * 3 + pb.point.index]];
    }
  };
  for (size_t k = 0; k < partCount; ++k) {
    const Vec3f diff = p - parts[k].point.point, pseudo = pseudoNormal(parts[k]);
    signs[k] = diff.dot(pseudo) >= 0.f ? 1.f : -1.f;
  }
  for (size_t k = 0; k < partCount; ++k) {
    const PartBest& pb = parts[k];
    // The part's closest region (the slot itself, unless the part is split): nearest, then lowest
    // triangle, as closestParts picks the part's closest triangle.
    size_t nearest = k;
    for (size_t i = 0; i < partCount; ++i) {
      const PartBest& q = parts[i];
      if (q.part == pb.part && (q.distance < parts[nearest].distance ||
                                (q.distance == parts[nearest].distance && q.tri < parts[nearest].tri)))
        nearest = i;
    }
    if (nearest != k) continue;
    // Deep inside by the pseudo-normal: confirm with the winding number (the header says why).
    if (signs[k] < 0.f && pb.distance > kWindingCheckDepth && windingNumber(p, int(pb.part)) < 0.5f) signs[k] = 1.f;
    for (size_t i = 0; i < partCount; ++i)
      if (i != k && parts[i].part == pb.part) {
        if (signs[k] > 0.f)
          signs[i] = 1.f;
        else
          keep[i] = false;
      }
  }
  size_t kept = 0;
  for (size_t k = 0; k < partCount; ++k) {
    if (!keep[k]) continue;
    const PartBest& pb = parts[k];
    const Vec3f diff = p - pb.point.point;
    const float sign = signs[k];
    Hit& h = hits[kept++];
    h.found = true;
    h.signedDistance = sign * pb.distance;
    h.point = pb.point.point;
    h.triangle = pb.tri;
    h.part = int(pb.part);
    h.region = int(pb.key);
    h.normal = pb.distance > 1e-7f ? Vec3f(sign * diff / pb.distance) : pseudoNormal(pb);
  }
  // Smallest signed distance first (ties: the lower part id, then, between regions of a part, the
  // lower triangle as the part's own closest feature is chosen: deterministic, and the first answer is
  // the part's).
  const size_t n = std::min(kept, out.size());
  std::partial_sort(hits.begin(), hits.begin() + std::ptrdiff_t(n), hits.begin() + std::ptrdiff_t(kept),
                    [](const Hit& x, const Hit& y) {
                      return x.signedDistance < y.signedDistance ||
                             (x.signedDistance == y.signedDistance &&
                              (x.part < y.part || (x.part == y.part && x.triangle < y.triangle)));
                    });
  std::copy_n(hits.begin(), n, out.begin());
  return n;
}

float BodyCollider::windingNumber(const Vec3f& p, int part) const {
  const auto r =
      std::find_if(partRanges_.begin(), partRanges_.end(), [&](const PartRange& x) { return int(x.part) == part; });
  if (r == partRanges_.end() || !r->closed) return 1.f;  // nothing to check against: keep the pseudo-normal's answer
  // Sum of the triangles' solid angles seen from p (Van Oosterom & Strackee), over 4 pi.
  double omega = 0.0;
  for (uint32_t i = r->begin; i < r->end; ++i) {
    const uint32_t t = partTriangles_[i];
    const Vec3f a = positions_.row(triangles_(t, 0)).transpose() - p,
                b = positions_.row(triangles_(t, 1)).transpose() - p,
                c = positions_.row(triangles_(t, 2)).transpose() - p;
    const float la = a.norm(), lb = b.norm(), lc = c.norm();
    const float num = a.dot(b.cross(c));
    const float den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    omega += 2.0 * std::atan2(double(num), double(den));
  }
  return float(omega / (4.0 * 3.14159265358979323846));
}

BodyCollider::Hit BodyCollider::closest(const Vec3f& p, float maxDistance, int onlyPart, int skipPart) const {
  // Union of the parts: the smallest signed distance wins.
  Hit hit;
  closestParts(p, maxDistance, std::span<Hit>(&hit, 1), onlyPart, skipPart);
  return hit;
}

}  // namespace swish::bake
