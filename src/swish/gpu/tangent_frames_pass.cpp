#include "swish/gpu/tangent_frames_pass.hpp"

#include "shaders/swish_layouts.h"
#include "shaders/swish_triangle_frames_layout.h"
#include "swish/core/error.hpp"
#include "swish/gpu/buffer.hpp"
#include "swish/gpu/context.hpp"

namespace swish::gpu {

VkDeviceSize TangentFramesPass::triangleTermsBytes(uint32_t triangles, uint32_t instances) {
  return VkDeviceSize(SWISH_TERMS_INSTANCE_FLOATS(VkDeviceSize(triangles))) * 4 * instances;
}

static_assert(TangentFramesPass::kNotOwnTriangle == SWISH_NOT_OWN_TRIANGLE);

std::vector<uint32_t> TangentFramesPass::frameTriangles(const MeshFrameTopology& topo) {
  const VertexTriangleAdjacency &welded = topo.normalAdjacency, &own = topo.tangentAdjacency;
  if (welded.offsets.size() != own.offsets.size())
    throw Error("tangent frames: the welded and own adjacency have different vertex counts");
  std::vector<uint32_t> out(welded.triangles);
  for (size_t v = 0; v + 1 < welded.offsets.size(); ++v) {
    uint32_t j = own.offsets[v];
    for (uint32_t i = welded.offsets[v]; i < welded.offsets[v + 1]; ++i) {
      if (out[i] & SWISH_NOT_OWN_TRIANGLE)
        throw Error("tangent frames: triangle index " + std::to_string(out[i]) + " too large");
      if (j < own.offsets[v + 1] && own.triangles[j] == out[i])
        ++j;
      else
        out[i] |= SWISH_NOT_OWN_TRIANGLE;
    }
    if (j != own.offsets[v + 1])
      throw Error("tangent frames: vertex " + std::to_string(v) +
                  "'s own triangles are not a subsequence of its welded ones");
  }
  return out;
}

namespace {
std::vector<VkDescriptorType> twoPassTypes() {
  std::vector<VkDescriptorType> t(SWISH_TF_BINDING_COUNT, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER);
  t[SWISH_TF_BINDING_TERMS_OUT] = t[SWISH_TF_BINDING_NORMALS_OUT] = t[SWISH_TF_BINDING_TANGENTS_OUT] =
      VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
  return t;
}
}  // namespace

TangentFramesPass::TangentFramesPass(Context& ctx, bool store64)
    : store64_(store64 && ctx.hasShaderInt64()),
      twoPassLayout_(ctx, twoPassTypes()),
      pipeline_(ctx, "tangent_frames.comp", {kWorkgroupSize}, sizeof(layout::TangentFramesParams)),
      trianglePipeline_(ctx, store64_ ? "triangle_frames_store64.comp" : "triangle_frames.comp", {kWorkgroupSize},
                        sizeof(layout::TriangleFramesParams), twoPassLayout_.get()),
      gatherPipeline_(ctx, store64_ ? "vertex_frames_gather_store64.comp" : "vertex_frames_gather.comp",
                      {kWorkgroupSize}, sizeof(layout::VertexFramesGatherParams), twoPassLayout_.get()) {}

DescriptorBinding TangentFramesPass::bindTwoPass(Context& ctx, const TwoPassBuffers& b) const {
  for (const Buffer* p : {b.positions, b.triangleTerms, b.normalOffsets, b.frameTriangles, b.normalsOut, b.tangentsOut})
    if (!p) throw Error("tangent frames pass: a buffer of the two-pass binding is missing");
  std::vector<BoundResource> r(SWISH_TF_BINDING_COUNT);
  r[SWISH_TF_BINDING_POSITIONS] = BoundResource::texels(*b.positions, VK_FORMAT_R32_SFLOAT);
  r[SWISH_TF_BINDING_TERMS_OUT] = BoundResource::storage(*b.triangleTerms);
  r[SWISH_TF_BINDING_TERMS] = BoundResource::texels(*b.triangleTerms, VK_FORMAT_R32G32B32A32_SFLOAT);
  r[SWISH_TF_BINDING_TERMS_Z] = BoundResource::texels(*b.triangleTerms, VK_FORMAT_R32_SFLOAT);
  r[SWISH_TF_BINDING_NORMAL_OFFSETS] = BoundResource::texels(*b.normalOffsets, VK_FORMAT_R32_UINT);
  r[SWISH_TF_BINDING_FRAME_TRIANGLES] = BoundResource::texels(*b.frameTriangles, VK_FORMAT_R32_UINT);
  r[SWISH_TF_BINDING_NORMALS_OUT] = BoundResource::storage(*b.normalsOut);
  r[SWISH_TF_BINDING_TANGENTS_OUT] = BoundResource::storage(*b.tangentsOut);
  return DescriptorBinding(ctx, twoPassLayout_, r);
}

uint32_t TangentFramesPass::record(VkCommandBuffer cmd, const Args& a) const {
  if (a.vertexCount == 0 || a.instanceCount == 0) return 0;
  if (a.twoPass != VK_NULL_HANDLE) {
    if (a.triangleCount > 0) {
      layout::TriangleFramesParams tp;
      tp.uvs = layout::Address::of(a.uvs);
      tp.triangles = layout::Address::of(a.triangles);
      tp.vertexCount = a.vertexCount;
      tp.triangleCount = a.triangleCount;
      tp.instanceCount = a.instanceCount;
      tp.hasUvs = a.hasUvs ? 1u : 0u;
      trianglePipeline_.bind(cmd, &tp, sizeof(tp), a.twoPass);
      vkCmdDispatch(cmd, groupCount(a.triangleCount, kWorkgroupSize), 1, 1);
      computeToComputeBarrier(cmd);  // triangle terms written -> read by the gather
    }
    layout::VertexFramesGatherParams gp;
    gp.vertexCount = a.vertexCount;
    gp.triangleCount = a.triangleCount;
    gp.instanceCount = a.instanceCount;
    gp.hasUvs = a.hasUvs ? 1u : 0u;
    gatherPipeline_.bind(cmd, &gp, sizeof(gp), a.twoPass);
    vkCmdDispatch(cmd, groupCount(a.vertexCount, kWorkgroupSize), a.instanceCount, 1);
    return a.triangleCount > 0 ? 2 : 1;
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
  return 1;
}

}  // namespace swish::gpu
