#include "swish/render/preview_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "swish/api_error.hpp"
#include "swish/io/png.hpp"
#include "swish/render/body_skinning.hpp"
#include "swish/render/preview_pipelines.hpp"
#include "swish/render/vk_owned.hpp"

#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace swish::render {

namespace {

VkImageMemoryBarrier2 imageBarrier(VkImage image, VkImageAspectFlags aspect, VkPipelineStageFlags2 srcStage,
                                   VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess,
                                   VkImageLayout from, VkImageLayout to) {
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  b.srcStageMask = srcStage;
  b.srcAccessMask = srcAccess;
  b.dstStageMask = dstStage;
  b.dstAccessMask = dstAccess;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = image;
  b.subresourceRange = {aspect, 0, 1, 0, 1};
  return b;
}

void pipelineBarrier(VkCommandBuffer cmd, std::span<const VkBufferMemoryBarrier2> buffers,
                     std::span<const VkImageMemoryBarrier2> images) {
  VkDependencyInfo di{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  di.bufferMemoryBarrierCount = uint32_t(buffers.size());
  di.pBufferMemoryBarriers = buffers.data();
  di.imageMemoryBarrierCount = uint32_t(images.size());
  di.pImageMemoryBarriers = images.data();
  vkCmdPipelineBarrier2(cmd, &di);
}

MappedBuffer filled(HostDevice& d, const void* src, size_t bytes, VkBufferUsageFlags usage) {
  MappedBuffer b = makeMappedBuffer(d, bytes, usage);
  if (bytes) std::memcpy(b.data, src, bytes);
  return b;
}

}  // namespace

struct PreviewRenderer::State {
  HostDevice* dev;
  api::Runtime runtime;
  api::Model model;
  api::CharacterBatch batch;
  PreviewOptions opts;
  PreviewPipelines pipes;
  PreviewCamera cam;
  api::Mat4 viewProj;
  Owned<VkCommandPool> pool;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  Owned<VkFence> fence;
  MappedBuffer jerseyIndices, zeroUvs;
  std::optional<BodySkinner> body;
  MappedBuffer bodyVertices, bodyIndices;
  OwnedImage dummyMap;  // bound when the model has no normal maps (never sampled: useNormalMap = 0)
  OwnedImage color, depth;
  MappedBuffer readback;
  uint32_t targetWidth = 0;
  uint64_t frame = 0;
  api::FrameReport lastReport;

  State(HostDevice& d, api::Runtime rt, const api::Model& m, PreviewOptions o)
      : dev(&d),
        runtime(std::move(rt)),
        model(m),
        batch(m.createBatch({1, o.framesInFlight, true, o.pushOut})),
        opts(std::move(o)),
        pipes(d) {}

  void submitAndWait() {
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd;
    vkCheck(vkQueueSubmit(dev->queue(), 1, &si, fence.get()), "vkQueueSubmit");
    VkFence f = fence.get();
    vkCheck(vkWaitForFences(dev->device(), 1, &f, VK_TRUE, UINT64_MAX), "vkWaitForFences");
    vkCheck(vkResetFences(dev->device(), 1, &f), "vkResetFences");
  }

