#include "swish/gpu/frame_recorder.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "shaders/swish_layouts.h"
#include "swish/gpu/context.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/gpu/vk_check.hpp"

namespace swish::gpu {

namespace {
enum Mark : uint32_t { kBegin = 0, kAfterDeform, kAfterTangentFrames, kAfterDecode, kAfterBlend };
}

FrameRecorder::FrameRecorder(Context& ctx, const GpuModel& model, uint32_t capacity, const FrameRecorderOptions& o)
    : ctx_(&ctx), model_(&model), capacity_(capacity), tangentFrames_(o.tangentFrames),
      normalMaps_(o.normalMaps && model.hasNormalMaps()),
      deform_(ctx, model.kernelMeshComponents(), model.influences()) {
  if (o.framesInFlight < 1 || o.framesInFlight > 8)
    throw Error("frame recorder: " + std::to_string(o.framesInFlight) + " frames in flight; supported: 1..8");
  if (capacity == 0) throw Error("frame recorder: the instance capacity must be at least 1");
  if (tangentFrames_) tangentFramesPass_ = TangentFramesPass(ctx);
  if (normalMaps_) {
    decode_ = VqDecodePass(ctx);
    blend_ = NormalMapBlendPass(ctx, o.framesInFlight);
  }
  for (uint32_t s = 0; s < o.framesInFlight; ++s) frames_.emplace_back(ctx, model, capacity, tangentFrames_, normalMaps_, s);
  if (normalMaps_)
    for (uint32_t s = 0; s < o.framesInFlight; ++s) {
      const uint32_t prev = (s + o.framesInFlight - 1) % o.framesInFlight;
      frames_[s].blendBinding = blend_.makeBinding(frames_[prev].normalMaps, frames_[s].normalMaps);
    }
}

void FrameRecorder::record(VkCommandBuffer cmd, uint64_t frameIndex, const runtime::FrameKernelInputs& in) {
  const GpuModel& m = *model_;
  if (in.instanceCount > capacity_)
    throw Error("frame recorder: " + std::to_string(in.instanceCount) + " instances, capacity " + std::to_string(capacity_));
  const size_t k = m.meshComponents(), j = m.jointCount();
  if (in.meshWeights.size() != in.instanceCount * k || in.skinMatrices.size() != in.instanceCount * j)
    throw Error("frame recorder: mesh weights or skinning matrices do not match " + std::to_string(in.instanceCount) +
                " instances of '" + m.name() + "'");
  const bool maps = normalMaps_ && !in.selectedMaps.empty();
  if (!in.selectedMaps.empty() && (in.selectedMaps.size() != in.instanceCount || in.blendAlpha.size() != in.instanceCount))
    throw Error("frame recorder: selected maps and blend weights must be given for every instance, or not at all");
  for (uint32_t map : in.selectedMaps)
    if (map >= m.mapCount()) throw Error("frame recorder: map " + std::to_string(map) + " is not in the database of '" + m.name() + "'");

  FrameResources& f = frames_[slotOf(frameIndex)];
  f.instanceCount = in.instanceCount;
  f.recordedTangentFrames = tangentFrames_;
  f.recordedNormalMaps = maps;
  f.decodedSlotCount = 0;
  if (k == 0) {
    std::memset(f.meshWeights.data(), 0, size_t(in.instanceCount) * sizeof(float));  // the kernel's padded K = 1
  } else {
    f.meshWeights.upload(*ctx_, in.meshWeights.data(), in.meshWeights.size() * sizeof(float));
  }
  f.skinMatrices.upload(*ctx_, in.skinMatrices.data(), in.skinMatrices.size() * sizeof(Mat4f));

  // Orders this frame after earlier frames' GPU work on the queue: their writes of the normal maps this
  // frame blends from, and their reads of buffers this frame overwrites.
  computeToComputeBarrier(cmd);
  f.timestamps.reset(cmd);
  f.timestamps.mark(cmd, kBegin);

  DeformPass::Args d;
  d.mean = m.mean.address();
  d.basis = m.basis.address();
  d.weights = f.meshWeights.address();
  d.skinMatrices = f.skinMatrices.address();
  d.skinJoints = m.skinJoints.address();
  d.skinWeights = m.skinWeights.address();
  d.positionsOut = f.positions.address();
  d.vertexCount = m.vertexCount();
  d.instanceCount = in.instanceCount;
  d.jointCount = m.jointCount();
  deform_.record(cmd, d);
  f.timestamps.mark(cmd, kAfterDeform);

  if (tangentFrames_) {
    computeToComputeBarrier(cmd);  // positions written -> read
    TangentFramesPass::Args t;
    t.positions = f.positions.address();
    t.uvs = m.uvs.address();
    t.triangles = m.triangles.address();
    t.normalOffsets = m.normalOffsets.address();
    t.normalTriangles = m.normalTriangles.address();
    t.tangentOffsets = m.tangentOffsets.address();
    t.tangentTriangles = m.tangentTriangles.address();
    t.normalsOut = f.normals.address();
    t.tangentsOut = f.tangents.address();
    t.vertexCount = m.vertexCount();
    t.instanceCount = in.instanceCount;
    t.hasUvs = m.hasUvs();
    t.triangleTerms = f.triangleTerms.address();  // two-pass: each triangle's terms computed once
    t.triangleCount = m.triangleCount();
    tangentFramesPass_.record(cmd, t);
    f.timestamps.mark(cmd, kAfterTangentFrames);
  }

  if (maps) {
    // Each selected map decoded once: slots in first-selection order (a batch selects a few dozen
    // maps at most, so a linear search beats hashing).
    std::vector<uint32_t> slotMaps;
    std::vector<layout::NormalMapBlendCharacter> chars(in.instanceCount);
    for (uint32_t i = 0; i < in.instanceCount; ++i) {
      const size_t slot = size_t(std::find(slotMaps.begin(), slotMaps.end(), in.selectedMaps[i]) - slotMaps.begin());
      if (slot == slotMaps.size()) slotMaps.push_back(in.selectedMaps[i]);
      chars[i] = {uint32_t(slot), in.blendAlpha[i]};
    }
    f.decodedSlotCount = uint32_t(slotMaps.size());
    f.decodeSlotMaps.upload(*ctx_, slotMaps.data(), slotMaps.size() * sizeof(uint32_t));
    f.blendCharacters.upload(*ctx_, chars.data(), chars.size() * sizeof(chars[0]));
    VqDecodePass::Args v;
    v.codebook = m.codebook.address();
    v.indices = m.indices.address();
    v.slotMaps = f.decodeSlotMaps.address();
    v.decodedOut = f.decodedMaps.address();
    v.width = m.mapWidth();
    v.height = m.mapHeight();
    v.slotCount = f.decodedSlotCount;
    v.codebookSize = m.codebookSize();
    decode_.record(cmd, v);
    f.timestamps.mark(cmd, kAfterDecode);
    computeToComputeBarrier(cmd);  // decoded slots written -> read
    NormalMapBlendPass::Args b;
    b.decoded = f.decodedMaps.address();
    b.characters = f.blendCharacters.address();
    b.width = m.mapWidth();
    b.height = m.mapHeight();
    b.characterCount = in.instanceCount;
    blend_.record(cmd, f.blendBinding.get(), b);
    f.timestamps.mark(cmd, kAfterBlend);
  }
}

StageTimes FrameRecorder::stageTimes(uint32_t slot) const {
  const auto t = frames_.at(slot).timestamps.readNs();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto span = [&](uint32_t a, uint32_t b) { return (std::isnan(t[a]) || std::isnan(t[b])) ? nan : (t[b] - t[a]) * 1e-6; };
  StageTimes s{span(kBegin, kAfterDeform), nan, nan, nan, nan};
  uint32_t last = kAfterDeform;
  if (!std::isnan(t[kAfterTangentFrames])) s.tangentFramesMs = span(kAfterDeform, last = kAfterTangentFrames);
  if (!std::isnan(t[kAfterDecode])) s.vqDecodeMs = span(last, kAfterDecode);
  if (!std::isnan(t[kAfterBlend])) s.normalBlendMs = span(kAfterDecode, last = kAfterBlend);
  s.totalMs = span(kBegin, last);
  return s;
}

runtime::ReferenceFrameOutputs FrameRecorder::download(uint32_t slot) const {
  const FrameResources& f = frames_.at(slot);
  ctx_->submitAndWait([](VkCommandBuffer cmd) { computeToHostBarrier(cmd); });
  const Eigen::Index n = model_->vertexCount();
  runtime::ReferenceFrameOutputs out;
  for (uint32_t i = 0; i < f.instanceCount; ++i) {
    Points3f p(n, 3);
    f.positions.download(*ctx_, p.data(), n * 3 * sizeof(float), VkDeviceSize(i) * n * 3 * sizeof(float));
    out.positions.push_back(std::move(p));
    if (f.recordedTangentFrames) {
      Points3f nr(n, 3);
      Points4f tg(n, 4);
      f.normals.download(*ctx_, nr.data(), n * 3 * sizeof(float), VkDeviceSize(i) * n * 3 * sizeof(float));
      f.tangents.download(*ctx_, tg.data(), n * 4 * sizeof(float), VkDeviceSize(i) * n * 4 * sizeof(float));
      out.normals.push_back(std::move(nr));
      out.tangents.push_back(std::move(tg));
    }
  }
  if (f.recordedNormalMaps) {
    const auto all = f.normalMaps.download(*ctx_);
    const size_t per = size_t(model_->mapWidth()) * model_->mapHeight() * 2;
    for (uint32_t i = 0; i < f.instanceCount; ++i)
      out.normalMaps.push_back({model_->mapWidth(), model_->mapHeight(),
                                std::vector<int16_t>(all.begin() + i * per, all.begin() + (i + 1) * per)});
  }
  return out;
}

void FrameRecorder::uploadNormalMaps(uint32_t slot, const std::vector<runtime::BlendedNormalMap>& maps) {
  FrameResources& f = frames_.at(slot);
  if (!normalMaps_) throw Error("frame recorder: this recorder has no normal maps");
  std::vector<int16_t> all(size_t(f.normalMaps.width()) * f.normalMaps.height() * 2 * f.normalMaps.layers(), 0);
  const size_t per = size_t(f.normalMaps.width()) * f.normalMaps.height() * 2;
  if (maps.size() > f.normalMaps.layers()) throw Error("frame recorder: more maps than instance capacity");
  for (size_t i = 0; i < maps.size(); ++i) {
    if (maps[i].xy.size() != per) throw Error("frame recorder: normal map " + std::to_string(i) + " has the wrong size");
    std::copy(maps[i].xy.begin(), maps[i].xy.end(), all.begin() + i * per);
  }
  f.normalMaps.upload(*ctx_, all);
}

}  // namespace swish::gpu
