#pragma once
// The deform pass (shaders/deform.comp): PCA reconstruction + linear blend skinning (+ the push-out of
// the body anchors' balls, runtime/reference_push_out.hpp) of every instance of one model in ONE dispatch; each
// vertex's basis values are read once per frame for all instances. The per-instance inputs (mesh weights, skin matrix
// rows) are bound as texel buffers through a descriptor set made once per pair of buffers by bindInstanceInputs
// (descriptor_binding.hpp says why), and with them the model's basis as R32 texels where it fits in the device's
// maxTexelBufferElements (shaders/deform_basis_texels.comp; else shaders/deform.comp reads it through its address).
// Quality levels (per-instance k, runtime/quality_levels.hpp) in the same one dispatch: two pipelines of
// the same shader, one without bands (every instance at K: the pass as it was) and one with bandsOf(K);
// record() takes the second where Args::instanceOrder is given (packLevels, packWeights with components).
//
// Records one dispatch into the caller's command buffer (never submits). Synchronisation the caller
// provides: inputs written by the host before the submission (mapped memory; the submission makes them
// visible) or by earlier GPU work followed by a barrier to COMPUTE_SHADER/SHADER_READ; after it, a
// barrier COMPUTE_SHADER/SHADER_WRITE -> the consumer's stage and access (computeToComputeBarrier for
// the tangent-frames pass, VERTEX_INPUT/VERTEX_ATTRIBUTE_READ for a renderer).
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "swish/core/types.hpp"
#include "swish/gpu/compute_pipeline.hpp"
#include "swish/gpu/descriptor_binding.hpp"
#include "swish/model/model.hpp"

namespace swish::gpu {

class DeformPass {
 public:
  static constexpr uint32_t kWorkgroupSize = 256;

  struct Args {
    VkDeviceAddress mean = 0;          // float[3N]
    VkDeviceAddress basis = 0;         // float[K][3N] (read here unless basisTexels())
    VkDeviceAddress skinJoints = 0;    // uint[N][influences]
    VkDeviceAddress skinWeights = 0;   // float[N][influences]
    VkDeviceAddress positionsOut = 0;  // float[instances][N][3]
    // The push-out: packAnchors' words (the model's, GpuModel::anchors); 0: no push-out. Only with skinning applied
    // (the anchors are skinned like the vertices). anchorSlots: the anchor sets in it (1 to 3: BodyAnchors::slots()).
    VkDeviceAddress anchors = 0;
    uint32_t anchorSlots = 1;
    VkDescriptorSet instanceInputs = VK_NULL_HANDLE;  // from bindInstanceInputs
    uint32_t vertexCount = 0;
    uint32_t instanceCount = 0;
    uint32_t jointCount = 0;
    // Per-instance quality levels (packLevels): the instances band by band, uint[instanceCount], with
    // bandEnd and maxGroups from the same Levels; each instance's weight row zero from its k_i on
    // (packWeights with components). 0: every instance reads all groupsOf(K), in order (the pipeline
    // without bands).
    VkDeviceAddress instanceOrder = 0;
    std::array<uint32_t, 4> bandEnd{};  // Levels::bandEnd (with instanceOrder)
    uint32_t maxGroups = 0;             // Levels::maxGroups (with instanceOrder)
  };

  // Layout of the mesh-weights buffer: float[instances][paddedComponents(K)], each row zero padded.
  static uint32_t paddedComponents(uint32_t k) { return (k + 3) / 4 * 4; }
  static VkDeviceSize weightsBytes(uint32_t instances, uint32_t k) {
    return VkDeviceSize(instances) * paddedComponents(k) * 4;
  }
  // Writes `instances` rows of K weights (row-major, as FrameKernelInputs holds them) in that layout.
  static void packWeights(const float* weights, uint32_t instances, uint32_t k, float* out);
  // The same for instances at quality levels: row i keeps its first components[i] weights (<= k) and
  // zeros the rest of its padded row, whatever `weights` holds there, so that the groups the kernel
  // reads whole add exact zeros beyond k_i. components empty: k for every instance. Throws Error naming
  // the instance on a size mismatch or a component count above k.
  static void packWeights(const float* weights, uint32_t instances, uint32_t k, std::span<const uint32_t> components,
                          float* out);
  // Weight groups (vec4 texels) `components` leading components fill.
  static uint32_t groupsOf(uint32_t components) { return (components + 3) / 4; }

