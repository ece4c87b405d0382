#pragma once
// Records one frame of swish's GPU work for a batch of instances of one model into a command buffer
// the caller owns (the caller submits; nothing here submits frame work):
//   deform + push-out (all instances, one dispatch) -> barrier -> tangent frames (two dispatches: triangles, vertices)
//   VQ decode (each newly selected map once, one dispatch) -> barrier -> normal-map blend (one dispatch,
//   into the normal-map images' own memory where they share it, else then a copy into them)
// with GPU timestamps around each pass. Resources exist per frame in flight (FrameResources); frame f
// uses slot f % framesInFlight and its blend reads the previous slot's blended maps
// (FrameResources::blendOutput()).
//
// Quality levels (runtime/quality_levels.hpp), per instance in the same dispatches:
// FrameKernelInputs::meshComponents puts each instance in the deform's band of weight groups that
// holds its k (DeformPass::packLevels; the kernel without bands where all are at K). An instance whose
// selectedMaps entry is kNoMap is left out of the decode and the blend, and its layer keeps its map:
// unchanged with one frame in flight, else copied from the previous frame's slot (only when this
// slot's layer is older: a character that stays without maps costs nothing after framesInFlight - 1
// frames). A frame where no instance has a map records no decode and no blend dispatch.
//
// Caller contract: before record(f), wait for the fence of the submission that used slot
// f % framesInFlight last (frame f - framesInFlight); submit frames in order on one queue. After
// the frame's submission, a renderer consuming the outputs needs a barrier from
// COMPUTE_SHADER/SHADER_WRITE to its stage (vertex input for the buffers, fragment shader reads for
// the normal maps).
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "swish/gpu/deform_pass.hpp"
#include "swish/gpu/frame_resources.hpp"
#include "swish/gpu/normal_map_blend_pass.hpp"
#include "swish/gpu/tangent_frames_pass.hpp"
#include "swish/gpu/vq_decode_pass.hpp"
#include "swish/runtime/reference_frame.hpp"

namespace swish::gpu {

class Context;
class GpuModel;

struct FrameRecorderOptions {
  uint32_t framesInFlight = 2;
  bool tangentFrames = true;  // normals + tangents pass
  bool normalMaps = true;     // VQ decode + blend (ignored for a model without a database)
  // Lay the normal-map images over the blend's output where the device allows it (NormalMapImages::
  // sharesTexels): no copy per frame. false: always the copy (tests compare the two).
  bool shareNormalMapTexels = true;
};

// GPU time of each pass of one frame, in milliseconds (NaN: not run, or no timestamps on the device).
struct StageTimes {
  double deformMs, tangentFramesMs, vqDecodeMs, normalBlendMs, totalMs;
};

class FrameRecorder {
 public:
  FrameRecorder(Context& ctx, const GpuModel& model, uint32_t instanceCapacity,
                const FrameRecorderOptions& options = {});
  FrameRecorder(const FrameRecorder&) = delete;
  FrameRecorder& operator=(const FrameRecorder&) = delete;

  uint32_t framesInFlight() const { return uint32_t(frames_.size()); }
  uint32_t instanceCapacity() const { return capacity_; }
  uint32_t slotOf(uint64_t frameIndex) const { return uint32_t(frameIndex % frames_.size()); }
  const FrameResources& frame(uint32_t slot) const { return frames_.at(slot); }

  // Writes `inputs` into frame frameIndex's slot and records its passes into `cmd` (begun by the caller);
  // returns the compute dispatches recorded (what the replay planner counts per batch: its "dispatches
  // per frame" are these, at most; the VQ decode has none on a frame whose maps are all decoded already).
  // The slot's decoded maps are kept for later frames: a caller that throws a recorded command buffer
  // away instead of submitting it calls forgetDecodedMaps() before the next record().
  uint32_t record(VkCommandBuffer cmd, uint64_t frameIndex, const runtime::FrameKernelInputs& inputs);
  // Every slot's decoded maps are decoded again when next selected, and every layer of an instance
  // without a map is copied from the previous slot when next kept.
  void forgetDecodedMaps();

  // After the fence of that frame's submission.
  StageTimes stageTimes(uint32_t slot) const;
  // Reads every output of a slot back (waits), in the reference's form, for comparisons and tools.
  runtime::ReferenceFrameOutputs download(uint32_t slot) const;
  // Sets a slot's normal maps (e.g. the previous frame's state in a test); waits.
  void uploadNormalMaps(uint32_t slot, const std::vector<runtime::BlendedNormalMap>& maps);

 private:
  Context* ctx_;
  const GpuModel* model_;
  uint32_t capacity_;
  bool tangentFrames_, normalMaps_;
  DeformPass deform_;
  TangentFramesPass tangentFramesPass_;
  VqDecodePass decode_;
  NormalMapBlendPass blend_;
  std::vector<FrameResources> frames_;
  std::vector<float> weightRows_, matrixRows_;  // inputs in DeformPass's layouts
  uint64_t records_ = 0;  // record() calls that decoded: the clock of FrameResources::slotLastUsed
  // Per instance (layer): the version of its current map, set by each blend or upload from versionClock_;
  // FrameResources::layerVersion says which slots hold it.
  std::vector<uint64_t> mapVersion_;
  uint64_t versionClock_ = 0;

  // Where the blend's layer list lies in FrameResources::blendCharacters: after the characters.
  VkDeviceSize blendLayersOffset() const { return VkDeviceSize(capacity_) * sizeof(NormalMapBlendPass::Character); }
  // Decode jobs and blend characters of the instances `blended` (those with a map); returns dispatches.
  uint32_t recordDecode(VkCommandBuffer cmd, FrameResources& f, const runtime::FrameKernelInputs& in,
                        const std::vector<uint32_t>& blended);
  // Brings the layers of the instances `kept` (without a map) in slot `slot` to their current maps.
  void carryLayersOver(VkCommandBuffer cmd, uint32_t slot, const std::vector<uint32_t>& kept);
};

}  // namespace swish::gpu
