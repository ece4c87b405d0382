#pragma once
// The GPU resources of one Model: everything the passes read that does not change per frame (PCA mean
// and basis, skin influences, triangles, UVs, the frame-topology adjacency, the VQ codebook and
// indices), uploaded once into device-local buffers. Shared by every instance batch of the model.
//
// Upload checks structure (sizes, and every index the kernels follow: skin joints, triangle corners,
// VQ indices are clamped by the kernel), not values: non-finite data goes through, so that NaN/Inf
// propagation can be tested; Model::validate is the place that rejects it for real models.
#include <cstdint>
#include <string>

#include "swish/gpu/buffer.hpp"
#include "swish/gpu/deform_pass.hpp"
#include "swish/model/model.hpp"

namespace swish::gpu {

class Context;

class GpuModel {
 public:
  GpuModel() = default;
  GpuModel(Context& ctx, const Model& model, const std::string& name = "model");

  const std::string& name() const { return name_; }
  uint32_t vertexCount() const { return vertexCount_; }
  uint32_t triangleCount() const { return triangleCount_; }
  uint32_t jointCount() const { return jointCount_; }
  uint32_t meshComponents() const { return meshComponents_; }          // K of the model (may be 0)
  uint32_t kernelMeshComponents() const { return kernelComponents_; }  // max(K, 1): a zero column pads K = 0
  uint32_t influences() const { return influences_; }
  bool hasUvs() const { return hasUvs_; }
  bool hasNormalMaps() const { return mapCount_ > 0; }
  uint32_t mapCount() const { return mapCount_; }
  uint32_t mapWidth() const { return mapWidth_; }
  uint32_t mapHeight() const { return mapHeight_; }
  uint32_t codebookSize() const { return codebookSize_; }
  // The push-out's body anchors (`anchors`, DeformPass::packAnchors' layout).
  bool hasBodyAnchors() const { return anchorSlots_ > 0; }
  uint32_t anchorSlots() const { return anchorSlots_; }              // BodyAnchors::slots()
  uint32_t anchorExtraJoints() const { return anchorExtraJoints_; }  // DeformPass::anchorExtraJointsOf
  bool anchorZeroSkip() const { return anchorZeroSkip_; }            // DeformPass::anchorsSkipZeroWeights

  // The deform's arguments for `instances` instances of this model: its buffers, counts and the given
  // per-frame inputs and output. No push-out and no quality bands (the caller adds those).
  DeformPass::Args deformArgs(VkDescriptorSet instanceInputs, const Buffer& positionsOut, uint32_t instances) const;
  // The deform pass this model runs with (as FrameRecorder makes it): its K and influences, skinning on, the
  // basis and anchors as texels where the device allows, its anchor sets and push-out table (anchorExtraJoints).
  DeformPass makeDeformPass(Context& ctx) const;

  Buffer mean, basis, skinJoints, skinWeights;
  Buffer uvs, triangles, normalOffsets, normalTriangles, tangentOffsets, tangentTriangles;
  Buffer frameTriangles;  // TangentFramesPass::frameTriangles: the two-pass gather's one walk of both adjacencies
  Buffer codebook, indices;
  Buffer anchors;  // DeformPass::packAnchors' words; empty without body anchors

 private:
  std::string name_;
  uint32_t anchorSlots_ = 0, anchorExtraJoints_ = 0;
  bool anchorZeroSkip_ = true;  // DeformPass::anchorsSkipZeroWeights
  uint32_t vertexCount_ = 0, triangleCount_ = 0, jointCount_ = 0, meshComponents_ = 0, kernelComponents_ = 1;
  uint32_t influences_ = 1;
  bool hasUvs_ = false;
  uint32_t mapCount_ = 0, mapWidth_ = 0, mapHeight_ = 0, codebookSize_ = 0;
};

}  // namespace swish::gpu
