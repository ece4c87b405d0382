#include "swish/gpu/tangent_frames_pass.hpp"

#include "shaders/swish_layouts.h"
#include "shaders/swish_triangle_frames_layout.h"
#include "swish/core/error.hpp"
#include "swish/gpu/buffer.hpp"
#include "swish/gpu/context.hpp"

namespace swish::gpu {

VkDeviceSize TangentFramesPass::triangleTermsBytes(uint32_t triangles, uint32_t instances) {
  return VkDeviceSize(triangles) * instances * SWISH_TRIANGLE_TERM_VEC4S * 16;
}

TangentFramesPass::TangentFramesPass(Context& ctx)
    : pipeline_(ctx, "tangent_frames.comp", {kWorkgroupSize}, sizeof(layout::TangentFramesParams)),
      trianglePipeline_(ctx, "triangle_frames.comp", {kWorkgroupSize}, sizeof(layout::TriangleFramesParams)),
      gatherPipeline_(ctx, "vertex_frames_gather.comp", {kWorkgroupSize}, sizeof(layout::VertexFramesGatherParams)) {}

void TangentFramesPass::record(VkCommandBuffer cmd, const Args& a) const {
  if (a.vertexCount == 0 || a.instanceCount == 0) return;
  if (a.triangleTerms != 0 && a.triangleCount > 0) {
    if (a.triangleTerms % 16 != 0) throw Error("tangent frames pass: the triangle-terms buffer is not 16-byte aligned");
    layout::TriangleFramesParams tp;
    tp.positions = layout::Address::of(a.positions);
    tp.uvs = layout::Address::of(a.uvs);
    tp.triangles = layout::Address::of(a.triangles);
    tp.termsOut = layout::Address::of(a.triangleTerms);
    tp.vertexCount = a.vertexCount;
    tp.triangleCount = a.triangleCount;
    tp.instanceCount = a.instanceCount;
    tp.hasUvs = a.hasUvs ? 1u : 0u;
    trianglePipeline_.bind(cmd, &tp, sizeof(tp));
    vkCmdDispatch(cmd, groupCount(a.triangleCount, kWorkgroupSize), 1, 1);
    computeToComputeBarrier(cmd);  // triangle terms written -> read by the gather
    layout::VertexFramesGatherParams gp;
    gp.terms = layout::Address::of(a.triangleTerms);
    gp.normalOffsets = layout::Address::of(a.normalOffsets);
    gp.normalTriangles = layout::Address::of(a.normalTriangles);
    gp.tangentOffsets = layout::Address::of(a.tangentOffsets);
    gp.tangentTriangles = layout::Address::of(a.tangentTriangles);
    gp.normalsOut = layout::Address::of(a.normalsOut);
    gp.tangentsOut = layout::Address::of(a.tangentsOut);
    gp.vertexCount = a.vertexCount;
    gp.triangleCount = a.triangleCount;
    gp.instanceCount = a.instanceCount;
    gp.hasUvs = a.hasUvs ? 1u : 0u;
    gatherPipeline_.bind(cmd, &gp, sizeof(gp));
    vkCmdDispatch(cmd, groupCount(a.vertexCount, kWorkgroupSize), a.instanceCount, 1);
    return;
  }
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
