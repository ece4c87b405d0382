#include "swish/gpu/deform_pass.hpp"

#include "shaders/swish_layouts.h"
#include "swish/core/error.hpp"
#include "swish/core/mesh.hpp"

namespace swish::gpu {

DeformPass::DeformPass(Context& ctx, uint32_t k, uint32_t influences, bool applySkinning) {
  if (k < 1 || k > SWISH_MAX_MESH_COMPONENTS)
    throw Error("deform pass: " + std::to_string(k) + " mesh components; the kernel supports 1.." +
                std::to_string(SWISH_MAX_MESH_COMPONENTS));
  if (influences < 1 || influences > uint32_t(kMaxInfluences))
    throw Error("deform pass: " + std::to_string(influences) + " skin influences; supported: 1..8");
  pipeline_ = ComputePipeline(ctx, "deform.comp", {kWorkgroupSize, k, influences, applySkinning ? 1u : 0u},
                              sizeof(layout::DeformParams));
}

void DeformPass::record(VkCommandBuffer cmd, const Args& a) const {
  if (a.vertexCount == 0 || a.instanceCount == 0) return;
  layout::DeformParams p;
  p.mean = layout::Address::of(a.mean);
  p.basis = layout::Address::of(a.basis);
  p.weights = layout::Address::of(a.weights);
  p.skinMatrices = layout::Address::of(a.skinMatrices);
  p.skinJoints = layout::Address::of(a.skinJoints);
  p.skinWeights = layout::Address::of(a.skinWeights);
  p.positionsOut = layout::Address::of(a.positionsOut);
  p.vertexCount = a.vertexCount;
  p.instanceCount = a.instanceCount;
  p.jointCount = a.jointCount;
  p.pad0 = 0;
  pipeline_.bind(cmd, &p, sizeof(p));
  vkCmdDispatch(cmd, groupCount(a.vertexCount, kWorkgroupSize), 1, 1);
}

}  // namespace swish::gpu
