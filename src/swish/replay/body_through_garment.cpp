#include "swish/replay/body_through_garment.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <utility>

#include "swish/bake/transfer/body_coverage.hpp"
#include "swish/bake/transfer/triangle_ray_scene.hpp"
#include "swish/core/error.hpp"
#include "swish/core/mesh.hpp"

namespace swish::replay {

namespace {

// The coverage ray starts this far below the body triangle (m): a garment that lies on the skin, or is
// already sunk a little under it at rest, covers it. The default jersey's rest game mesh cuts up to 8 mm
// under the shoulder tops (its long triangles there are chords of the rounded shoulder), and those
// shoulder caps are what a player sees first; a ray from the skin outwards missed them.
constexpr float kSunk = 0.015f;
// A body triangle buried in another part at rest is covered when the garment lies over it within this (m).
constexpr float kBuriedReach = 0.08f;
// Rays from a body triangle start this far off it (m), so that it is never its own hit.
constexpr float kLiftOff = 1e-4f;

}  // namespace

BodyThroughGarmentMeter::BodyThroughGarmentMeter(const Points3f& restBody, const Triangles& bodyTriangles,
                                                 const Points3f& restGarment, const Triangles& garmentTriangles,
                                                 float reach, float edgeMargin)
    : bodyTriangles_(bodyTriangles),
      garmentTriangles_(garmentTriangles),
      bodyVertices_(restBody.rows()),
      garmentVertices_(restGarment.rows()),
      reach_(reach) {
  if (!(reach > 0.f) || !std::isfinite(reach))
    throw Error("body through the garment: the reach must be a positive number of metres");
  if (!(edgeMargin >= 0.f) || !std::isfinite(edgeMargin))
    throw Error("body through the garment: the margin from the garment's openings must be >= 0 metres");
  // Validates both meshes (indices, finite positions).
  const bake::TriangleRayScene body(restBody, bodyTriangles, "body through the garment: rest body");
  const bake::TriangleRayScene garment(restGarment, garmentTriangles, "body through the garment: rest garment");
  // The garment's open edges (hem, collar, sleeve ends; UV seams welded first, they are not openings).
  std::vector<Vec3f> openEdgePoints;
  for (const auto& [a, b] : openEdges(trianglesWeldedByPosition(restGarment, garmentTriangles)))
    openEdgePoints.push_back(0.5f * (restGarment.row(a) + restGarment.row(b)).transpose());
  auto nearOpening = [&](const Vec3f& p) {
    for (const Vec3f& q : openEdgePoints)
      if ((q - p).squaredNorm() < edgeMargin * edgeMargin) return true;
    return false;
  };
  nearOpening_.assign(size_t(garmentTriangles.rows()), 0);
  for (Eigen::Index t = 0; t < garmentTriangles.rows(); ++t)
    for (int k = 0; k < 3; ++k) nearOpening_[size_t(t)] |= char(nearOpening(restGarment.row(garmentTriangles(t, k))));
  covered_.assign(size_t(bodyTriangles.rows()), 0);
  for (Eigen::Index t = 0; t < bodyTriangles.rows(); ++t) {
    const Vec3f a = restBody.row(bodyTriangles(t, 0)), b = restBody.row(bodyTriangles(t, 1)),
                c = restBody.row(bodyTriangles(t, 2));
    const std::optional<bake::SurfacePoint> hit = bake::garmentAlongNormal(a, b, c, garment, -kSunk, kSunk + reach);
    if (!hit) continue;  // degenerate: no outward direction
    if (hit->found && !nearOpening(hit->point)) {
      covered_[size_t(t)] = 1;
      continue;
    }
    // Buried in another part at rest (the top of an arm tube inside the trunk's shoulder): hidden then, and
    // under the garment when a pose brings it out, if the garment lies over it within kBuriedReach. Inside
    // when the first body surface the outward line meets faces the same way (the line leaves a part there).
    const Vec3f dir = (b - a).cross(c - a).normalized(), centroid = (a + b + c) / 3.f;
    const bake::SurfacePoint exit = body.intersect(centroid + kLiftOff * dir, dir, 0.f, kBuriedReach);
    if (!exit.found) continue;
    const Vec3f ea = restBody.row(bodyTriangles(exit.triangle, 0)), eb = restBody.row(bodyTriangles(exit.triangle, 1)),
                ec = restBody.row(bodyTriangles(exit.triangle, 2));
    if (!((eb - ea).cross(ec - ea).dot(dir) > 0.f)) continue;
    const std::optional<bake::SurfacePoint> over = bake::garmentAlongNormal(a, b, c, garment, 0.f, kBuriedReach);
    covered_[size_t(t)] = over && over->found && !nearOpening(over->point);
  }
}

size_t BodyThroughGarmentMeter::coveredTriangles() const {
  return size_t(std::count(covered_.begin(), covered_.end(), char(1)));
}

BodyThroughGarment BodyThroughGarmentMeter::measure(const Points3f& body, const Points3f& garment,
                                                    const api::Mat4& viewProjection, uint32_t width, uint32_t height,
                                                    std::vector<int32_t>* where) const {
  if (body.rows() != bodyVertices_ || garment.rows() != garmentVertices_)
    throw Error("body through the garment: the posed body has " + std::to_string(body.rows()) +
                " vertices and the garment " + std::to_string(garment.rows()) + ", at rest " +
                std::to_string(bodyVertices_) + " and " + std::to_string(garmentVertices_));
  if (width == 0 || height == 0) throw Error("body through the garment: the picture has no pixels");
  const Eigen::Matrix4f vp = Eigen::Map<const Eigen::Matrix4f>(viewProjection.data());  // column-major, as stored
  const Eigen::FullPivLU<Eigen::Matrix4f> lu(vp);
  if (!vp.allFinite() || !lu.isInvertible())
    throw Error("body through the garment: the view-projection is not invertible");
  const Eigen::Matrix4f inv = lu.inverse();
  const bake::TriangleRayScene bodyScene(body, bodyTriangles_, "body through the garment: posed body");
  const bake::TriangleRayScene garmentScene(garment, garmentTriangles_, "body through the garment: posed garment");
  auto unproject = [&](float x, float y, float z) {
    const Eigen::Vector4f h = inv * Eigen::Vector4f(x, y, z, 1.f);
    return Vec3f(h.head<3>() / h.w());
  };
  if (where) where->assign(size_t(width) * height, -1);
  auto pixel = [&](uint32_t px, uint32_t py, BodyThroughGarment& out) {
    const float x = (float(px) + 0.5f) / float(width) * 2.f - 1.f;
    const float y = (float(py) + 0.5f) / float(height) * 2.f - 1.f;
    const Vec3f from = unproject(x, y, 0.f), to = unproject(x, y, 1.f);
    const float length = (to - from).norm();
    if (!(length > 0.f) || !std::isfinite(length)) return;
    const Vec3f dir = (to - from) / length;
    const bake::SurfacePoint g = garmentScene.intersect(from, dir, 0.f, length);
    const bake::SurfacePoint b = bodyScene.intersect(from, dir, 0.f, length);
    if (g.found && (!b.found || g.distance <= b.distance))
      ++out.garmentPixels;
    else if (b.found && covered_[b.triangle]) {
      // Skin is drawn where the garment covers it at rest. Through the cloth when the garment is right
      // there (sunk beneath the skin, or just behind it), not when its edge has moved off (a hem that
      // rode up when the arms rose, a sleeve that slid).
      const bake::SurfacePoint c = garmentScene.closestPoint(b.point, reach_);
      if (c.found && !nearOpening_[c.triangle]) {
        ++out.pixels;
        if (where) (*where)[size_t(py) * width + px] = int32_t(b.triangle);
      }
    }
  };
  return tbb::parallel_reduce(
      tbb::blocked_range<uint32_t>(0, height), BodyThroughGarment{},
      [&](const tbb::blocked_range<uint32_t>& rows, BodyThroughGarment acc) {
        for (uint32_t py = rows.begin(); py != rows.end(); ++py)
          for (uint32_t px = 0; px < width; ++px) pixel(px, py, acc);
        return acc;
      },
      [](BodyThroughGarment a, const BodyThroughGarment& b) {
        a.pixels += b.pixels;
        a.garmentPixels += b.garmentPixels;
        return a;
      });
}

}  // namespace swish::replay