  // Quality levels come as bands of weight groups the kernel has an unrolled loop for (deform.glsl says
  // why): groupsOf(K), then ceil of 1/2, 1/4 and 1/8 of it, then 0, the distinct ones, descending (at
  // most kMaxBands). An instance of k components reads the narrowest band of at least groupsOf(k).
  static constexpr uint32_t kMaxBands = 5;
  static std::vector<uint32_t> bandsOf(uint32_t k);
  struct Levels {
    std::vector<uint32_t> order;        // the instances band by band, stable (Args::instanceOrder's contents)
    std::array<uint32_t, 4> bandEnd{};  // end of bands 0..3 in `order` (bands beyond bandsOf(K): instanceCount)
    uint32_t maxGroups = 0;             // groups of the widest band in use (0: every instance at k = 0)
    std::vector<uint32_t> groups;       // per instance (in instance order): the groups it reads, its band's
  };
  // The bands of `components` (one per instance, each <= k, else Error naming the instance).
  static Levels packLevels(std::span<const uint32_t> components, uint32_t k);
  // Layout of the instance-order buffer: uint[instances].
  static VkDeviceSize orderBytes(uint32_t instances) { return VkDeviceSize(instances) * 4; }
  // Layout of the skin-matrices buffer: vec4[instances][jointCount][3], the top three rows of each
  // affine skinning matrix (3 texel fetches per influence instead of 4 columns).
  static VkDeviceSize skinMatricesBytes(uint32_t instances, uint32_t joints) {
    return VkDeviceSize(instances) * joints * 48;
  }
  // Writes `count` matrices (instance-major, as FrameKernelInputs holds them) in that layout.
  static void packSkinMatrices(const Mat4f* matrices, size_t count, float* out);
  // The push-out's joint table of a vertex: its skin joints (`skin.influences` slots, whatever their
  // weights: the skinning fetches their matrices anyway), then the joints its anchors (every set's, in
  // set order and then rank order) weigh that are not among them. The anchors' weights are placed on
  // the table's slots, so the kernel fetches each matrix once per instance (deform.glsl). Extra joints
  // the worst vertex needs (0 without anchors; at most SWISH_MAX_ANCHOR_EXTRA_JOINTS): the pass's
  // anchorExtraJoints.
  static uint32_t anchorExtraJointsOf(const BodyAnchors& anchors, const SkinWeights& skin);
  // Whether the anchors' blends must skip zero weights as the reference does (true), or may add them
  // unguarded (false: a third of their work on lavapipe), for anchors of `extraJoints`
  // (anchorExtraJointsOf) on `skin`. False where no vertex needs extra joints and every skin weight is
  // non-zero: a table slot's non-finite matrix then already makes the skinned vertex non-finite, which no
  // push moves (deform.glsl).
  static bool anchorsSkipZeroWeights(uint32_t extraJoints, const SkinWeights& skin);
  // The body anchors in the push-out's layout (shaders/swish_layouts.h): per vertex its table's
  // anchorExtraJointsOf extra joints (0 where a vertex needs fewer), then per set (BodyAnchors::slots()) and
  // vertex the ball's centre xyz (BodyAnchor::centre()) and reach (BodyAnchor::reach()), and the
  // anchor's weights over the table's slots. Throws Error naming the vertex for an anchor joint >=
  // jointCount, or for anchors and skin of different vertex counts.
  static std::vector<uint32_t> packAnchors(const BodyAnchors& anchors, const SkinWeights& skin, uint32_t jointCount);
  // The texels (uvec4) of that layout for `vertices` vertices of `influences` skin influences, `extraJoints`
  // table joints beyond them and `sets` anchor sets.
  static uint64_t anchorTexelsOf(uint64_t vertices, uint32_t influences, uint32_t extraJoints, uint32_t sets) {
    return vertices * ((extraJoints + 3) / 4 + uint64_t(sets) * (1 + (influences + extraJoints + 3) / 4));
  }

