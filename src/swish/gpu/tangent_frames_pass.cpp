#include "swish/gpu/tangent_frames_pass.hpp"

#include "shaders/swish_layouts.h"
#include "swish/core/error.hpp"
#include "swish/gpu/context.hpp"

namespace swish::gpu {

TangentFramesPass::TangentFramesPass(Context& ctx)
    : pipeline_(ctx, "tangent_frames.comp", {kWorkgroupSize}, sizeof(layout::TangentFramesParams)) {}

void TangentFramesPass::record(VkCommandBuffer cmd, const Args& a) const {
  if (a.vertexCount == 0 || a.instanceCount == 0) return;
  layout::TangentFramesParams p;
  p.positions = layout::Address::of(a.positions);
  p.uvs = layout::Address::of(a.uvs);
  p.triangles = layout::Address::of(a.triangles);
  p.normalOffsets = layout::Address::of(a.normalOffsets);
  p.normalTriangles = layout::Address::of(a.normalTriangles);
  p.tangentOffsets = layout::Address::of(a.tangentOffsets);
  p.tangentTriangles = layout::Address::of(a.tangentTriangles);
  p.normalsOut = layout::Address::of(a.normalsOut);
  p.tangentsOut = layout::Address::of(a.tangentsOut);
  p.vertexCount = a.vertexCount;
  p.instanceCount = a.instanceCount;
  p.hasUvs = a.hasUvs ? 1u : 0u;
  p.pad0 = 0;
  pipeline_.bind(cmd, &p, sizeof(p));
  vkCmdDispatch(cmd, groupCount(a.vertexCount, kWorkgroupSize), a.instanceCount, 1);
}

}  // namespace swish::gpu
