#include "swish/bake/transfer/body_coverage.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include <tbb/parallel_for.h>

#include "swish/bake/cloth/body_collider.hpp"
#include "swish/bake/transfer/triangle_ray_scene.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/reference_skinning.hpp"

namespace swish::bake {

std::optional<SurfacePoint> garmentAlongNormal(const Vec3f& a, const Vec3f& b, const Vec3f& c,
                                               const TriangleRayScene& garment, float from, float length) {
  const Vec3f n = (b - a).cross(c - a);
  const float len = n.norm();
  if (!(len > 0.f)) return std::nullopt;
  const Vec3f centroid = (a + b + c) / 3.f;
  const Vec3f dir = n / len;
  return garment.intersect(centroid + from * dir, dir, 0.f, length);
}

BodyCoverageResult coveredBodyTriangles(const Character& character, const std::vector<const DatasetPose*>& poses,
                                        const BodyCoverageOptions& o) {
  const Mesh& body = character.body;
  BodyCoverageResult r;
  r.bodyTriangles = uint32_t(body.triangleCount());
  if (body.triangleCount() == 0 || poses.empty()) return r;
  const size_t nt = body.triangleCount();
  std::vector<uint32_t> hits(nt, 0);
  std::vector<uint8_t> everCovered(nt, 0);
  // Parts of the body buried in each other (an arm tube in the trunk) hide their own triangles: the
  // collider's closest point of the OTHER parts tells whether a triangle is inside one of them.
  std::optional<BodyCollider> collider;
  if (o.buriedCounts) collider.emplace(body, 0.05f, "body coverage: body");
  const size_t step = std::max<size_t>(1, (poses.size() + o.maxPoses - 1) / std::max<size_t>(1, o.maxPoses));
  for (size_t k = 0; k < poses.size(); k += step) {
    const DatasetPose& p = *poses[k];
    if (size_t(p.gameMeshWorld.rows()) != character.garment.vertexCount())
      throw Error("body coverage: pose " + std::to_string(p.id) + " has a game mesh of " +
                  std::to_string(p.gameMeshWorld.rows()) + " vertices, the character's garment " +
                  std::to_string(character.garment.vertexCount()));
    const Points3f posed =
        runtime::referenceSkin(body.positions, body.skin, character.skeleton.skinningMatrices(p.pose));
    const TriangleRayScene garment(p.gameMeshWorld, character.garment.triangles, "body coverage: garment");
    if (collider) collider->pose(character.skeleton.skinningMatrices(p.pose));
    std::vector<uint8_t> hit(nt, 0), buried(nt, 0);
    tbb::parallel_for(size_t(0), nt, [&](size_t t) {
      const Vec3f a = posed.row(body.triangles(Eigen::Index(t), 0)), b = posed.row(body.triangles(Eigen::Index(t), 1)),
                  c = posed.row(body.triangles(Eigen::Index(t), 2));
      const std::optional<SurfacePoint> g = garmentAlongNormal(a, b, c, garment, -o.maxInside, o.maxInside + o.maxGap);
      if (!g) return;  // degenerate: never covered
      hit[t] = g->found;
      if (!hit[t] && collider) {
        const Vec3f centroid = (a + b + c) / 3.f;
        const int part = int(collider->triangleRegions()[t]);
        const BodyCollider::Hit q = collider->closest(centroid, kBuriedSearch, -1, part);
        buried[t] = q.found && q.signedDistance < -kBuriedDepth;
      }
    });
    size_t own = 0, inside = 0;
    for (size_t t = 0; t < nt; ++t) {
      own += hit[t];
      inside += buried[t];
      hits[t] += hit[t] | buried[t];
      everCovered[t] |= hit[t];
    }
    r.buriedPerPose.push_back(uint32_t(inside));
    if (r.poses == 0) r.coveredAtRest = own;
    r.perPose.push_back(uint32_t(own));
    ++r.poses;
  }
  for (double share : {0.5, 0.8, 0.9, 0.95, 0.98, 1.0}) {
    const uint32_t n = uint32_t(std::max<double>(1.0, std::ceil(share * double(r.poses) - 1e-9)));
    r.byShare.push_back({share, uint32_t(std::count_if(hits.begin(), hits.end(), [&](uint32_t h) { return h >= n; }))});
  }
  // Covered in at least minShare of the poses tested (rounded up; 1: every one).
  const uint32_t need = uint32_t(std::max<double>(1.0, std::ceil(o.minShare * double(r.poses) - 1e-9)));
  for (size_t t = 0; t < nt; ++t)
    if (hits[t] >= need && everCovered[t]) r.covered.push_back(uint32_t(t));
  return r;
}

}  // namespace swish::bake
