#pragma once
// The inputs of one frame of the GPU kernels for a batch of instances of one model, and the CPU
// reference of the whole frame: PCA reconstruction -> skinning -> push-out to the body anchors ->
// normals and tangents per instance;
// VQ decode of each selected map -> temporal blend into each character's normal map. The GPU frame
// (gpu/frame_recorder.hpp) must reproduce every output within the per-kernel tolerances.
#include <cstdint>
#include <vector>

#include "swish/model/model.hpp"
#include "swish/runtime/reference_normal_blend.hpp"

namespace swish::runtime {

// "No map": FrameEvaluator's mapIndex for a model without a normal-map database or a character at a
// quality level without normal maps; in FrameKernelInputs::selectedMaps, an instance that gets no decode
// and no blend this frame (its normal map stays as it was).
inline constexpr uint32_t kNoMap = 0xFFFFFFFFu;

struct FrameKernelInputs {
  uint32_t instanceCount = 0;
  std::vector<float> meshWeights;   // instanceCount x K, instance-major (the MLP's mesh weights)
  std::vector<Mat4f> skinMatrices;  // instanceCount x jointCount (Skeleton::skinningMatrices per instance)
  // instanceCount database maps (kNoMap: that instance's map stays as it was), or empty: no normal-map
  // work this frame
  std::vector<uint32_t> selectedMaps;
  std::vector<float> blendAlpha;  // instanceCount weights of the new map (the temporal filter's alpha)
  // Per instance: the leading mesh components its deform reads (its quality level's k, 0..K; the weights
  // beyond it count as 0 whatever meshWeights holds). Empty: K for every instance.
  std::vector<uint32_t> meshComponents;
  // Push the skinned garment out to the model's body anchors (reference_push_out.hpp); no effect for
  // a model without them.
  bool pushOut = true;

  // Throws Error naming the problem if sizes or map indices do not fit `model`.
  void validate(const Model& model) const;
};

struct ReferenceFrameOutputs {
  std::vector<Points3f> positions;  // per instance, skinned
  std::vector<Points3f> normals;    // per instance
  std::vector<Points4f> tangents;   // per instance
  // per instance (empty when selectedMaps is): an instance with kNoMap keeps its previous map
  std::vector<BlendedNormalMap> normalMaps;
};

// The skinned positions of one instance alone (PCA of its meshComponents -> skinning -> push-out when
// `pushOut` and the model has body anchors): what referenceFrame's positions are, without the rest of the frame.
Points3f referencePositions(const Model& model, const FrameKernelInputs& inputs, uint32_t instance, bool pushOut);

// prevMaps: each character's normal map after the previous frame (empty: all zeros, as the GPU images
// start); an instance whose selectedMaps entry is kNoMap gets it back unchanged.
ReferenceFrameOutputs referenceFrame(const Model& model, const FrameKernelInputs& inputs,
                                     const std::vector<BlendedNormalMap>& prevMaps = {});

}  // namespace swish::runtime
