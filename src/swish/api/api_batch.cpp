// CharacterBatch: per-frame CPU evaluation (network, lookup, filter) and the recording of the GPU
// passes into the host's command buffer, with the frames-in-flight bookkeeping that keeps a frame
// the GPU may still read from being overwritten.
#include <chrono>
#include <cmath>

#include "swish/api/api_impl.hpp"
#include "swish/gpu/buffer.hpp"

namespace swish::api {

namespace {

uint32_t heldSlot(const BatchImpl& b, uint64_t frameIndex, const char* what) {
  const uint32_t slot = uint32_t(frameIndex % b.slots.size());
  if (b.slots[slot].frame != frameIndex)
    throw Error(ErrorCode::InvalidArgument, std::string(what) + ": frame " + std::to_string(frameIndex) +
                                                " is not held by this batch (only the last " +
                                                std::to_string(b.slots.size()) + " recorded frames are)");
  return slot;
}

uint32_t retiredSlot(const BatchImpl& b, uint64_t frameIndex, uint32_t character, const char* what) {
  const uint32_t slot = heldSlot(b, frameIndex, what);
  if (!b.slots[slot].retired)
    throw Error(ErrorCode::FrameInFlight, std::string(what) + ": frame " + std::to_string(frameIndex) +
                                              " is not retired yet (wait for its fence, then retireFrame)");
  if (character >= b.characters)
    throw Error(ErrorCode::InvalidArgument,
                std::string(what) + ": character " + std::to_string(character) + " of " + std::to_string(b.characters));
  return slot;
}

void ensureLadder(BatchImpl& b) {
  if (!b.levels.empty()) return;
  b.ladder = runtime::ladderOf(b.model->model, b.normalMaps);
  b.levels.assign(b.characters, 0);
  b.hostLevel.assign(b.characters, false);
}

}  // namespace

CharacterBatch::CharacterBatch(std::unique_ptr<BatchImpl> impl) : impl_(std::move(impl)) {}
CharacterBatch::CharacterBatch(CharacterBatch&&) noexcept = default;
CharacterBatch& CharacterBatch::operator=(CharacterBatch&&) noexcept = default;
CharacterBatch::~CharacterBatch() = default;

uint32_t CharacterBatch::characters() const { return impl_->characters; }
uint32_t CharacterBatch::framesInFlight() const { return uint32_t(impl_->slots.size()); }

FrameReport CharacterBatch::recordFrame(VkCommandBuffer cmd, uint64_t frameIndex,
                                        std::span<const CharacterPose> poses) {
  return translateErrors(ErrorCode::InvalidArgument, [&] {
    BatchImpl& b = *impl_;
    const auto start = std::chrono::steady_clock::now();
    const std::string where = "recordFrame(frame " + std::to_string(frameIndex) + ") of '" + b.model->info.name + "'";
    if (cmd == VK_NULL_HANDLE) throw Error(ErrorCode::InvalidArgument, where + ": no command buffer");
    if (b.lastRecorded && frameIndex != *b.lastRecorded + 1)
      throw Error(ErrorCode::InvalidArgument,
                  where + ": frames must be recorded in order; the last one was " + std::to_string(*b.lastRecorded));
    const uint32_t slot = uint32_t(frameIndex % b.slots.size());
    if (b.slots[slot].frame && !b.slots[slot].retired)
      throw Error(ErrorCode::FrameInFlight,
                  where + ": its resources were last used by frame " + std::to_string(*b.slots[slot].frame) +
                      ", which is not retired (wait for that frame's fence, then retireFrame)");
    if (poses.size() != b.characters)
      throw Error(ErrorCode::InvalidArgument, where + ": " + std::to_string(poses.size()) + " poses for " +
                                                  std::to_string(b.characters) + " characters");

    // Everything is checked before any state changes, so that an error leaves the batch as it was.
    FrameReport report;
    report.frameIndex = frameIndex;
    const swish::Model& model = b.model->model;
    const size_t joints = model.skeleton.size();
    b.rotations.resize(size_t(b.characters) * joints);
    b.dt.resize(b.characters);
    b.inputs.instanceCount = b.characters;
    b.inputs.skinMatrices.clear();
    for (uint32_t c = 0; c < b.characters; ++c) {
      const Pose p = toSkeletonPose(model, poses[c], c, &report.warnings);
      std::copy(p.local.begin(), p.local.end(), b.rotations.begin() + size_t(c) * joints);
      b.dt[c] = poses[c].dtSeconds;
      const Mat4f world = toMat4f(poses[c].characterToWorld);
      for (const Mat4f& m : model.skeleton.skinningMatrices(p)) b.inputs.skinMatrices.push_back(world * m);
    }

    ensureLadder(b);
    if (b.planner) {
      b.roots.clear();
      for (uint32_t c = 0; c < b.characters; ++c) {
        const Mat4f world = toMat4f(poses[c].characterToWorld);
        b.roots.push_back(world.block<3, 1>(0, 3).cast<double>());
      }
      const runtime::PlannedLevels& planned = b.planner->plan(frameIndex, b.roots);
      for (uint32_t c = 0; c < b.characters; ++c)
        if (!b.hostLevel[c] && planned.characters[c].level != b.levels[c]) {
          b.levels[c] = planned.characters[c].level;
          b.evaluator->setLevel(c, b.ladder[b.levels[c]]);
        }
    }
    const runtime::FrameOutput& out = b.evaluator->evaluate(b.rotations, b.dt);
    for (uint32_t c : out.invalidDt)
      report.warnings.push_back("character " + std::to_string(c) + ": negative or NaN dtSeconds treated as 0");
    for (uint32_t c : out.nonFiniteCode)
      report.warnings.push_back("character " + std::to_string(c) +
                                ": the network's normal code was not finite; kept the previous map");
    report.novelty = out.novelty;
    report.guardBlend = out.guardBlend;
    report.novelCharacters = out.novel;
    b.inputs.meshWeights = out.meshWeights;
    b.inputs.meshComponents.resize(b.characters);
    for (uint32_t c = 0; c < b.characters; ++c) b.inputs.meshComponents[c] = b.ladder[b.levels[c]].meshComponents;
    report.qualityLevels = b.levels;
    b.inputs.selectedMaps.clear();
    b.inputs.blendAlpha.clear();
    if (b.normalMaps) {
      b.inputs.selectedMaps = out.mapIndex;
      b.inputs.blendAlpha = out.blendAlpha;
    }
    b.recorder->record(cmd, frameIndex, b.inputs);
    b.slots[slot] = {frameIndex, false};
    b.lastRecorded = frameIndex;
    report.cpuMilliseconds =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return report;
  });
}

void CharacterBatch::setQualityLevel(uint32_t character, uint32_t level) {
  translateErrors(ErrorCode::InvalidArgument, [&] {
    BatchImpl& b = *impl_;
    ensureLadder(b);
    if (character >= b.characters)
      throw Error(ErrorCode::InvalidArgument,
                  "setQualityLevel: character " + std::to_string(character) + " of " + std::to_string(b.characters));
    if (level >= b.ladder.size())
      throw Error(ErrorCode::InvalidArgument, "setQualityLevel: level " + std::to_string(level) + " of a ladder of " +
                                                  std::to_string(b.ladder.size()) + " levels");
    b.levels[character] = level;
    b.hostLevel[character] = true;
    b.evaluator->setLevel(character, b.ladder[level]);
  });
}

uint32_t CharacterBatch::qualityLevel(uint32_t character) const {
  if (character >= impl_->characters)
    throw Error(ErrorCode::InvalidArgument,
                "qualityLevel: character " + std::to_string(character) + " of " + std::to_string(impl_->characters));
  return impl_->levels.empty() ? 0u : impl_->levels[character];
}

void CharacterBatch::planQualityLevels(const LevelPlanning& p) {
  translateErrors(ErrorCode::InvalidArgument, [&] {
    BatchImpl& b = *impl_;
    ensureLadder(b);
    runtime::LevelPlannerSettings s;
    s.camera.position = Eigen::Vector3d(p.cameraPosition[0], p.cameraPosition[1], p.cameraPosition[2]);
    s.camera.target = Eigen::Vector3d(p.cameraTarget[0], p.cameraTarget[1], p.cameraTarget[2]);
    s.camera.verticalFovDegrees = p.verticalFovDegrees;
    s.camera.imageHeightPixels = p.imageHeightPixels;
    s.tolerancePixels = double(p.tolerancePixels);
    s.holdFrames = p.holdFrames;
    if (!(p.verticalFovDegrees >= 1.f && p.verticalFovDegrees <= 170.f) || !(p.imageHeightPixels >= 16.f))
      throw Error(ErrorCode::InvalidArgument, "planQualityLevels: field of view 1..170 degrees, image >= 16 px");
    b.planner.emplace(std::vector<const runtime::QualityLadder*>(b.characters, &b.ladder),
                      std::vector<std::optional<uint32_t>>(b.characters), s);
  });
}

void CharacterBatch::retireFrame(uint64_t frameIndex) {
  for (auto& s : impl_->slots)
    if (s.frame && *s.frame <= frameIndex) s.retired = true;
}

bool CharacterBatch::idle() const {
  for (const auto& s : impl_->slots)
    if (!s.retired) return false;
  return true;
}

void CharacterBatch::resetCharacter(uint32_t character) {
  translateErrors(ErrorCode::InvalidArgument, [&] {
    if (character >= impl_->characters)
      throw Error(ErrorCode::InvalidArgument, "resetCharacter: character " + std::to_string(character) + " of " +
                                                  std::to_string(impl_->characters));
    impl_->evaluator->resetCharacter(character);
  });
}

GpuTimes CharacterBatch::gpuTimes(uint64_t frameIndex) const {
  return translateErrors(ErrorCode::InvalidArgument, [&] {
    const uint32_t slot = retiredSlot(*impl_, frameIndex, 0, "gpuTimes");
    const gpu::StageTimes t = impl_->recorder->stageTimes(slot);
    return GpuTimes{t.deformMs, t.tangentFramesMs, t.vqDecodeMs, t.normalBlendMs, t.totalMs};
  });
}

DeformedMesh CharacterBatch::readBackMesh(uint64_t frameIndex, uint32_t character) const {
  return translateErrors(ErrorCode::InvalidArgument, [&] {
    const uint32_t slot = retiredSlot(*impl_, frameIndex, character, "readBackMesh");
    gpu::Context& ctx = impl_->model->runtime->ctx;
    const gpu::FrameResources& f = impl_->recorder->frame(slot);
    const size_t n = impl_->model->info.vertexCount;
    ctx.submitAndWait([](VkCommandBuffer cmd) { gpu::computeToHostBarrier(cmd); });
    DeformedMesh m;
    m.positions.resize(3 * n);
    m.normals.resize(3 * n);
    m.tangents.resize(4 * n);
    f.positions.download(ctx, m.positions.data(), 3 * n * sizeof(float), character * 3 * n * sizeof(float));
    f.normals.download(ctx, m.normals.data(), 3 * n * sizeof(float), character * 3 * n * sizeof(float));
    f.tangents.download(ctx, m.tangents.data(), 4 * n * sizeof(float), character * 4 * n * sizeof(float));
    m.uvs = impl_->model->info.uvs;
    return m;
  });
}

std::vector<int16_t> CharacterBatch::readBackNormalMap(uint64_t frameIndex, uint32_t character) const {
  return translateErrors(ErrorCode::InvalidArgument, [&] {
    const uint32_t slot = retiredSlot(*impl_, frameIndex, character, "readBackNormalMap");
    if (!impl_->normalMaps) return std::vector<int16_t>{};
    gpu::Context& ctx = impl_->model->runtime->ctx;
    const auto all = impl_->recorder->frame(slot).normalMaps.download(ctx);
    const size_t per = size_t(impl_->model->info.normalMapWidth) * impl_->model->info.normalMapHeight * 2;
    return std::vector<int16_t>(all.begin() + character * per, all.begin() + (character + 1) * per);
  });
}

FrameOutputs CharacterBatch::outputs(uint64_t frameIndex) const {
  return translateErrors(ErrorCode::InvalidArgument, [&] {
    const BatchImpl& b = *impl_;
    const uint32_t slot = heldSlot(b, frameIndex, "outputs");
    const gpu::FrameResources& f = b.recorder->frame(slot);
    const gpu::GpuModel& gm = *b.model->gpuModel;
    const VkDeviceSize n = gm.vertexCount();
    FrameOutputs o;
    o.frameIndex = frameIndex;
    o.characters = b.characters;
    o.vertexCount = gm.vertexCount();
    o.positions = {f.positions.handle(), 0, n * 12, 12, VK_FORMAT_R32G32B32_SFLOAT};
    o.normals = {f.normals.handle(), 0, n * 12, 12, VK_FORMAT_R32G32B32_SFLOAT};
    o.tangents = {f.tangents.handle(), 0, n * 16, 16, VK_FORMAT_R32G32B32A32_SFLOAT};
    if (gm.hasUvs()) o.uvs = {gm.uvs.handle(), 0, 0, 8, VK_FORMAT_R32G32_SFLOAT};
    // gpu/buffer.cpp creates every buffer with these usages.
    o.bufferUsage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_VERTEX_BUFFER_BIT |
                    VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    o.queueFamily = b.model->runtime->ctx.queueFamily();
    if (b.normalMaps) {
      NormalMapOutput nm;
      nm.image = f.normalMaps.image();
      nm.view = f.normalMaps.arrayView();
      nm.format = gpu::NormalMapImages::kFormat;
      nm.layout = VK_IMAGE_LAYOUT_GENERAL;  // normal_map_images.hpp: GENERAL for the image's whole life
      nm.usage = VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                 VK_IMAGE_USAGE_TRANSFER_DST_BIT;
      nm.range = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, f.normalMaps.layers()};
      nm.width = f.normalMaps.width();
      nm.height = f.normalMaps.height();
      nm.layers = f.normalMaps.layers();
      o.normalMaps = nm;
    }
    return o;
  });
}

}  // namespace swish::api
