#include "swish/bake/transfer/normal_map_baker.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "swish/bake/transfer/mesh_transfer.hpp"
#include "swish/bake/transfer/triangle_ray_scene.hpp"
#include "swish/bake/transfer/uv_dilation.hpp"
#include "swish/core/error.hpp"

namespace swish::bake {

NormalMapBaker::NormalMapBaker(const Points2f& uvs, const Triangles& tris, const Points3f& rest,
                               const NormalMapBakeSettings& s, const std::string& what)
    : uvs_(uvs), triangles_(tris), settings_(s), what_(what) {
  if (s.width == 0 || s.height == 0 || s.width > 16384 || s.height > 16384)
    throw Error(what + ": map size " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                " is outside 1..16384");
  if (!(s.maxDistance > 0.f) || !std::isfinite(s.maxDistance))
    throw Error(what + ": maxDistance must be positive and finite");
  if (s.dilationRings < 0) throw Error(what + ": dilationRings must be >= 0");
  if (uvs.rows() != rest.rows() || uvs.rows() == 0)
    throw Error(what + ": the game mesh needs one UV per vertex (" + std::to_string(uvs.rows()) + " UVs, " +
                std::to_string(rest.rows()) + " vertices)");
  if (!uvs.allFinite()) throw Error(what + ": non-finite UVs");
  for (Eigen::Index t = 0; t < tris.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (tris(t, k) >= uint32_t(rest.rows()))
        throw Error(what + ": triangle " + std::to_string(t) + " index out of range");
  topology_ = buildFrameTopology(tris, rest);

  // Rasterise the UV layout: texel centres inside each triangle, first (lowest) triangle wins.
  const uint32_t W = s.width, H = s.height;
  std::vector<int64_t> owner(size_t(W) * H, -1);
  std::vector<Vec2f> bary(size_t(W) * H);
  for (Eigen::Index t = 0; t < tris.rows(); ++t) {
    const Vec2f a = uvs.row(tris(t, 0)).transpose(), b = uvs.row(tris(t, 1)).transpose();
    const Vec2f c = uvs.row(tris(t, 2)).transpose();
    const float det = (b.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (b.y() - a.y());
    if (!(std::abs(det) > 1e-14f)) continue;  // zero UV area: covers no texel
    const float minU = std::min({a.x(), b.x(), c.x()}), maxU = std::max({a.x(), b.x(), c.x()});
    const float minV = std::min({a.y(), b.y(), c.y()}), maxV = std::max({a.y(), b.y(), c.y()});
    const int x0 = std::max(0, int(std::floor(minU * W - 0.5f))),
              x1 = std::min(int(W) - 1, int(std::ceil(maxU * W - 0.5f)));
    const int y0 = std::max(0, int(std::floor(minV * H - 0.5f))),
              y1 = std::min(int(H) - 1, int(std::ceil(maxV * H - 0.5f)));
    // Texels on a shared edge belong to whichever triangle comes first; the small tolerance closes
    // the cracks that rounding would leave between neighbours.
    const float eps = -1e-6f;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const size_t i = size_t(y) * W + x;
        if (owner[i] >= 0) continue;
        const Vec2f p((float(x) + .5f) / float(W), (float(y) + .5f) / float(H));
        const float b1 = ((p.x() - a.x()) * (c.y() - a.y()) - (c.x() - a.x()) * (p.y() - a.y())) / det;
        const float b2 = ((b.x() - a.x()) * (p.y() - a.y()) - (p.x() - a.x()) * (b.y() - a.y())) / det;
        if (b1 < eps || b2 < eps || 1.f - b1 - b2 < eps) continue;
        owner[i] = t;
        bary[i] = Vec2f(b1, b2);
      }
  }
  for (size_t i = 0; i < owner.size(); ++i)
    if (owner[i] >= 0) texels_.push_back({uint32_t(i), uint32_t(owner[i]), bary[i].x(), bary[i].y()});
}

NormalMapImage NormalMapBaker::bake(const Points3f& game, const Points3f& sim, const Triangles& simTris,
                                    const MeshFrameTopology& simTopo, NormalMapBakeStats* stats) const {
  if (game.rows() != uvs_.rows())
    throw Error(what_ + ": " + std::to_string(game.rows()) + " game positions for " + std::to_string(uvs_.rows()) +
                " vertices");
  if (!game.allFinite()) throw Error(what_ + ": non-finite game-mesh positions");
  if (simTopo.normalAdjacency.offsets.size() != size_t(sim.rows()) + 1)
    throw Error(what_ + ": the simulation topology does not match its " + std::to_string(sim.rows()) + " vertices");
  Points3f gameN;
  Points4f gameT;
  computeVertexFrames(game, uvs_, triangles_, topology_, gameN, gameT);
  const Points3f simN = surfaceVertexNormals(sim, simTris, simTopo);
  const TriangleRayScene scene(sim, simTris, what_ + " (simulation mesh)");

  NormalMapImage im;
  im.width = settings_.width;
  im.height = settings_.height;
  im.xy.assign(size_t(im.width) * im.height * 2, 0.f);
  std::vector<uint8_t> filled(size_t(im.width) * im.height, 0);
  std::vector<float> hitDistance(texels_.size(), -1.f);
  const float maxD = settings_.maxDistance;
  // Rays start slightly behind the surface so that a simulation surface exactly at the game surface
  // (t = 0) is found by one of the two rays whatever Embree's tnear convention.
  const float lead = 1e-4f * maxD;

  tbb::parallel_for(size_t(0), texels_.size(), [&](size_t k) {
    const ChartTexel& c = texels_[k];
    const uint32_t i0 = triangles_(c.triangle, 0), i1 = triangles_(c.triangle, 1), i2 = triangles_(c.triangle, 2);
    const float w0 = 1.f - c.b1 - c.b2;
    auto lerp3 = [&](const auto& m) {
      return Vec3f(w0 * m.row(i0).template head<3>().transpose() + c.b1 * m.row(i1).template head<3>().transpose() +
                   c.b2 * m.row(i2).template head<3>().transpose());
    };
    const Vec3f P = lerp3(game);
    Vec3f N = lerp3(gameN);
    N = N.norm() > 1e-20f ? Vec3f(N.normalized()) : Vec3f::UnitZ();
    Vec3f T = lerp3(gameT);
    T -= N * N.dot(T);
    T = T.norm() > 1e-20f ? Vec3f(T.normalized()) : anyPerpendicular(N);
    const float sign = (w0 * gameT(i0, 3) + c.b1 * gameT(i1, 3) + c.b2 * gameT(i2, 3)) < 0.f ? -1.f : 1.f;
    const Vec3f B = sign * N.cross(T);

    auto simNormalAt = [&](const SurfacePoint& s) {
      const uint32_t j0 = simTris(s.triangle, 0), j1 = simTris(s.triangle, 1), j2 = simTris(s.triangle, 2);
      Vec3f n = (1.f - s.u - s.v) * simN.row(j0).transpose() + s.u * simN.row(j1).transpose() +
                s.v * simN.row(j2).transpose();
      return n.norm() > 1e-20f ? Vec3f(n.normalized()) : N;
    };
    // Nearest valid hit along +N and along -N; invalid (back-facing) hits are stepped over.
    float bestDist = std::numeric_limits<float>::infinity();
    Vec3f bestNormal = N;
    for (int dir = 0; dir < 2; ++dir) {
      const Vec3f d = dir == 0 ? N : Vec3f(-N);
      const Vec3f origin = P - d * lead;
      float tNear = 0.f;
      for (int attempt = 0; attempt < 4; ++attempt) {
        const SurfacePoint s = scene.intersect(origin, d, tNear, maxD + lead);
        if (!s.found) break;
        const float dist = std::abs(s.distance - lead);
        if (dist >= bestDist) break;
        const Vec3f n = simNormalAt(s);
        if (n.dot(N) > 0.f) {
          bestDist = dist;
          bestNormal = n;
          break;
        }
        tNear = std::nextafter(s.distance, std::numeric_limits<float>::infinity());
      }
    }
    if (!std::isfinite(bestDist)) return;
    im.xy[2 * size_t(c.index)] = bestNormal.dot(T);
    im.xy[2 * size_t(c.index) + 1] = bestNormal.dot(B);
    filled[c.index] = 1;
    hitDistance[k] = bestDist;
  });

  const DilationResult dil = dilateNormalMap(im, filled, settings_.dilationRings);
  if (stats) {
    *stats = {};
    stats->chartTexels = texels_.size();
    double sum = 0.0;
    for (float d : hitDistance)
      if (d >= 0.f) {
        ++stats->hitTexels;
        sum += d;
        stats->maxHitDistance = std::max(stats->maxHitDistance, d);
      }
    stats->missedTexels = texels_.size() - stats->hitTexels;
    stats->meanHitDistance = stats->hitTexels ? float(sum / double(stats->hitTexels)) : 0.f;
    stats->dilatedTexels = dil.dilated;
    stats->flatTexels = dil.setToFlat;
  }
  return im;
}

}  // namespace swish::bake
