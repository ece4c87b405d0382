#include "swish/gpu/frame_recorder.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "shaders/swish_layouts.h"
#include "swish/gpu/context.hpp"
#include "swish/gpu/gpu_model.hpp"
#include "swish/gpu/vk_check.hpp"
#include "swish/runtime/reference_push_out.hpp"

namespace swish::gpu {

namespace {
enum Mark : uint32_t { kBegin = 0, kAfterDeform, kAfterTangentFrames, kAfterDecode, kAfterBlend };
}

FrameRecorder::FrameRecorder(Context& ctx, const GpuModel& model, uint32_t capacity, const FrameRecorderOptions& o)
    : ctx_(&ctx),
      model_(&model),
      capacity_(capacity),
      tangentFrames_(o.tangentFrames),
      normalMaps_(o.normalMaps && model.hasNormalMaps()),
      deform_(ctx, model.kernelMeshComponents(), model.influences(), true, model.basis.size() / sizeof(float)) {
  if (o.framesInFlight < 1 || o.framesInFlight > 8)
    throw Error("frame recorder: " + std::to_string(o.framesInFlight) + " frames in flight; supported: 1..8");
  if (capacity == 0) throw Error("frame recorder: the instance capacity must be at least 1");
  if (tangentFrames_) tangentFramesPass_ = TangentFramesPass(ctx);
  if (normalMaps_) {
    decode_ = VqDecodePass(ctx);
    blend_ = NormalMapBlendPass(ctx, model.mapWidth());
  }
  for (uint32_t s = 0; s < o.framesInFlight; ++s)
    frames_.emplace_back(ctx, model, capacity, tangentFrames_, normalMaps_, s, o.shareNormalMapTexels);
  for (uint32_t s = 0; s < o.framesInFlight; ++s) {
    FrameResources& f = frames_[s];
    f.deformInputs = deform_.bindInstanceInputs(ctx, f.meshWeights, f.skinMatrices, &model.basis);
    if (tangentFrames_) {
      TangentFramesPass::TwoPassBuffers b;
      b.positions = &f.positions;
      b.triangleTerms = &f.triangleTerms;
      b.normalOffsets = &model.normalOffsets;
      b.frameTriangles = &model.frameTriangles;
      b.normalsOut = &f.normals;
      b.tangentsOut = &f.tangents;
      f.tangentFrames = tangentFramesPass_.bindTwoPass(ctx, b);
    }
    if (normalMaps_) {
      const uint32_t prev = (s + o.framesInFlight - 1) % o.framesInFlight;
      f.blendBinding = blend_.makeBinding(ctx, frames_[prev].blendOutput(), f.blendOutput(), f.decodedMaps);
    }
  }
}

void FrameRecorder::forgetDecodedMaps() {
  for (FrameResources& f : frames_) std::fill(f.slotMap.begin(), f.slotMap.end(), FrameResources::kNoMap);
}

uint32_t FrameRecorder::record(VkCommandBuffer cmd, uint64_t frameIndex, const runtime::FrameKernelInputs& in) {
  const GpuModel& m = *model_;
  if (in.instanceCount > capacity_)
    throw Error("frame recorder: " + std::to_string(in.instanceCount) + " instances, capacity " +
                std::to_string(capacity_));
  const size_t k = m.meshComponents(), j = m.jointCount();
  if (in.meshWeights.size() != in.instanceCount * k || in.skinMatrices.size() != in.instanceCount * j)
    throw Error("frame recorder: mesh weights or skinning matrices do not match " + std::to_string(in.instanceCount) +
                " instances of '" + m.name() + "'");
  const bool maps = normalMaps_ && !in.selectedMaps.empty();
  if (!in.selectedMaps.empty() &&
      (in.selectedMaps.size() != in.instanceCount || in.blendAlpha.size() != in.instanceCount))
    throw Error("frame recorder: selected maps and blend weights must be given for every instance, or not at all");
  for (uint32_t map : in.selectedMaps)
    if (map >= m.mapCount())
      throw Error("frame recorder: map " + std::to_string(map) + " is not in the database of '" + m.name() + "'");

  FrameResources& f = frames_[slotOf(frameIndex)];
  f.instanceCount = in.instanceCount;
  f.recordedTangentFrames = tangentFrames_;
  f.recordedNormalMaps = maps;
  f.decodedSlotCount = 0;
  f.decodeJobCount = 0;
  // The deform kernel's layouts: zero-padded weight rows, the top three rows of each skin matrix.
  const uint32_t kk = m.kernelMeshComponents();
  weightRows_.resize(size_t(in.instanceCount) * DeformPass::paddedComponents(kk));
  if (k == 0) {
    std::fill(weightRows_.begin(), weightRows_.end(), 0.f);  // the kernel's padded K = 1
  } else {
    DeformPass::packWeights(in.meshWeights.data(), in.instanceCount, uint32_t(k), weightRows_.data());
  }
  f.meshWeights.upload(*ctx_, weightRows_.data(), weightRows_.size() * sizeof(float));
  matrixRows_.resize(in.skinMatrices.size() * 12);
  DeformPass::packSkinMatrices(in.skinMatrices.data(), in.skinMatrices.size(), matrixRows_.data());
  f.skinMatrices.upload(*ctx_, matrixRows_.data(), matrixRows_.size() * sizeof(float));
  const bool pushOut = in.pushOut && m.capsuleCount() > 0;
  if (pushOut) {
    posedCapsules_.clear();
    for (uint32_t i = 0; i < in.instanceCount; ++i)
      runtime::poseBodyProxy(m.bodyProxy(), std::span(in.skinMatrices).subspan(i * j, j), posedCapsules_);
    f.posedCapsules.upload(*ctx_, posedCapsules_.data(), posedCapsules_.size() * sizeof(float));
  }

  // Orders this frame after earlier frames' GPU work on the queue: their writes of the normal maps this
  // frame blends from, and their reads of buffers this frame overwrites.
  computeToComputeBarrier(cmd);
  f.timestamps.reset(cmd);
  f.timestamps.mark(cmd, kBegin);

  DeformPass::Args d;
  d.mean = m.mean.address();
  d.basis = m.basis.address();
  d.instanceInputs = f.deformInputs.get();
  d.skinJoints = m.skinJoints.address();
  d.skinWeights = m.skinWeights.address();
  d.positionsOut = f.positions.address();
  d.vertexCount = m.vertexCount();
  d.instanceCount = in.instanceCount;
  d.jointCount = m.jointCount();
  if (pushOut) {
    d.capsules = f.posedCapsules.address();
    d.capsuleCount = m.capsuleCount();
  }
  uint32_t dispatches = deform_.record(cmd, d);
  f.timestamps.mark(cmd, kAfterDeform);

  if (tangentFrames_) {
    computeToComputeBarrier(cmd);  // positions written -> read
    TangentFramesPass::Args t;     // two-pass: each triangle's terms computed once (the rest is in the set)
    t.uvs = m.uvs.address();
    t.triangles = m.triangles.address();
    t.vertexCount = m.vertexCount();
    t.instanceCount = in.instanceCount;
    t.hasUvs = m.hasUvs();
    t.twoPass = f.tangentFrames.get();
    t.triangleCount = m.triangleCount();
    dispatches += tangentFramesPass_.record(cmd, t);
    f.timestamps.mark(cmd, kAfterTangentFrames);
  }

  if (maps) {
    // Each selected map is decoded once into a slot of decodedMaps, and stays there for later frames
    // (database maps are constant): only maps in no slot yet are decoded, into the slots least recently
    // selected (never one this frame reads). A batch selects a few dozen maps at most, so linear
    // searches beat hashing. The distinct maps of a frame never outnumber the slots (one per instance).
    const uint64_t now = ++records_;  // 0 in slotLastUsed: never selected
    auto slotOfMap = [&](uint32_t map) {
      return size_t(std::find(f.slotMap.begin(), f.slotMap.end(), map) - f.slotMap.begin());
    };
    for (uint32_t map : in.selectedMaps)  // first the slots this frame reads, so that none is given away
      if (const size_t slot = slotOfMap(map); slot < f.slotMap.size()) f.slotLastUsed[slot] = now;
    std::vector<uint32_t> jobMaps, jobSlots;
    std::vector<layout::NormalMapBlendCharacter> chars(in.instanceCount);
    for (uint32_t i = 0; i < in.instanceCount; ++i) {
      const uint32_t map = in.selectedMaps[i];
      size_t slot = slotOfMap(map);
      if (slot == f.slotMap.size()) {
        slot = size_t(std::min_element(f.slotLastUsed.begin(), f.slotLastUsed.end()) - f.slotLastUsed.begin());
        f.slotMap[slot] = map;
        f.slotLastUsed[slot] = now;
        jobMaps.push_back(map);
        jobSlots.push_back(uint32_t(slot));
      }
      chars[i] = {uint32_t(slot), in.blendAlpha[i]};
    }
    f.decodedSlotCount = uint32_t(std::count(f.slotLastUsed.begin(), f.slotLastUsed.end(), now));
    f.decodeJobCount = uint32_t(jobMaps.size());
    jobMaps.insert(jobMaps.end(), jobSlots.begin(), jobSlots.end());
    f.decodeSlotMaps.upload(*ctx_, jobMaps.data(), jobMaps.size() * sizeof(uint32_t));
    f.blendCharacters.upload(*ctx_, chars.data(), chars.size() * sizeof(chars[0]));
    VqDecodePass::Args v;
    v.codebook = m.codebook.address();
    v.indices = m.indices.address();
    v.jobMaps = f.decodeSlotMaps.address();
    v.jobSlots = f.decodeSlotMaps.address() + f.decodeJobCount * sizeof(uint32_t);
    v.decodedOut = f.decodedMaps.address();
    v.width = m.mapWidth();
    v.height = m.mapHeight();
    v.jobCount = f.decodeJobCount;
    v.codebookSize = m.codebookSize();
    dispatches += decode_.record(cmd, v);
    f.timestamps.mark(cmd, kAfterDecode);
    computeToComputeBarrier(cmd);  // decoded slots written -> read
    NormalMapBlendPass::Args b;
    b.characters = f.blendCharacters.address();
    b.width = m.mapWidth();
    b.height = m.mapHeight();
    b.characterCount = in.instanceCount;
    b.outTexels = f.blendOutput().handle();
    b.outMaps = f.normalMaps.image();
    b.outMapsShareTexels = f.normalMaps.sharesTexels();
    dispatches += blend_.record(cmd, f.blendBinding.get(), b);
    f.timestamps.mark(cmd, kAfterBlend);
  }
  return dispatches;
}

StageTimes FrameRecorder::stageTimes(uint32_t slot) const {
  const auto t = frames_.at(slot).timestamps.readNs();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto span = [&](uint32_t a, uint32_t b) {
    return (std::isnan(t[a]) || std::isnan(t[b])) ? nan : (t[b] - t[a]) * 1e-6;
  };
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
    if (maps[i].xy.size() != per)
      throw Error("frame recorder: normal map " + std::to_string(i) + " has the wrong size");
    std::copy(maps[i].xy.begin(), maps[i].xy.end(), all.begin() + i * per);
  }
  f.normalMaps.upload(*ctx_, all);
  if (!f.normalMaps.sharesTexels())                                           // else the upload wrote them
    f.blendedTexels.upload(*ctx_, all.data(), all.size() * sizeof(int16_t));  // what the next frame's blend reads
}

}  // namespace swish::gpu
