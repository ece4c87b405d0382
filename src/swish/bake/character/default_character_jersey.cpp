#include "swish/bake/character/default_character_jersey.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "swish/core/error.hpp"

namespace swish::bake {
namespace {

struct Builder {
  std::vector<Vec3f> pos;
  std::vector<Vec2f> uv;
  std::vector<std::array<uint32_t, 3>> tris;
  uint32_t add(const Vec3f& p, const Vec2f& t) {
    pos.push_back(p);
    uv.push_back(t);
    return uint32_t(pos.size() - 1);
  }
};

void pushOutOfBody(Vec3f& p, const std::vector<const SweptEllipseTube*>& parts, float clearance) {
  // A few sweeps: leaving one part can enter another where parts meet (armpit, neck).
  for (int sweep = 0; sweep < 4; ++sweep) {
    bool moved = false;
    for (const auto* part : parts) moved = part->pushOut(p, clearance) || moved;
    if (!moved) return;
  }
}

// The body's torso surface at angle theta (0 = front, +pi/2 = left) and height y.
Vec3f torsoPoint(const SweptEllipseTube& torso, float theta, float y) {
  const TubeSection s = torso.sectionAtHeight(y);
  return {s.center.x() + s.halfWidth * std::sin(theta), y, s.center.z() + s.halfDepth * std::cos(theta)};
}

}  // namespace

Mesh buildJersey(const RecipeJersey& r, const SweptEllipseTube& torso, const std::vector<JerseyArm>& arms,
                 const std::vector<const SweptEllipseTube*>& bodyParts) {
  const int N = r.columns, R = r.rows;
  const float height = r.collarY - r.hemY;
  const float vBase = 0.01f;
  Builder b;

  // Torso grid, columns 0..N (column N is the back seam copy of column 0).
  std::vector<std::vector<uint32_t>> grid(size_t(R + 1), std::vector<uint32_t>(size_t(N + 1)));
  std::vector<Vec3f> rowPos(static_cast<size_t>(N));
  for (int row = 0; row <= R; ++row) {
    const float y = r.hemY + height * float(row) / float(R);
    for (int i = 0; i < N; ++i) {
      const float theta = -float(M_PI) + 2.f * float(M_PI) * float(i) / float(N);
      // Offset along the body surface's normal, not radially: on the shoulder slope the two differ a lot.
      const float h = 1e-3f;
      const Vec3f dTheta = torsoPoint(torso, theta + h, y) - torsoPoint(torso, theta - h, y);
      const Vec3f dY = torsoPoint(torso, theta, y + h) - torsoPoint(torso, theta, y - h);
      Vec3f p = torsoPoint(torso, theta, y) + r.offset * dTheta.cross(dY).normalized();
      pushOutOfBody(p, bodyParts, r.clearance);
      rowPos[size_t(i)] = p;
    }
    for (int i = 0; i <= N; ++i)
      grid[size_t(row)][size_t(i)] =
          b.add(rowPos[size_t(i % N)], Vec2f(float(i) / float(N), vBase + height * float(row) / float(R)));
  }

  // Armhole blocks: quads [col0, col0 + a) x [rowA, rowB).
  const int rowA = std::clamp(int(std::lround((r.armholeBottomY - r.hemY) / height * float(R))), 1, R - 2);
  const int rowB = std::clamp(int(std::lround((r.armholeTopY - r.hemY) / height * float(R))), rowA + 1, R - 1);
  const TubeSection mid = torso.sectionAtHeight(0.5f * (r.armholeBottomY + r.armholeTopY));
  const float dTheta = 2.f * float(M_PI) / float(N);
  const int a = std::max(2, 2 * int(std::lround(r.armholeHalfWidth / (mid.halfDepth + r.offset) / dTheta)));
  struct Hole {
    int col0;
    float side;
  };
  std::vector<Hole> holes;
  for (const JerseyArm& arm : arms) holes.push_back({(arm.side > 0 ? 3 * N / 4 : N / 4) - a / 2, arm.side});
  auto inHole = [&](int i, int row) {
    for (const Hole& h : holes)
      if (i >= h.col0 && i < h.col0 + a && row >= rowA && row < rowB) return true;
    return false;
  };
  std::set<std::pair<uint32_t, uint32_t>> torsoEdges;
  for (int row = 0; row < R; ++row)
    for (int i = 0; i < N; ++i) {
      if (inHole(i, row)) continue;
      const uint32_t v00 = grid[size_t(row)][size_t(i)], v10 = grid[size_t(row)][size_t(i + 1)];
      const uint32_t v11 = grid[size_t(row + 1)][size_t(i + 1)], v01 = grid[size_t(row + 1)][size_t(i)];
      b.tris.push_back({v00, v10, v11});
      b.tris.push_back({v00, v11, v01});
      for (const auto& t : {std::array<uint32_t, 3>{v00, v10, v11}, std::array<uint32_t, 3>{v00, v11, v01}})
        for (int k = 0; k < 3; ++k) torsoEdges.insert({t[size_t(k)], t[size_t((k + 1) % 3)]});
    }

  // Sleeves.
  const float sleeveU0[2] = {0.02f, 0.52f};
  for (size_t h = 0; h < holes.size(); ++h) {
    const Hole& hole = holes[h];
    const SweptEllipseTube& arm = *arms[h].tube;
    // Boundary loop of the block, as torso vertex indices.
    std::vector<uint32_t> loop;
    for (int i = hole.col0; i < hole.col0 + a; ++i) loop.push_back(grid[size_t(rowA)][size_t(i)]);
    for (int row = rowA; row < rowB; ++row) loop.push_back(grid[size_t(row)][size_t(hole.col0 + a)]);
    for (int i = hole.col0 + a; i > hole.col0; --i) loop.push_back(grid[size_t(rowB)][size_t(i)]);
    for (int row = rowB; row > rowA; --row) loop.push_back(grid[size_t(row)][size_t(hole.col0)]);
    const size_t M = loop.size();

    Vec3f loopCenter = Vec3f::Zero();
    for (uint32_t v : loop) loopCenter += b.pos[v];
    loopCenter /= float(M);
    TubeSection start;
    if (!std::isfinite(arm.normalisedRadius(loopCenter, &start)))
      start = arm.section(0.f);  // the loop's centre lies behind the arm's start: begin there
    const float ahead = 0.01f;
    const float metresPerParam = (arm.section(start.param + ahead).center - start.center).norm() / ahead;
    // Seam under the arm: the loop vertex closest to the underside direction.
    const Vec3f under = (-Vec3f::UnitY() - (-Vec3f::UnitY()).dot(start.tangent) * start.tangent).normalized();
    size_t seam = 0;
    float bestDot = -2.f;
    for (size_t j = 0; j < M; ++j) {
      const float d = (b.pos[loop[j]] - loopCenter).normalized().dot(under);
      if (d > bestDot) {
        bestDot = d;
        seam = j;
      }
    }
    std::rotate(loop.begin(), loop.begin() + long(seam), loop.end());
    // Sleeve vertex grid: rings 0..K, columns 0..M (column M is the seam copy of column 0).
    const int K = r.sleeveRings;
    const float circumference = 2.f * float(M_PI) * (0.5f * (start.halfWidth + start.halfDepth) + r.offset);
    const float vTop = vBase + height + 0.03f;
    std::vector<std::vector<uint32_t>> ring(size_t(K + 1), std::vector<uint32_t>(M + 1));
    // Each column's angle about the arm, in the start frame (so rings do not twist against each
    // other): the seam vertex's own angle, then advancing by arc length along the loop. The loop's
    // own angles would bunch up where a side of its rectangle is seen edge-on from the arm axis, and
    // left pairs of columns under a millimetre apart along the whole sleeve: cloth edges a hundred
    // times shorter than their neighbours, which no cloth solver can keep stable.
    auto angleOf = [&](const Vec3f& p0) {
      const Vec3f q = p0 - start.center;
      return std::atan2(q.dot(start.e2), q.dot(start.e1));
    };
    std::vector<float> arc(M + 1, 0.f);
    float turn = 0.f;  // total signed angle around the loop: +-2 pi, its sign is the direction
    for (size_t j = 0; j < M; ++j) {
      arc[j + 1] = arc[j] + (b.pos[loop[(j + 1) % M]] - b.pos[loop[j]]).norm();
      turn += std::remainder(angleOf(b.pos[loop[(j + 1) % M]]) - angleOf(b.pos[loop[j]]), 2.f * float(M_PI));
    }
    const float phiSeam = angleOf(b.pos[loop[0]]), direction = turn >= 0.f ? 1.f : -1.f;
    for (int k = 0; k <= K; ++k) {
      const float along = r.sleeveLength * float(k) / float(K);
      const TubeSection s = arm.section(start.param + along / std::max(metresPerParam, 1e-4f));
      // Rings ease from the armhole loop onto the arm tube over the first `easeRings` rings.
      const float e = std::min(1.f, float(k) / float(std::max(1, std::min(K, 3))));
      const float blend = e * e * (3.f - 2.f * e);
      for (size_t j = 0; j <= M; ++j) {
        const Vec2f t(sleeveU0[h % 2] + circumference * float(j) / float(M), vTop + along);
        if (j == M) {  // the seam copy of column 0: bitwise the same position, so it welds
          ring[size_t(k)][j] = b.add(b.pos[ring[size_t(k)][0]], t);
          continue;
        }
        const Vec3f p0 = b.pos[loop[j]];
        Vec3f p = p0;
        if (k > 0) {
          const float phi = phiSeam + direction * 2.f * float(M_PI) * arc[j] / arc[M];
          const Vec3f onTube = s.center + (s.halfWidth + r.offset) * std::cos(phi) * s.e1 +
                               (s.halfDepth + r.offset) * std::sin(phi) * s.e2;
          p = (1.f - blend) * p0 + blend * onTube;
          pushOutOfBody(p, bodyParts, r.clearance);
        }
        ring[size_t(k)][j] = b.add(p, t);
      }
    }
    // Winding: opposite to the torso's along the shared loop.
    const bool torsoForward = torsoEdges.count({loop[0], loop[1]}) > 0;
    for (int k = 0; k < K; ++k)
      for (size_t j = 0; j < M; ++j) {
        const uint32_t a0 = ring[size_t(k)][j], a1 = ring[size_t(k)][j + 1];
        const uint32_t b0 = ring[size_t(k + 1)][j], b1 = ring[size_t(k + 1)][j + 1];
        if (torsoForward) {
          b.tris.push_back({a1, a0, b0});
          b.tris.push_back({a1, b0, b1});
        } else {
          b.tris.push_back({a0, a1, b1});
          b.tris.push_back({a0, b1, b0});
        }
      }
  }

  // Drop grid vertices inside the armholes (no triangle uses them).
  std::vector<int> remap(b.pos.size(), -1);
  for (const auto& t : b.tris)
    for (uint32_t v : t) remap[v] = 0;
  Mesh m;
  int next = 0;
  for (auto& x : remap)
    if (x == 0) x = next++;
  m.positions.resize(next, 3);
  m.uvs.resize(next, 2);
  for (size_t v = 0; v < remap.size(); ++v)
    if (remap[v] >= 0) {
      m.positions.row(remap[v]) = b.pos[v].transpose();
      m.uvs.row(remap[v]) = b.uv[v].transpose();
    }
  m.triangles.resize(Eigen::Index(b.tris.size()), 3);
  for (size_t t = 0; t < b.tris.size(); ++t)
    for (int k = 0; k < 3; ++k) m.triangles(Eigen::Index(t), k) = uint32_t(remap[b.tris[t][size_t(k)]]);
  if (m.uvs.maxCoeff() > 1.f || m.uvs.minCoeff() < 0.f)
    throw Error("default jersey: UV layout leaves [0, 1] (sleeves too long or wide for the recipe's chart)");
  return m;
}

}  // namespace swish::bake
