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
    : ctx_(&ctx),
      model_(&model),
      capacity_(capacity),
      tangentFrames_(o.tangentFrames),
      normalMaps_(o.normalMaps && model.hasNormalMaps()),
      deform_(model.makeDeformPass(ctx)) {
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
  mapVersion_.assign(capacity, 0);  // every slot's layers start as version 0 (zeros)
  for (uint32_t s = 0; s < o.framesInFlight; ++s) {
    FrameResources& f = frames_[s];
    f.deformInputs = deform_.bindInstanceInputs(ctx, f.meshWeights, f.skinMatrices, &model.basis, &model.anchors);
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
  for (FrameResources& f : frames_) {
    std::fill(f.slotMap.begin(), f.slotMap.end(), FrameResources::kNoMap);
    // The thrown-away frame may have given its slot's layers versions its copies never wrote.
    std::fill(f.layerVersion.begin(), f.layerVersion.end(), FrameResources::kUnknownVersion);
  }
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
  if (!in.meshComponents.empty() && in.meshComponents.size() != in.instanceCount)
    throw Error("frame recorder: " + std::to_string(in.meshComponents.size()) +
                " per-instance mesh component counts for " + std::to_string(in.instanceCount) + " instances");
  for (size_t i = 0; i < in.meshComponents.size(); ++i)
    if (in.meshComponents[i] > k)
      throw Error("frame recorder: instance " + std::to_string(i) + " reads " + std::to_string(in.meshComponents[i]) +
                  " mesh components; '" + m.name() + "' has " + std::to_string(k));
  const bool maps = normalMaps_ && !in.selectedMaps.empty();
  if (!in.selectedMaps.empty() &&
      (in.selectedMaps.size() != in.instanceCount || in.blendAlpha.size() != in.instanceCount))
    throw Error("frame recorder: selected maps and blend weights must be given for every instance, or not at all");
  for (uint32_t map : in.selectedMaps)
    if (map != runtime::kNoMap && map >= m.mapCount())
      throw Error("frame recorder: map " + std::to_string(map) + " is not in the database of '" + m.name() + "'");

  const uint32_t slotIndex = slotOf(frameIndex);
  FrameResources& f = frames_[slotIndex];
  f.instanceCount = in.instanceCount;
  f.recordedTangentFrames = tangentFrames_;
  f.recordedNormalMaps = maps;
  f.decodedSlotCount = 0;
  f.decodeJobCount = 0;
  f.blendedCount = 0;
  f.carriedLayers = 0;
  // The deform kernel's layouts: zero-padded weight rows (zero from each instance's k on), the top three
  // rows of each skin matrix.
  const uint32_t kk = m.kernelMeshComponents();
  weightRows_.resize(size_t(in.instanceCount) * DeformPass::paddedComponents(kk));
  if (k == 0) {
    std::fill(weightRows_.begin(), weightRows_.end(), 0.f);  // the kernel's padded K = 1
  } else {
    DeformPass::packWeights(in.meshWeights.data(), in.instanceCount, uint32_t(k), in.meshComponents,
                            weightRows_.data());
  }
  f.meshWeights.upload(*ctx_, weightRows_.data(), weightRows_.size() * sizeof(float));
  // The deform's bands only where some instance reads fewer than all K: at full quality the kernel
  // without bands runs, as it did before levels.
  const bool levels =
      k > 0 && std::any_of(in.meshComponents.begin(), in.meshComponents.end(), [&](uint32_t c) { return c < k; });
  DeformPass::Levels bands;
  if (levels) {
    bands = DeformPass::packLevels(in.meshComponents, uint32_t(k));
    f.instanceOrder.upload(*ctx_, bands.order.data(), bands.order.size() * sizeof(uint32_t));
  }
  matrixRows_.resize(in.skinMatrices.size() * 12);
  DeformPass::packSkinMatrices(in.skinMatrices.data(), in.skinMatrices.size(), matrixRows_.data());
  f.skinMatrices.upload(*ctx_, matrixRows_.data(), matrixRows_.size() * sizeof(float));
  const bool pushOut = in.pushOut && m.hasBodyAnchors();

  // Orders this frame after earlier frames' GPU work on the queue: their writes of the normal maps this
  // frame blends from, and their reads of buffers this frame overwrites.
  computeToComputeBarrier(cmd);
  f.timestamps.reset(cmd);
  f.timestamps.mark(cmd, kBegin);

  DeformPass::Args d = m.deformArgs(f.deformInputs.get(), f.positions, in.instanceCount);
  if (pushOut) {
    d.anchors = m.anchors.address();
    d.anchorSlots = m.anchorSlots();
  }
  if (levels) {
    d.instanceOrder = f.instanceOrder.address();
    d.bandEnd = bands.bandEnd;
    d.maxGroups = bands.maxGroups;
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
    // The instances with a map this frame are decoded and blended; those without (kNoMap: a quality
    // level without normal maps) are left out of both, and their layers keep their maps.
    std::vector<uint32_t> blended, kept;
    for (uint32_t i = 0; i < in.instanceCount; ++i)
      (in.selectedMaps[i] == runtime::kNoMap ? kept : blended).push_back(i);
    f.blendedCount = uint32_t(blended.size());
    if (!blended.empty()) {
      dispatches += recordDecode(cmd, f, in, blended);
      f.timestamps.mark(cmd, kAfterDecode);
      computeToComputeBarrier(cmd);  // decoded slots written -> read
    }
    carryLayersOver(cmd, slotIndex, kept);
    if (!blended.empty()) {
      NormalMapBlendPass::Args b;
      b.characters = f.blendCharacters.address();
      b.width = m.mapWidth();
      b.height = m.mapHeight();
      b.characterCount = uint32_t(blended.size());
      if (blended.size() < in.instanceCount) {  // else character c is instance c: no list to read
        b.layers = f.blendCharacters.address() + blendLayersOffset();
        b.hostLayers = blended;
        b.maxLayers = capacity_;
      }
      b.outTexels = f.blendOutput().handle();
      b.outMaps = f.normalMaps.image();
      b.outMapsShareTexels = f.normalMaps.sharesTexels();
      dispatches += blend_.record(cmd, f.blendBinding.get(), b);
      for (uint32_t i : blended) f.layerVersion[i] = mapVersion_[i] = ++versionClock_;
    }
    if (!blended.empty() || f.carriedLayers > 0) f.timestamps.mark(cmd, kAfterBlend);
  }
  return dispatches;
}

uint32_t FrameRecorder::recordDecode(VkCommandBuffer cmd, FrameResources& f, const runtime::FrameKernelInputs& in,
                                     const std::vector<uint32_t>& blended) {
  const GpuModel& m = *model_;
  // Each selected map is decoded once into a slot of decodedMaps, and stays there for later frames
  // (database maps are constant): only maps in no slot yet are decoded, into the slots least recently
  // selected (never one this frame reads). A batch selects a few dozen maps at most, so linear
  // searches beat hashing. The distinct maps of a frame never outnumber the slots (one per instance).
  const uint64_t now = ++records_;  // 0 in slotLastUsed: never selected
  auto slotOfMap = [&](uint32_t map) {
    return size_t(std::find(f.slotMap.begin(), f.slotMap.end(), map) - f.slotMap.begin());
  };
  for (uint32_t i : blended)  // first the slots this frame reads, so that none is given away
    if (const size_t slot = slotOfMap(in.selectedMaps[i]); slot < f.slotMap.size()) f.slotLastUsed[slot] = now;
  std::vector<uint32_t> jobMaps, jobSlots;
  std::vector<layout::NormalMapBlendCharacter> chars(blended.size());
  for (size_t c = 0; c < blended.size(); ++c) {
    const uint32_t map = in.selectedMaps[blended[c]];
    size_t slot = slotOfMap(map);
    if (slot == f.slotMap.size()) {
      slot = size_t(std::min_element(f.slotLastUsed.begin(), f.slotLastUsed.end()) - f.slotLastUsed.begin());
      f.slotMap[slot] = map;
      f.slotLastUsed[slot] = now;
      jobMaps.push_back(map);
      jobSlots.push_back(uint32_t(slot));
    }
    chars[c] = {uint32_t(slot), in.blendAlpha[blended[c]]};
  }
  f.decodedSlotCount = uint32_t(std::count(f.slotLastUsed.begin(), f.slotLastUsed.end(), now));
  f.decodeJobCount = uint32_t(jobMaps.size());
  jobMaps.insert(jobMaps.end(), jobSlots.begin(), jobSlots.end());
  f.decodeSlotMaps.upload(*ctx_, jobMaps.data(), jobMaps.size() * sizeof(uint32_t));
  f.blendCharacters.upload(*ctx_, chars.data(), chars.size() * sizeof(chars[0]));
  f.blendCharacters.upload(*ctx_, blended.data(), blended.size() * sizeof(uint32_t), blendLayersOffset());
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
  return decode_.record(cmd, v);
}

void FrameRecorder::carryLayersOver(VkCommandBuffer cmd, uint32_t slotIndex, const std::vector<uint32_t>& kept) {
  FrameResources& f = frames_[slotIndex];
  const uint32_t prev = (slotIndex + framesInFlight() - 1) % framesInFlight();
  // Per source slot, the layers to copy from it: the previous slot's where it holds the current map (the
  // usual case), else any slot that does; where none does (forgetDecodedMaps after a command buffer was
  // thrown away), the previous slot's, which becomes the current map.
  std::vector<std::vector<uint32_t>> from(framesInFlight());
  for (uint32_t i : kept) {
    if (f.layerVersion[i] == mapVersion_[i]) continue;  // always so with one frame in flight
    uint32_t src = prev;
    if (frames_[prev].layerVersion[i] != mapVersion_[i])
      for (uint32_t s = 0; s < framesInFlight(); ++s)
        if (frames_[s].layerVersion[i] == mapVersion_[i]) {
          src = s;
          break;
        }
    if (frames_[src].layerVersion[i] != mapVersion_[i]) frames_[src].layerVersion[i] = mapVersion_[i] = ++versionClock_;
    f.layerVersion[i] = mapVersion_[i];
    if (src != slotIndex) from[src].push_back(i);
  }
  std::vector<uint32_t> all;  // every layer copied, for the images' layout transitions
  for (const auto& layers : from) all.insert(all.end(), layers.begin(), layers.end());
  if (all.empty()) return;
  const bool images = !f.normalMaps.sharesTexels();
  // The sources were written by earlier frames' blends (shader writes, or transfer writes into images
  // of their own), ordered before this frame's start; the copies' reads and writes come after them.
  // Where the images have memory of their own, the copied layers go to TRANSFER_DST_OPTIMAL for the
  // copy (the layout copies ask for) and back to GENERAL, as in the blend pass.
  VkMemoryBarrier mb{};
  mb.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER;
  mb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  std::vector<VkImageMemoryBarrier> ibs;
  if (images)
    for (uint32_t i : all) {
      VkImageMemoryBarrier ib{};
      ib.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER;
      ib.srcAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
      ib.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
      ib.oldLayout = VK_IMAGE_LAYOUT_GENERAL;
      ib.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
      ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
      ib.image = f.normalMaps.image();
      ib.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, i, 1};
      ibs.push_back(ib);
    }
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &mb, 0, nullptr, uint32_t(ibs.size()), ibs.data());
  const GpuModel& m = *model_;
  const VkDeviceSize layerBytes = NormalMapBlendPass::texelBytes(m.mapWidth(), m.mapHeight(), 1);
  for (uint32_t s = 0; s < framesInFlight(); ++s) {
    if (from[s].empty()) continue;
    const Buffer& src = frames_[s].blendOutput();
    std::vector<VkBufferCopy> bufferCopies;
    std::vector<VkBufferImageCopy> imageCopies;
    for (uint32_t i : from[s]) {
      bufferCopies.push_back({i * layerBytes, i * layerBytes, layerBytes});
      VkBufferImageCopy c{};  // tightly packed rows: the texels' layout is the image's
      c.bufferOffset = i * layerBytes;
      c.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, i, 1};
      c.imageExtent = {m.mapWidth(), m.mapHeight(), 1};
      imageCopies.push_back(c);
    }
    // The packed texels, which the next frame's blend reads (the images' own memory where they share
    // it); else the images take the same layers from the same source (the source slot's texels hold
    // what its images hold), so the two copies need no order between them, and the source slot's
    // images, which a renderer may still sample, are not touched.
    vkCmdCopyBuffer(cmd, src.handle(), f.blendOutput().handle(), uint32_t(bufferCopies.size()), bufferCopies.data());
    if (images)
      vkCmdCopyBufferToImage(cmd, src.handle(), f.normalMaps.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                             uint32_t(imageCopies.size()), imageCopies.data());
    f.carriedLayers += uint32_t(from[s].size());
  }
  // To the compute stage, as the blend pass ends: the next frame's blend reads these texels, and a
  // renderer's barrier from COMPUTE_SHADER/SHADER_WRITE (FrameRecorder's contract) chains to the copies.
  mb.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  mb.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
  for (VkImageMemoryBarrier& b : ibs) {
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_GENERAL;
  }
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0, 1, &mb, 0, nullptr,
                       uint32_t(ibs.size()), ibs.data());
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
  for (uint32_t i = 0; i < f.normalMaps.layers(); ++i) f.layerVersion[i] = mapVersion_[i] = ++versionClock_;
  if (!f.normalMaps.sharesTexels())                                           // else the upload wrote them
    f.blendedTexels.upload(*ctx_, all.data(), all.size() * sizeof(int16_t));  // what the next frame's blend reads
}

}  // namespace swish::gpu
