#pragma once
// The preview's fixed camera: a perspective view from in front of the character (+Z, which the
// character faces), slightly above, looking at the middle of what is drawn. Vulkan clip conventions:
// y down in framebuffer space, depth 0..1.
#include <array>
#include <span>

#include "swish/api_types.hpp"

namespace swish::render {

using Vec3 = std::array<float, 3>;

struct PreviewCamera {
  Vec3 eye{0, 1, 4};
  Vec3 target{0, 1, 0};
  Vec3 up{0, 1, 0};
  float verticalFovDegrees = 30.f;
  float nearPlane = 0.05f, farPlane = 100.f;
};

// world -> clip for an image of the given aspect (width / height).
api::Mat4 viewProjection(const PreviewCamera& camera, float aspect);

// A camera framing the axis-aligned box [lo, hi] (world space) from the front, with `margin` of the
// box's size around it, for an image of the given aspect.
PreviewCamera frameBox(const Vec3& lo, const Vec3& hi, float aspect, float margin = 0.08f);

// Bounds of xyz triples.
void boundsOf(std::span<const float> xyz, Vec3& lo, Vec3& hi);

// Pixel coordinates (x right, y down, pixel centres at +0.5) of a world point, and its clip w.
std::array<float, 3> projectToPixel(const api::Mat4& viewProj, const Vec3& p, uint32_t width, uint32_t height);

}  // namespace swish::render
