#include "swish/render/preview_camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace swish::render {

namespace {
Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
float dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 normalize(const Vec3& a) {
  const float l = std::sqrt(dot(a, a));
  return {a[0] / l, a[1] / l, a[2] / l};
}
// c = a * b, column-major.
api::Mat4 mul(const api::Mat4& a, const api::Mat4& b) {
  api::Mat4 c{};
  for (int col = 0; col < 4; ++col)
    for (int row = 0; row < 4; ++row) {
      float s = 0;
      for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[col * 4 + k];
      c[col * 4 + row] = s;
    }
  return c;
}
}  // namespace

api::Mat4 viewProjection(const PreviewCamera& c, float aspect) {
  const Vec3 f = normalize(sub(c.target, c.eye));
  const Vec3 s = normalize(cross(f, c.up));
  const Vec3 u = cross(s, f);
  // Right-handed view: camera looks down -Z.
  const api::Mat4 view = {s[0], u[0], -f[0], 0, s[1],           u[1],           -f[1],         0,
                          s[2], u[2], -f[2], 0, -dot(s, c.eye), -dot(u, c.eye), dot(f, c.eye), 1};
  const float t = 1.f / std::tan(c.verticalFovDegrees * 3.14159265f / 360.f);
  const float n = c.nearPlane, fa = c.farPlane;
  // Vulkan: y flipped (framebuffer y down), depth 0 at near, 1 at far.
  const api::Mat4 proj = {t / aspect, 0, 0, 0, 0, -t, 0, 0, 0, 0, fa / (n - fa), -1, 0, 0, n * fa / (n - fa), 0};
  return mul(proj, view);
}

void boundsOf(std::span<const float> xyz, Vec3& lo, Vec3& hi) {
  const float inf = std::numeric_limits<float>::infinity();
  lo = {inf, inf, inf};
  hi = {-inf, -inf, -inf};
  for (size_t i = 0; i + 2 < xyz.size(); i += 3)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], xyz[i + a]);
      hi[a] = std::max(hi[a], xyz[i + a]);
    }
}

PreviewCamera frameBox(const Vec3& lo, const Vec3& hi, float aspect, float margin) {
  PreviewCamera c;
  const Vec3 centre = {(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2};
  const float h = (hi[1] - lo[1]) * (1 + 2 * margin);
  const float w = (hi[0] - lo[0]) * (1 + 2 * margin);
  const float halfFov = c.verticalFovDegrees * 3.14159265f / 360.f;
  // Distance at which both the height and the width fit, measured to the front of the box.
  const float dist = std::max(h / 2, w / (2 * aspect)) / std::tan(halfFov) + (hi[2] - lo[2]) / 2;
  const float lift = 0.12f * h;  // a little from above, as a person looks at a mannequin
  c.target = centre;
  c.eye = {centre[0], centre[1] + lift, centre[2] + dist};
  c.nearPlane = std::max(0.01f, dist * 0.05f);
  c.farPlane = dist * 4 + (hi[2] - lo[2]);
  return c;
}

std::array<float, 3> projectToPixel(const api::Mat4& m, const Vec3& p, uint32_t width, uint32_t height) {
  float clip[4];
  for (int r = 0; r < 4; ++r) clip[r] = m[0 * 4 + r] * p[0] + m[1 * 4 + r] * p[1] + m[2 * 4 + r] * p[2] + m[3 * 4 + r];
  const float x = clip[0] / clip[3], y = clip[1] / clip[3];
  return {(x * 0.5f + 0.5f) * float(width), (y * 0.5f + 0.5f) * float(height), clip[3]};
}

}  // namespace swish::render
