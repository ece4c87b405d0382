#include "swish/render/body_skinning.hpp"

#include <cmath>

#include "swish/render/preview_renderer.hpp"

namespace swish::render {

std::vector<float> vertexNormals(const std::vector<float>& p, const std::vector<uint32_t>& tris) {
  std::vector<float> n(p.size(), 0.f);
  for (size_t t = 0; t + 2 < tris.size(); t += 3) {
    const float* a = &p[3 * tris[t]];
    const float* b = &p[3 * tris[t + 1]];
    const float* c = &p[3 * tris[t + 2]];
    const float e1[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const float e2[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const float f[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
    for (int k = 0; k < 3; ++k)
      for (int a2 = 0; a2 < 3; ++a2) n[3 * tris[t + k] + a2] += f[a2];  // |f| = twice the area: area weighting
  }
  for (size_t v = 0; v < n.size(); v += 3) {
    const float l = std::sqrt(n[v] * n[v] + n[v + 1] * n[v + 1] + n[v + 2] * n[v + 2]);
    if (l > 0) {
      n[v] /= l, n[v + 1] /= l, n[v + 2] /= l;
    } else {
      n[v] = 0, n[v + 1] = 0, n[v + 2] = 1;  // isolated vertex: any unit vector
    }
  }
  return n;
}

BodySkinner::BodySkinner(const BodyMesh& b)
    : rest_(b.positions),
      restNormals_(b.normals.empty() ? vertexNormals(b.positions, b.triangles) : b.normals),
      weights_(b.weights),
      joints_(b.joints),
      influences_(b.influences) {}

void BodySkinner::skin(const std::vector<api::Mat4>& mats, float* out) const {
  const size_t n = vertexCount();
  float* pos = out;
  float* nrm = out + 3 * n;
  for (size_t v = 0; v < n; ++v) {
    float m[16] = {};
    for (uint32_t k = 0; k < influences_; ++k) {
      const float w = weights_[v * influences_ + k];
      if (w == 0.f) continue;
      const api::Mat4& s = mats[joints_[v * influences_ + k]];
      for (int e = 0; e < 16; ++e) m[e] += w * s[e];
    }
    const float* p = &rest_[3 * v];
    const float* q = &restNormals_[3 * v];
    float r[3], t[3];
    for (int row = 0; row < 3; ++row) {
      r[row] = m[row] * p[0] + m[4 + row] * p[1] + m[8 + row] * p[2] + m[12 + row];
      t[row] = m[row] * q[0] + m[4 + row] * q[1] + m[8 + row] * q[2];  // blended rotations: near-rigid
    }
    const float l = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (int a = 0; a < 3; ++a) {
      pos[3 * v + a] = r[a];
      nrm[3 * v + a] = l > 0 ? t[a] / l : q[a];
    }
  }
}

}  // namespace swish::render