  void begin() {
    vkCheck(vkResetCommandBuffer(cmd, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkCheck(vkBeginCommandBuffer(cmd, &bi), "vkBeginCommandBuffer");
  }

  void ensureTarget(uint32_t width) {
    if (width == targetWidth) return;
    const uint32_t h = opts.height;
    color = makeImage(*dev, width, h, PreviewPipelines::kColorFormat,
                      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT, VK_IMAGE_ASPECT_COLOR_BIT);
    depth = makeImage(*dev, width, h, PreviewPipelines::kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT,
                      VK_IMAGE_ASPECT_DEPTH_BIT);
    readback = makeMappedBuffer(*dev, VkDeviceSize(width) * h * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    targetWidth = width;
  }

  PreviewPushConstants push(const float* rgb, bool normalMap) const {
    PreviewPushConstants p{};
    std::memcpy(p.viewProj, viewProj.data(), sizeof p.viewProj);
    for (int a = 0; a < 3; ++a) {
      p.cameraPos[a] = cam.eye[a];
      p.lightDir[a] = opts.lightDirection[a];
      p.baseColor[a] = rgb[a];
    }
    p.layer = 0;
    p.useNormalMap = normalMap ? 1u : 0u;
    return p;
  }
};

void BodyMesh::validate(size_t jointCount) const {
  auto bad = [](const std::string& why) { throw api::Error(api::ErrorCode::InvalidArgument, "body mesh: " + why); };
  if (positions.empty() || positions.size() % 3) bad("positions must be 3 floats per vertex, at least one vertex");
  const size_t n = positions.size() / 3;
  if (!normals.empty() && normals.size() != positions.size()) bad("normals must be empty or 3 floats per vertex");
  if (triangles.empty() || triangles.size() % 3) bad("triangles must be 3 indices each, at least one");
  for (uint32_t t : triangles)
    if (t >= n) bad("triangle index " + std::to_string(t) + " >= vertex count " + std::to_string(n));
  if (influences < 1 || influences > 8) bad(std::to_string(influences) + " influences per vertex; 1..8 supported");
  if (joints.size() != n * influences || weights.size() != n * influences)
    bad("skin joints/weights must be vertexCount * influences");
  for (uint16_t j : joints)
    if (j >= jointCount)
      bad("skin joint " + std::to_string(j) + " is not in the model's skeleton of " + std::to_string(jointCount));
  for (float v : positions)
    if (!std::isfinite(v)) bad("non-finite position");
}

size_t BodyMesh::hideCovered(const api::ModelInfo& model) {
  const size_t count = triangles.size() / 3;
  if (model.coveredBodyTriangles.empty()) return 0;
  if (model.coveredBodyOf != count)
    throw api::Error(api::ErrorCode::InvalidArgument, "body mesh: the model's covered-triangle list is for a body of " +
                                                          std::to_string(model.coveredBodyOf) +
                                                          " triangles, this one has " + std::to_string(count) +
                                                          " (not the body the model was baked on)");
  std::vector<uint8_t> hide(count, 0);
  for (uint32_t t : model.coveredBodyTriangles) hide[t] = 1;
  std::vector<uint32_t> kept;
  kept.reserve(triangles.size());
  for (size_t t = 0; t < count; ++t)
    if (!hide[t]) kept.insert(kept.end(), triangles.begin() + long(3 * t), triangles.begin() + long(3 * t + 3));
  if (kept.empty())
    throw api::Error(api::ErrorCode::InvalidArgument, "body mesh: the garment covers every triangle; nothing to draw");
  const size_t hidden = count - kept.size() / 3;
  triangles = std::move(kept);
  return hidden;
}

PreviewRenderer::PreviewRenderer(HostDevice& device, api::Runtime runtime, const api::Model& model,
                                 PreviewOptions options) {
  if (options.width == 0 || options.height == 0 || options.width > 8192 || options.height > 8192)
    throw api::Error(api::ErrorCode::InvalidArgument, "preview renderer: image size must be 1..8192 a side");
  if (options.body) options.body->validate(model.info().jointNames.size());
  s_ = std::make_unique<State>(device, std::move(runtime), model, std::move(options));
  State& s = *s_;
  VkDevice dev = device.device();
  const api::ModelInfo& info = s.model.info();

  VkCommandPoolCreateInfo cpci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  cpci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cpci.queueFamilyIndex = device.queueFamily();
  VkCommandPool pool;
  vkCheck(vkCreateCommandPool(dev, &cpci, nullptr, &pool), "vkCreateCommandPool");
  s.pool = Owned<VkCommandPool>(pool, [dev](VkCommandPool h) { vkDestroyCommandPool(dev, h, nullptr); });
  VkCommandBufferAllocateInfo cbai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cbai.commandPool = pool;
  cbai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cbai.commandBufferCount = 1;
  vkCheck(vkAllocateCommandBuffers(dev, &cbai, &s.cmd), "vkAllocateCommandBuffers");
  VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence;
  vkCheck(vkCreateFence(dev, &fci, nullptr, &fence), "vkCreateFence");
  s.fence = Owned<VkFence>(fence, [dev](VkFence h) { vkDestroyFence(dev, h, nullptr); });

  s.jerseyIndices =
      filled(device, info.triangleIndices.data(), info.triangleIndices.size() * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  if (info.uvs.empty()) {
    const std::vector<float> zeros(size_t(info.vertexCount) * 2, 0.f);
    s.zeroUvs = filled(device, zeros.data(), zeros.size() * 4, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  }
  if (s.opts.body) {
    s.body.emplace(*s.opts.body);
    s.bodyVertices = makeMappedBuffer(device, s.body->vertexCount() * 24, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
    s.bodyIndices = filled(device, s.opts.body->triangles.data(), s.opts.body->triangles.size() * 4,
                           VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  }

  // The fixed camera: the body's rest pose when there is one (the whole mannequin), else the jersey's.
  const float aspect = float(s.opts.width) / float(s.opts.height);
  if (s.opts.camera) {
    s.cam = *s.opts.camera;
  } else {
    Vec3 lo, hi;
    boundsOf(s.opts.body ? std::span<const float>(s.opts.body->positions) : std::span<const float>(info.restPositions),
             lo, hi);
    s.cam = frameBox(lo, hi, aspect);
  }
  s.viewProj = render::viewProjection(s.cam, aspect);

  s.dummyMap = makeImage(device, 1, 1, VK_FORMAT_R16G16_SNORM, VK_IMAGE_USAGE_SAMPLED_BIT, VK_IMAGE_ASPECT_COLOR_BIT,
                         VK_IMAGE_VIEW_TYPE_2D_ARRAY);
  s.begin();
  const auto toGeneral = imageBarrier(s.dummyMap.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_NONE, 0,
                                      VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                                      VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL);
  pipelineBarrier(s.cmd, {}, std::span(&toGeneral, 1));
  vkCheck(vkEndCommandBuffer(s.cmd), "vkEndCommandBuffer");
  s.submitAndWait();
}

PreviewRenderer::~PreviewRenderer() = default;

bool PreviewRenderer::drawsBody() const { return s_->body.has_value(); }
const PreviewCamera& PreviewRenderer::camera() const { return s_->cam; }
api::Mat4 PreviewRenderer::viewProjection() const { return s_->viewProj; }
const PreviewOptions& PreviewRenderer::options() const { return s_->opts; }
uint64_t PreviewRenderer::framesRendered() const { return s_->frame; }
const api::FrameReport& PreviewRenderer::lastReport() const { return s_->lastReport; }

api::DeformedMesh PreviewRenderer::lastJersey() const {
  if (s_->frame == 0) throw api::Error(api::ErrorCode::InvalidArgument, "preview renderer: nothing rendered yet");
  return s_->batch.readBackMesh(s_->frame - 1, 0);
}

std::vector<float> PreviewRenderer::lastBody() const {
  if (s_->frame == 0) throw api::Error(api::ErrorCode::InvalidArgument, "preview renderer: nothing rendered yet");
  if (!s_->body) return {};
  const float* xyz = static_cast<const float*>(s_->bodyVertices.data);  // positions, then normals
  return std::vector<float>(xyz, xyz + 3 * s_->body->vertexCount());
}

PreviewImage PreviewRenderer::render(const api::CharacterPose& pose, const std::vector<PreviewVariant>& variants) {
  State& s = *s_;
  if (variants.empty()) throw api::Error(api::ErrorCode::InvalidArgument, "preview renderer: no variant to draw");
  const uint32_t w = s.opts.width, h = s.opts.height, total = w * uint32_t(variants.size());
  if (total > 16384)
    throw api::Error(api::ErrorCode::InvalidArgument, "preview renderer: too many variants side by side");
  s.ensureTarget(total);
  if (s.body) s.body->skin(s.model.skinningMatrices(pose), static_cast<float*>(s.bodyVertices.data));

  s.begin();
  s.lastReport = s.batch.recordFrame(s.cmd, s.frame, std::span(&pose, 1));
  const api::FrameOutputs out = s.batch.outputs(s.frame);
  // swish's outputs -> our vertex input and fragment sampling; our targets -> attachments.
  const auto bufferBarriers = out.vertexBarriers();
  std::vector<VkImageMemoryBarrier2> images;
  if (auto b = out.normalMapBarrier()) images.push_back(*b);
  images.push_back(imageBarrier(s.color.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_COPY_BIT,
                                VK_ACCESS_2_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_IMAGE_LAYOUT_UNDEFINED,
                                VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL));
  images.push_back(
      imageBarrier(s.depth.image.get(), VK_IMAGE_ASPECT_DEPTH_BIT, VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                   VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                   VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                   VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT,
                   VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL));
  pipelineBarrier(s.cmd, bufferBarriers, images);
  const bool maps = out.normalMaps.has_value();
  s.pipes.bindNormalMaps(maps ? out.normalMaps->view : s.dummyMap.view.get(), VK_IMAGE_LAYOUT_GENERAL);

  VkRenderingAttachmentInfo ca{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  ca.imageView = s.color.view.get();
  ca.imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  ca.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  ca.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  ca.clearValue.color = {{s.opts.background[0], s.opts.background[1], s.opts.background[2], 0.f}};
  VkRenderingAttachmentInfo da{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
  da.imageView = s.depth.view.get();
  da.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
  da.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  da.storeOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  da.clearValue.depthStencil = {1.f, 0};
  VkRenderingInfo ri{VK_STRUCTURE_TYPE_RENDERING_INFO};
  ri.renderArea = {{0, 0}, {total, h}};
  ri.layerCount = 1;
  ri.colorAttachmentCount = 1;
  ri.pColorAttachments = &ca;
  ri.pDepthAttachment = &da;
  vkCmdBeginRendering(s.cmd, &ri);
  const VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
  for (size_t v = 0; v < variants.size(); ++v) {
    const VkViewport vp{float(v * w), 0.f, float(w), float(h), 0.f, 1.f};
    const VkRect2D sc{{int32_t(v * w), 0}, {w, h}};
    vkCmdSetViewport(s.cmd, 0, 1, &vp);
    vkCmdSetScissor(s.cmd, 0, 1, &sc);
    if (s.body && variants[v].body) {
      const auto pc = s.push(s.opts.bodyColor.data(), false);
      vkCmdBindPipeline(s.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.pipes.body());
      vkCmdPushConstants(s.cmd, s.pipes.layout(), stages, 0, sizeof pc, &pc);
      const VkBuffer bufs[2] = {s.bodyVertices.buffer.get(), s.bodyVertices.buffer.get()};
      const VkDeviceSize offs[2] = {0, VkDeviceSize(s.body->vertexCount()) * 12};
      vkCmdBindVertexBuffers(s.cmd, 0, 2, bufs, offs);
      vkCmdBindIndexBuffer(s.cmd, s.bodyIndices.buffer.get(), 0, VK_INDEX_TYPE_UINT32);
      vkCmdDrawIndexed(s.cmd, uint32_t(s.opts.body->triangles.size()), 1, 0, 0, 0);
    }
    const auto pc = s.push(s.opts.jerseyColor.data(), maps && variants[v].normalMap);
    vkCmdBindPipeline(s.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.pipes.jersey());
    const VkDescriptorSet set = s.pipes.descriptorSet();
    vkCmdBindDescriptorSets(s.cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, s.pipes.layout(), 0, 1, &set, 0, nullptr);
    vkCmdPushConstants(s.cmd, s.pipes.layout(), stages, 0, sizeof pc, &pc);
    const VkBuffer bufs[4] = {out.positions.buffer, out.normals.buffer, out.tangents.buffer,
                              out.uvs.buffer ? out.uvs.buffer : s.zeroUvs.buffer.get()};
    const VkDeviceSize offs[4] = {out.positions.offset, out.normals.offset, out.tangents.offset,
                                  out.uvs.buffer ? out.uvs.offset : 0};
    vkCmdBindVertexBuffers(s.cmd, 0, 4, bufs, offs);
    vkCmdBindIndexBuffer(s.cmd, s.jerseyIndices.buffer.get(), 0, VK_INDEX_TYPE_UINT32);
    vkCmdDrawIndexed(s.cmd, uint32_t(s.model.info().triangleIndices.size()), 1, 0, 0, 0);
  }
  vkCmdEndRendering(s.cmd);

  const auto toCopy =
      imageBarrier(s.color.image.get(), VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                   VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                   VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
  pipelineBarrier(s.cmd, {}, std::span(&toCopy, 1));
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {total, h, 1};
  vkCmdCopyImageToBuffer(s.cmd, s.color.image.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, s.readback.buffer.get(), 1,
                         &region);
  VkBufferMemoryBarrier2 toHost{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
  toHost.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
  toHost.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  toHost.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
  toHost.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
  toHost.srcQueueFamilyIndex = toHost.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  toHost.buffer = s.readback.buffer.get();
  toHost.size = VK_WHOLE_SIZE;
  pipelineBarrier(s.cmd, std::span(&toHost, 1), {});
  vkCheck(vkEndCommandBuffer(s.cmd), "vkEndCommandBuffer");
  s.submitAndWait();
  s.batch.retireFrame(s.frame);
  ++s.frame;

  PreviewImage img;
  img.width = total;
  img.height = h;
  img.rgba.resize(size_t(total) * h * 4);
  std::memcpy(img.rgba.data(), s.readback.data, img.rgba.size());
  return img;
}

void writePreviewPng(const std::string& path, const PreviewImage& image, const std::array<float, 3>& background) {
  io::PngImage png;
  png.width = image.width;
  png.height = image.height;
  png.channels = 3;
  png.bitDepth = 8;
  png.samples.resize(size_t(image.width) * image.height * 3);
  for (size_t p = 0; p < size_t(image.width) * image.height; ++p) {
    const float a = image.rgba[p * 4 + 3] / 255.f;
    for (int c = 0; c < 3; ++c) {
      const float bg = std::pow(background[c], 1.f / 2.2f) * 255.f;  // the clear colour as the shaders encode
      png.samples[p * 3 + c] = uint16_t(std::lround(image.rgba[p * 4 + c] * a + bg * (1.f - a)));
    }
  }
  io::writePng(path, png);
}

}  // namespace swish::render
