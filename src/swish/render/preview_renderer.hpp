#pragma once
// The headless preview renderer: a host of swish like any other, built only on the public API
// (include/swish/). Each frame it records swish's passes and its own drawing into one command buffer
// of its own device (HostDevice, adopted by the api::Runtime): the jersey from swish's deformed
// vertex streams, lit and shaded with swish's tangent-space normal map, and the body as a plain
// mannequin skinned on the CPU with the model's skinning matrices; fixed camera, offscreen colour +
// depth, no swapchain. Images come back as RGBA8 (alpha 0 where nothing was drawn).
//
// One frame can be drawn in several variants side by side from the same deformation (normal map on
// and off, say), so that the comparison shows only what the normal map adds.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "swish/api_runtime.hpp"
#include "swish/render/host_device.hpp"
#include "swish/render/preview_camera.hpp"

namespace swish::render {

// A skinned body on the MODEL's skeleton (joint indices in ModelInfo::jointNames order), rest pose.
struct BodyMesh {
  std::vector<float> positions;     // 3 per vertex, character space
  std::vector<float> normals;       // 3 per vertex; empty: computed from the triangles
  std::vector<uint32_t> triangles;  // 3 per triangle
  uint32_t influences = 0;          // per vertex, 1..8
  std::vector<uint16_t> joints;     // vertexCount * influences
  std::vector<float> weights;       // vertexCount * influences
  // Throws api::Error(InvalidArgument) naming the problem (sizes, indices, joints >= jointCount).
  void validate(size_t jointCount) const;
  // Leaves out the triangles the model says its garment covers (api::ModelInfo::coveredBodyTriangles),
  // as games do for skin under tight clothing. Returns how many were left out; throws
  // api::Error(InvalidArgument) when this body is not the one the list refers to (another triangle count).
  size_t hideCovered(const api::ModelInfo& model);
};

struct PreviewOptions {
  uint32_t width = 480, height = 640;   // of one view
  std::optional<BodyMesh> body;         // absent: the jersey alone
  std::optional<PreviewCamera> camera;  // absent: framing the rest-pose body (or the jersey) from the front
  std::array<float, 3> jerseyColor{0.72f, 0.12f, 0.14f};
  std::array<float, 3> bodyColor{0.62f, 0.62f, 0.64f};
  std::array<float, 3> background{0.93f, 0.94f, 0.96f};      // used when flattening to RGB
  std::array<float, 3> lightDirection{0.45f, 0.55f, 0.70f};  // towards the key light
  uint32_t framesInFlight = 2;
  bool pushOut = true;  // api::BatchOptions::pushOut: the garment kept off the body by the model's body anchors
};

struct PreviewImage {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  // row-major from the top
  uint8_t alpha(uint32_t x, uint32_t y) const { return rgba[(size_t(y) * width + x) * 4 + 3]; }
};

struct PreviewVariant {
  bool normalMap = true;
  bool body = true;  // draw the mannequin (when there is one)
};

class PreviewRenderer {
 public:
  // `device` must be the device `runtime` adopted; `model` loaded on that runtime.
  PreviewRenderer(HostDevice& device, api::Runtime runtime, const api::Model& model, PreviewOptions options);
  ~PreviewRenderer();
  PreviewRenderer(const PreviewRenderer&) = delete;
  PreviewRenderer& operator=(const PreviewRenderer&) = delete;

  bool drawsBody() const;
  const PreviewCamera& camera() const;
  api::Mat4 viewProjection() const;  // of one view
  const PreviewOptions& options() const;
  uint64_t framesRendered() const;

  // Advances swish one frame with `pose` and draws it once per variant, left to right, into one
  // image of width * variants.size(). Waits for the GPU.
  PreviewImage render(const api::CharacterPose& pose, const std::vector<PreviewVariant>& variants = {{}});
  // The last rendered frame's jersey as swish produced it (read back), for checks.
  api::DeformedMesh lastJersey() const;
  // The last rendered frame's body as drawn (skinned on the CPU): 3 floats per vertex; empty without a body.
  std::vector<float> lastBody() const;
  // Report of the last frame's swish CPU step (warnings, time).
  const api::FrameReport& lastReport() const;

 private:
  struct State;
  std::unique_ptr<State> s_;
};

// RGBA over the background -> an 8-bit RGB PNG image's samples; writes atomically with io/png.
void writePreviewPng(const std::string& path, const PreviewImage& image, const std::array<float, 3>& background);

}  // namespace swish::render