  DeformPass() = default;
  // meshComponents (K) in 1..SWISH_MAX_MESH_COMPONENTS; influences in 1..8. applySkinning = false writes
  // the pre-skinning shape (used to check the PCA reconstruction on its own). basisFloats: 3N x K. The
  // model's streams, the basis and the body anchors, are read as texels (deform_basis_texels.comp) when
  // basisFloats is > 0 and both fit in the device's maxTexelBufferElements (the anchors as
  // anchorTexelsOf); else through Args::basis and Args::anchors (deform.comp). anchorSets (0 to
  // kMaxAnchorSlots): the most body anchor sets a frame pushes out of (the model's BodyAnchors::slots()).
  // The push-out's code is in the pipelines made for it only: a frame without it (Args::anchors 0) runs
  // the kernel without it, which lavapipe would otherwise run masked (deform.glsl).
  // anchorExtraJoints (0 to SWISH_MAX_ANCHOR_EXTRA_JOINTS, 0 without anchor sets): the push-out table's
  // joints beyond the skin's (anchorExtraJointsOf the model's anchors, which packAnchors laid out for it).
  // anchorZeroSkip: anchorsSkipZeroWeights of the model (false only where it says so; true is always right).
  DeformPass(Context& ctx, uint32_t meshComponents, uint32_t influences, bool applySkinning = true,
             uint64_t basisFloats = 0, uint32_t anchorSets = 0, uint32_t anchorExtraJoints = 0,
             bool anchorZeroSkip = true);
  bool basisTexels() const { return basisTexels_; }
  uint32_t meshComponents() const { return meshComponents_; }        // K of the pipeline
  uint32_t anchorSets() const { return anchorSets_; }                // the most anchor sets a frame may apply
  uint32_t anchorExtraJoints() const { return anchorExtraJoints_; }  // push-out table joints beyond the skin's
  const std::vector<uint32_t>& bands() const { return bands_; }      // bandsOf(K)

  // The descriptor set of the per-instance inputs (both offsets 16-byte aligned, at least one instance)
  // and, where basisTexels(), of the model's basis (float[K][3N], required then, ignored otherwise) and
  // body anchors (packAnchors' words, the buffer Args::anchors points into; null or empty for a model
  // without them: no push-out then). Without basisTexels() the anchors are read through Args::anchors.
  DescriptorBinding bindInstanceInputs(Context& ctx, const Buffer& weights, const Buffer& skinMatrices,
                                       const Buffer* basis, const Buffer* anchors, VkDeviceSize weightsOffset = 0,
                                       VkDeviceSize matricesOffset = 0) const;
  // Returns the dispatches recorded (1; 0 for an empty input).
  uint32_t record(VkCommandBuffer cmd, const Args& args) const;

 private:
  bool basisTexels_ = false;
  uint32_t meshComponents_ = 0;
  uint32_t anchorSets_ = 0, anchorExtraJoints_ = 0;
  std::vector<uint32_t> bands_;  // bandsOf(K)
  DescriptorLayout inputsLayout_;
  // [0]: without the push-out; [1]: with anchorSets_ sets (made where anchorSets_ > 0).
  std::array<ComputePipeline, 2> pipeline_;        // one band: every instance at K (Args::instanceOrder 0)
  std::array<ComputePipeline, 2> bandedPipeline_;  // bands_
};

}  // namespace swish::gpu
