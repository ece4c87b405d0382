#include "swish/bake/transfer/triangle_ray_scene.hpp"

#include <embree3/rtcore.h>

#include <cmath>
#include <string>

#include "swish/core/error.hpp"

namespace swish::bake {

struct TriangleRayScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

Vec2f closestPointOnTriangle(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.f && d2 <= 0.f) return {0.f, 0.f};
  const Vec3f bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.f && d4 <= d3) return {1.f, 0.f};
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.f && d1 >= 0.f && d3 <= 0.f) {
    const float v = d1 / (d1 - d3);
    return {v, 0.f};
  }
  const Vec3f cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.f && d5 <= d6) return {0.f, 1.f};
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.f && d2 >= 0.f && d6 <= 0.f) {
    const float w = d2 / (d2 - d6);
    return {0.f, w};
  }
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.f && (d4 - d3) >= 0.f && (d5 - d6) >= 0.f) {
    const float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {1.f - w, w};
  }
  const float denom = va + vb + vc;
  if (!(std::abs(denom) > 0.f)) return {0.f, 0.f};  // degenerate triangle: its first corner
  const float inv = 1.f / denom;
  return {vb * inv, vc * inv};
}

TriangleRayScene::TriangleRayScene(const Points3f& positions, const Triangles& triangles, const std::string& what)
    : impl_(std::make_unique<Impl>()), positions_(positions), triangles_(triangles) {
  if (triangles.rows() == 0) throw Error(what + ": no triangles");
  if (!positions.allFinite()) throw Error(what + ": non-finite vertex positions");
  for (Eigen::Index t = 0; t < triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (triangles(t, k) >= uint32_t(positions.rows()))
        throw Error(what + ": triangle " + std::to_string(t) + " uses vertex " + std::to_string(triangles(t, k)) +
                    " of " + std::to_string(positions.rows()));
  impl_->device = rtcNewDevice("threads=1");  // queries are parallel outside; the build is small
  if (!impl_->device)
    throw Error(what + ": cannot create an Embree device (error " + std::to_string(int(rtcGetDeviceError(nullptr))) +
                ")");
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  // Robust mode: watertight edges, so a ray through a shared edge or vertex cannot slip between the
  // two triangles (texel rays hit edges exactly whenever game and simulation meshes coincide).
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                         3 * sizeof(float), size_t(positions.rows())));
  auto* ib = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                            3 * sizeof(uint32_t), size_t(triangles.rows())));
  if (!vb || !ib) {
    rtcReleaseGeometry(geom);
    throw Error(what + ": Embree could not allocate geometry buffers");
  }
  std::copy(positions.data(), positions.data() + positions.size(), vb);
  std::copy(triangles.data(), triangles.data() + triangles.size(), ib);
  rtcCommitGeometry(geom);
  rtcAttachGeometry(impl_->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(impl_->scene);
  if (rtcGetDeviceError(impl_->device) != RTC_ERROR_NONE) throw Error(what + ": Embree scene build failed");
}

TriangleRayScene::~TriangleRayScene() = default;
TriangleRayScene::TriangleRayScene(TriangleRayScene&&) noexcept = default;
TriangleRayScene& TriangleRayScene::operator=(TriangleRayScene&&) noexcept = default;

namespace {

struct ClosestQuery {
  const TriangleRayScene* scene;
  Vec3f p;
  SurfacePoint best;
};

bool closestPointCallback(RTCPointQueryFunctionArguments* args) {
  auto* q = static_cast<ClosestQuery*>(args->userPtr);
  const uint32_t t = args->primID;
  const auto& P = q->scene->positions();
  const auto& T = q->scene->triangles();
  const Vec3f a = P.row(T(t, 0)).transpose(), b = P.row(T(t, 1)).transpose(), c = P.row(T(t, 2)).transpose();
  const Vec2f uv = closestPointOnTriangle(q->p, a, b, c);
  const Vec3f x = (1.f - uv.x() - uv.y()) * a + uv.x() * b + uv.y() * c;
  const float d = (x - q->p).norm();
  if (d < q->best.distance || (d == q->best.distance && q->best.found && t < q->best.triangle)) {
    q->best = {true, t, uv.x(), uv.y(), x, d};
    if (d < args->query->radius) {
      args->query->radius = d;
      return true;
    }
  }
  return false;
}

}  // namespace

SurfacePoint TriangleRayScene::closestPoint(const Vec3f& p, float maxRadius) const {
  ClosestQuery q{this, p, {}};
  q.best.distance = maxRadius;
  RTCPointQuery query;
  query.x = p.x(), query.y = p.y(), query.z = p.z();
  query.time = 0.f;
  query.radius = maxRadius;
  RTCPointQueryContext ctx;
  rtcInitPointQueryContext(&ctx);
  rtcPointQuery(impl_->scene, &query, &ctx, closestPointCallback, &q);
  if (!q.best.found) q.best.distance = std::numeric_limits<float>::infinity();
  return q.best;
}

SurfacePoint TriangleRayScene::intersect(const Vec3f& origin, const Vec3f& direction, float tNear, float tFar) const {
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh{};
  rh.ray.org_x = origin.x(), rh.ray.org_y = origin.y(), rh.ray.org_z = origin.z();
  rh.ray.dir_x = direction.x(), rh.ray.dir_y = direction.y(), rh.ray.dir_z = direction.z();
  rh.ray.tnear = tNear;
  rh.ray.tfar = tFar;
  rh.ray.mask = ~0u;
  rh.ray.time = 0.f;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &ctx, &rh);
  SurfacePoint s;
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return s;
  s.found = true;
  s.triangle = rh.hit.primID;
  s.u = rh.hit.u;
  s.v = rh.hit.v;
  s.distance = rh.ray.tfar;
  s.point = origin + direction * rh.ray.tfar;
  return s;
}

}  // namespace swish::bake
