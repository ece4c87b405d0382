#pragma once
// Small characters for the cloth tests and benchmark, built in code: a skinned capsule "torso" with a
// tube "shirt" around it, and a sphere with a flat sheet above it. Analytic shapes, so tests can check
// the solver against exact distances instead of against the collider it uses.
#include <cmath>

#include "swish/core/character.hpp"

namespace swish::test {

struct CapsuleSpec {
  float radius = 0.12f;                  // body
  float axisLow = 0.f, axisHigh = 0.7f;  // capsule axis along +y (hemispheres beyond)
  int around = 32, rows = 28;            // body tessellation of the cylinder part
  float gap = 0.012f;                    // garment off the body
  float garmentLow = 0.05f, garmentHigh = 0.62f;
  int garmentAround = 40, garmentRows = 24;
  Vec3f offset = Vec3f::Zero();  // the whole character moved (huge-coordinate tests)
};

// Chain Hips (y=0) -> LowerBack (0.25) -> Spine (0.5) -> Neck (0.75); weights blend smoothly across
// each joint over +-6 cm, as an artist's would.
inline void capsuleWeights(float y, uint16_t* joints, float* weights) {
  const float heights[4] = {0.f, 0.25f, 0.5f, 0.75f};
  int seg = 0;
  while (seg < 3 && y > heights[seg + 1]) ++seg;
  auto smooth = [](float t) {
    t = std::clamp(t, 0.f, 1.f);
    return t * t * (3.f - 2.f * t);
  };
  for (int k = 0; k < 4; ++k) joints[k] = 0, weights[k] = 0.f;
  // Blend with the next joint near its height, and with the previous near this one's.
  const float up = seg < 3 ? smooth((y - (heights[seg + 1] - 0.06f)) / 0.12f) : 0.f;
  const float down = seg > 0 ? 1.f - smooth((y - (heights[seg] - 0.06f)) / 0.12f) : 0.f;
  joints[0] = uint16_t(seg);
  weights[0] = 1.f - up - down;
  joints[1] = uint16_t(std::min(seg + 1, 3));
  weights[1] = up;
  joints[2] = uint16_t(std::max(seg - 1, 0));
  weights[2] = down;
  if (weights[0] < 0.f) weights[0] = 0.f;
  const float sum = weights[0] + weights[1] + weights[2];
  for (int k = 0; k < 3; ++k) weights[k] /= sum;
}

inline void setCapsuleSkin(Mesh& m) {
  m.skin.influences = 4;
  m.skin.joints.resize(m.vertexCount() * 4);
  m.skin.weights.resize(m.vertexCount() * 4);
  for (size_t v = 0; v < m.vertexCount(); ++v)
    capsuleWeights(m.positions(Eigen::Index(v), 1), &m.skin.joints[v * 4], &m.skin.weights[v * 4]);
}

inline Skeleton capsuleSkeleton(const Vec3f& offset) {
  Skeleton s;
  s.joints.push_back({"Hips", -1, {Quatf::Identity(), offset}});
  s.joints.push_back({"LowerBack", 0, {Quatf::Identity(), Vec3f(0, 0.25f, 0)}});
  s.joints.push_back({"Spine", 1, {Quatf::Identity(), Vec3f(0, 0.25f, 0)}});
  s.joints.push_back({"Neck", 2, {Quatf::Identity(), Vec3f(0, 0.25f, 0)}});
  s.computeInverseBindFromRest();
  return s;
}

// A closed capsule: cylinder rings plus hemisphere rings and two pole vertices. Outward-facing.
inline Mesh capsuleBody(const CapsuleSpec& c) {
  std::vector<Vec3f> pts;
  std::vector<Eigen::Vector3i> tris;
  const int capRings = 8;
  std::vector<std::pair<float, float>> rings;  // (y, ring radius) from bottom to top
  for (int i = 1; i < capRings; ++i) {
    const float a = float(M_PI) / 2.f * float(capRings - i) / float(capRings);
    rings.push_back({c.axisLow - c.radius * std::sin(a), c.radius * std::cos(a)});
  }
  for (int i = 0; i <= c.rows; ++i)
    rings.push_back({c.axisLow + (c.axisHigh - c.axisLow) * float(i) / float(std::max(c.rows, 1)), c.radius});
  for (int i = 1; i < capRings; ++i) {
    const float a = float(M_PI) / 2.f * float(i) / float(capRings);
    rings.push_back({c.axisHigh + c.radius * std::sin(a), c.radius * std::cos(a)});
  }
  pts.push_back(Vec3f(0, c.axisLow - c.radius, 0));
  for (auto [y, r] : rings)
    for (int k = 0; k < c.around; ++k) {
      const float a = 2.f * float(M_PI) * float(k) / float(c.around);
      pts.push_back(Vec3f(r * std::cos(a), y, -r * std::sin(a)));
    }
  pts.push_back(Vec3f(0, c.axisHigh + c.radius, 0));
  const int n = c.around, nr = int(rings.size()), top = int(pts.size()) - 1;
  auto at = [&](int ring, int k) { return 1 + ring * n + (k % n); };
  for (int k = 0; k < n; ++k) tris.push_back({0, at(0, k + 1), at(0, k)});
  for (int r = 0; r + 1 < nr; ++r)
    for (int k = 0; k < n; ++k) {
      tris.push_back({at(r, k), at(r, k + 1), at(r + 1, k + 1)});
      tris.push_back({at(r, k), at(r + 1, k + 1), at(r + 1, k)});
    }
  for (int k = 0; k < n; ++k) tris.push_back({top, at(nr - 1, k), at(nr - 1, k + 1)});
  Mesh m;
  m.positions.resize(Eigen::Index(pts.size()), 3);
  for (size_t i = 0; i < pts.size(); ++i) m.positions.row(Eigen::Index(i)) = pts[i];
  m.triangles.resize(Eigen::Index(tris.size()), 3);
  for (size_t i = 0; i < tris.size(); ++i) m.triangles.row(Eigen::Index(i)) = tris[i].cast<uint32_t>();
  setCapsuleSkin(m);
  m.positions.rowwise() += c.offset.transpose();
  return m;
}

// An open tube with a UV seam: the first column is repeated (same position, u = 1) as glTF would.
inline Mesh tubeGarment(const CapsuleSpec& c) {
  const int n = c.garmentAround, rows = c.garmentRows;
  const float r = c.radius + c.gap;
  Mesh m;
  m.positions.resize((n + 1) * (rows + 1), 3);
  m.uvs.resize((n + 1) * (rows + 1), 2);
  for (int i = 0; i <= rows; ++i)
    for (int k = 0; k <= n; ++k) {
      const float a = 2.f * float(M_PI) * float(k % n) / float(n);
      const float y = c.garmentLow + (c.garmentHigh - c.garmentLow) * float(i) / float(rows);
      m.positions.row(i * (n + 1) + k) << r * std::cos(a), y, -r * std::sin(a);
      m.uvs.row(i * (n + 1) + k) << float(k) / float(n), float(i) / float(rows);
    }
  m.triangles.resize(2 * n * rows, 3);
  int t = 0;
  for (int i = 0; i < rows; ++i)
    for (int k = 0; k < n; ++k) {
      const uint32_t a = uint32_t(i * (n + 1) + k), b = a + 1, d = a + uint32_t(n + 1), e = d + 1;
      m.triangles.row(t++) << a, b, e;
      m.triangles.row(t++) << a, e, d;
    }
  setCapsuleSkin(m);
  m.positions.rowwise() += c.offset.transpose();
  return m;
}

inline Character capsuleCharacter(const CapsuleSpec& c = {}) {
  Character ch;
  ch.name = "capsule";
  ch.skeleton = capsuleSkeleton(c.offset);
  ch.body = capsuleBody(c);
  ch.garment = tubeGarment(c);
  return ch;
}

// Distance from p to the capsule surface in the rest pose (negative inside).
inline float capsuleSignedDistance(const CapsuleSpec& c, const Vec3f& p) {
  const Vec3f q = p - c.offset;
  const float y = std::clamp(q.y(), c.axisLow, c.axisHigh);
  return (q - Vec3f(0, y, 0)).norm() - c.radius;
}

}  // namespace swish::test
