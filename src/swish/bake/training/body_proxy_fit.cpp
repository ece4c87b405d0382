#include "swish/bake/training/body_proxy_fit.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include <Eigen/Eigenvalues>

#include "swish/bake/cloth/body_collider.hpp"
#include "swish/core/error.hpp"

namespace swish::bake {

namespace {

constexpr float kPi = 3.14159265358979f;

float segmentDistance(const Vec3f& p, const Vec3f& a, const Vec3f& b) {
  const Vec3f d = b - a;
  const float len2 = d.squaredNorm();
  const float t = len2 > 0.f ? std::clamp((p - a).dot(d) / len2, 0.f, 1.f) : 0.f;
  return (p - (a + d * t)).norm();
}

// Points on a capsule's surface: rings along the segment and two hemispheres.
std::vector<Vec3f> surfaceSamples(const BodyCapsule& c) {
  Vec3f u = c.b - c.a;
  const float len = u.norm();
  u = len > 0.f ? Vec3f(u / len) : Vec3f::UnitY();
  const Vec3f v = (std::abs(u.x()) < 0.9f ? Vec3f::UnitX() : Vec3f::UnitY()).cross(u).normalized();
  const Vec3f w = u.cross(v);
  std::vector<Vec3f> out;
  const int around = 24, along = std::max(2, int(std::ceil(len / 0.01f)) + 1);
  for (int i = 0; i < along; ++i) {
    const Vec3f o = c.a + u * (len * float(i) / float(along - 1));
    for (int k = 0; k < around; ++k) {
      const float t = 2.f * kPi * float(k) / float(around);
      out.push_back(o + (v * std::cos(t) + w * std::sin(t)) * c.radius);
    }
  }
  for (int end = 0; end < 2; ++end) {
    const Vec3f o = end ? c.b : c.a, axis = end ? u : Vec3f(-u);
    for (int lat = 1; lat <= 4; ++lat) {
      const float phi = 0.5f * kPi * float(lat) / 4.f;
      for (int k = 0; k < around; ++k) {
        const float t = 2.f * kPi * float(k) / float(around);
        out.push_back(o + (axis * std::sin(phi) + (v * std::cos(t) + w * std::sin(t)) * std::cos(phi)) * c.radius);
      }
    }
  }
  return out;
}

float boxDistance(const Vec3f& p, const Vec3f& lo, const Vec3f& hi) { return (p.cwiseMax(lo).cwiseMin(hi) - p).norm(); }

}  // namespace

BodyProxyFit fitBodyProxy(const Mesh& body, const Skeleton& skeleton, const Mesh* garment,
                          const BodyProxyFitSettings& s) {
  body.validate("body proxy fit: body", skeleton.size());
  if (body.triangleCount() == 0) throw Error("body proxy fit: the body has no triangles");
  const size_t n = body.vertexCount();
  const Triangles welded = trianglesWeldedByPosition(body.positions, body.triangles);
  // Part of each vertex through its weld representative (a seam copy is in no welded triangle).
  const std::vector<uint32_t> rep = weldByPosition(body.positions);
  const std::vector<uint32_t> repPart = connectedParts(welded, n);
  std::vector<uint32_t> part(n);
  for (size_t v = 0; v < n; ++v) part[v] = repPart[rep[v]];

  // Constraint points of each part: vertices, edge midpoints, triangle centres (chords of a coarse
  // tube sag towards its axis; the midpoints catch most of that).
  std::map<uint32_t, std::vector<Vec3f>> partPoints;
  for (size_t v = 0; v < n; ++v) partPoints[part[v]].push_back(body.positions.row(Eigen::Index(v)).transpose());
  for (Eigen::Index t = 0; t < welded.rows(); ++t) {
    const Vec3f a = body.positions.row(welded(t, 0)).transpose(), b = body.positions.row(welded(t, 1)).transpose(),
                c = body.positions.row(welded(t, 2)).transpose();
    auto& pts = partPoints[part[welded(t, 0)]];
    pts.push_back((a + b + c) / 3.f);
    pts.push_back((a + b) * 0.5f), pts.push_back((b + c) * 0.5f), pts.push_back((c + a) * 0.5f);
  }

  // Groups: (dominant joint, part) -> vertices.
  std::map<std::pair<uint32_t, uint32_t>, std::vector<Vec3f>> groups;
  for (size_t v = 0; v < n; ++v)
    groups[{body.skin.strongestJoint(v), part[v]}].push_back(body.positions.row(Eigen::Index(v)).transpose());

  BodyCollider collider(body, 0.05f, "body proxy fit: body");
  collider.pose(std::vector<Mat4f>(skeleton.size(), Mat4f::Identity()));

  Vec3f lo = Vec3f::Constant(-1e30f), hi = Vec3f::Constant(1e30f);
  if (garment && garment->vertexCount() > 0) {
    lo = garment->positions.colwise().minCoeff().transpose();
    hi = garment->positions.colwise().maxCoeff().transpose();
  }

  BodyProxyFit fit;
  struct Kept {
    BodyCapsule capsule;
    float distance;
  };
  std::vector<Kept> kept;
  for (const auto& [key, pts] : groups) {
    ++fit.groups;
    if (pts.size() < s.minVertices) {
      ++fit.dropped;
      continue;
    }
    Vec3f centre = Vec3f::Zero();
    for (const Vec3f& p : pts) centre += p;
    centre /= float(pts.size());
    Mat3f cov = Mat3f::Zero();
    for (const Vec3f& p : pts) cov += (p - centre) * (p - centre).transpose();
    const Eigen::SelfAdjointEigenSolver<Mat3f> eig(cov);  // ascending eigenvalues
    const std::vector<Vec3f>& constraints = partPoints.at(key.second);
    BodyCapsule best;
    float bestVolume = -1.f;
    for (int axis = 2; axis >= 0; --axis) {
      const Vec3f u = eig.eigenvectors().col(axis).normalized();
      float tlo = 1e30f, thi = -1e30f;
      for (const Vec3f& p : pts) {
        const float t = (p - centre).dot(u);
        tlo = std::min(tlo, t), thi = std::max(thi, t);
      }
      const float mid = 0.5f * (tlo + thi), half = 0.5f * (thi - tlo);
      // Each end on its own: up to half the group's extent beyond it (into the neighbouring group, so
      // that consecutive capsules overlap instead of leaving a waist between their round ends) or
      // back to the middle (a closed end, e.g. the bottom of the trunk, keeps the segment from it).
      static constexpr float kShares[] = {1.5f, 1.25f, 1.f, 0.75f, 0.5f, 0.25f, 0.f};
      for (const float lowShare : kShares)
        for (const float highShare : kShares) {
          BodyCapsule c;
          c.joint = key.first;
          c.a = centre + u * (mid - half * lowShare);
          c.b = centre + u * (mid + half * highShare);
          float r = 1e30f;
          for (const Vec3f& p : constraints) r = std::min(r, segmentDistance(p, c.a, c.b));
          c.radius = r;
          const float volume = kPi * r * r * (c.b - c.a).norm() + 4.f / 3.f * kPi * r * r * r;
          if (r < 1e29f && volume > bestVolume) bestVolume = volume, best = c;
        }
    }
    // Inside the real body (all parts together), within the sampling's tolerance.
    float outside = 0.f;
    for (int round = 0; round < 8 && best.radius >= s.minRadius; ++round) {
      outside = 0.f;
      for (const Vec3f& p : surfaceSamples(best)) {
        const BodyCollider::Hit h = collider.closest(p, 0.2f);
        const float sd = h.found ? h.signedDistance : 0.2f;
        outside = std::max(outside, sd);
      }
      if (outside <= kInsideTolerance) break;
      best.radius -= outside;
    }
    if (!(best.radius >= s.minRadius) || outside > kInsideTolerance) {
      ++fit.dropped;
      continue;
    }
    fit.worstOutsideMm = std::max(fit.worstOutsideMm, 1000.f * outside);
    float distance = 0.f;
    if (garment) distance = std::min(boxDistance(best.a, lo, hi), boxDistance(best.b, lo, hi)) - best.radius;
    if (s.reach >= 0.f && distance > s.reach) {
      ++fit.dropped;
      continue;
    }
    kept.push_back({best, distance});
  }
  std::stable_sort(kept.begin(), kept.end(), [](const Kept& a, const Kept& b) { return a.distance < b.distance; });
  if (kept.size() > kMaxBodyCapsules) {
    fit.dropped += kept.size() - kMaxBodyCapsules;
    kept.resize(kMaxBodyCapsules);
  }
  // In skeleton order (stable for equal joints): neighbouring threads' capsules near each other.
  std::stable_sort(kept.begin(), kept.end(),
                   [](const Kept& a, const Kept& b) { return a.capsule.joint < b.capsule.joint; });
  for (const Kept& k : kept) {
    fit.proxy.capsules.push_back(k.capsule);
    fit.capsuleJoints.push_back(skeleton.joints[k.capsule.joint].name);
  }
  return fit;
}

}  // namespace swish::bake
