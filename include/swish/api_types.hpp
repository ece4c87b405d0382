#pragma once
// Plain data of the swish embedding API: device handles, poses, model descriptions and the GPU outputs
// of a frame with the synchronisation a renderer must use. No Eigen, no swish internals: Vulkan C
// handles, std containers and spans only.
#include <vulkan/vulkan.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace swish::api {

// A Vulkan device as a host renderer made it. swish never destroys these handles; the host keeps
// them alive as long as any swish object made on them lives.
struct DeviceHandles {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;  // swish submits its uploads (model load) and readbacks here
  uint32_t queueFamily = 0;        // must support compute; swish's outputs belong to this family
};

struct Quat {  // unit quaternion, x y z w (glTF order)
  float x = 0, y = 0, z = 0, w = 1;
};

using Mat4 = std::array<float, 16>;  // column-major 4x4, as GLSL and glTF store it
inline constexpr Mat4 kIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

// One character's pose for one frame.
struct CharacterPose {
  // Local (parent-relative) rotation of every skeleton joint, in ModelInfo::jointNames order. A
  // joint's rotation REPLACES its rest rotation (the rest pose is ModelInfo::restRotations).
  // Non-unit quaternions are normalised and NaN/zero ones replaced by the rest rotation; both are
  // listed in FrameReport::warnings, never silent.
  std::span<const Quat> localRotations;
  // The root joint's translation in character space; unset: its rest translation.
  std::optional<std::array<float, 3>> rootTranslation;
  // Character space -> world space; the deformed vertices come out in world space.
  Mat4 characterToWorld = kIdentity;
  // Seconds since this character's previous frame, for the normal-map temporal filter (0: paused).
  float dtSeconds = 1.f / 60.f;
};

// One quality level of a model (its ladder, full quality first): the leading PCA components its deform
// reads, whether it gets normal maps, and what the bake measured (NaN: not measured).
struct QualityLevelInfo {
  std::string name;
  uint32_t meshComponents = 0;  // 0: the mean shape skinned, no network
  bool normalMaps = false;
  float vertexMeanMm = NAN, vertexP95Mm = NAN, normalMeanDeg = NAN;
  float cpuMicrosecondsPerCharacter = NAN, gpuMicrosecondsPerCharacter = NAN;
};

// Let swish choose each character's level every frame from its size on screen
// (CharacterBatch::planQualityLevels): the cheapest level whose mean error on screen is within
// tolerancePixels, keeping a level at least holdFrames frames. The character's position is the
// translation of its CharacterPose::characterToWorld.
struct LevelPlanning {
  std::array<float, 3> cameraPosition{0, 1.7f, -5};
  std::array<float, 3> cameraTarget{0, 1, 0};
  float verticalFovDegrees = 50;
  float imageHeightPixels = 1080;
  float tolerancePixels = 0.5f;
  uint32_t holdFrames = 30;
};

// What a loaded model is: its skeleton (the order poses use), its mesh topology and its normal maps.
struct ModelInfo {
  std::string name;
  std::vector<std::string> jointNames;
  std::vector<int> jointParents;                       // -1 for a root; parents come first
  std::vector<Quat> restRotations;                     // the rest (A-)pose, per joint
  std::vector<std::array<float, 3>> restTranslations;  // per joint, relative to the parent
  std::vector<uint32_t> inputJoints;                   // joints the network reads (indices)
  // The network also reads the body's lean: the gravity direction in the root joint's frame, from the
  // root's rotation in the pose a host passes. A host whose character stands on a tilted floor or a
  // moving deck passes the root's rotation relative to gravity.
  bool rootGravity = false;
  uint32_t vertexCount = 0;
  uint32_t triangleCount = 0;
  std::vector<float> restPositions;       // 3 per vertex, the rest pose in character space (bounds, culling)
  std::vector<uint32_t> triangleIndices;  // 3 per triangle, counter-clockwise seen from outside
  std::vector<float> uvs;                 // 2 per vertex (empty when the model has none)
  bool hasNormalMaps = false;
  uint32_t normalMapWidth = 0, normalMapHeight = 0, normalMapDatabaseSize = 0;
  float temporalFilterSeconds = 0;  // the normal-map filter's time constant
  uint32_t bodyAnchors = 0;         // garment vertices anchored to the body for the push-out (0: no push-out)
  // The novelty guard (models of format 1.2): FrameReport::novelty is measured per character, and a
  // character above noveltyFlagAbove is in FrameReport::novelCharacters. Novelty 1 is the sparse edge
  // of the poses the model was trained on.
  bool hasNoveltyGuard = false;
  // The triangles of the body the model was baked on that the garment covers in (nearly) every training pose
  // (ascending): a host drawing that body (coveredBodyOf triangles) may leave them out, as games do
  // under tight clothing, so the body can never show through. Empty: not computed.
  uint32_t coveredBodyOf = 0;
  std::vector<uint32_t> coveredBodyTriangles;
  float noveltyFlagAbove = 0, noveltyBlendStart = 0, noveltyBlendEnd = 0;
  // Quality levels, level 0 full quality (CharacterBatch::setQualityLevel, planQualityLevels).
  std::vector<QualityLevelInfo> qualityLevels;
};

// One vertex attribute of the deformed mesh. Character c's vertices start at
// offset + c * instanceStride; vertex v at + v * stride.
struct VertexStream {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceSize offset = 0;
  VkDeviceSize instanceStride = 0;  // 0 for data shared by all characters (UVs)
  uint32_t stride = 0;
  VkFormat format = VK_FORMAT_UNDEFINED;
};

// The per-character tangent-space normal maps of a frame: one layer per character of a 2D array
// image. Texels hold tangent-space X and Y; reconstruct Z = sqrt(max(0, 1 - X^2 - Y^2)).
struct NormalMapOutput {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;  // VK_IMAGE_VIEW_TYPE_2D_ARRAY over every layer, for sampling
  VkImageViewType viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
  VkFormat format = VK_FORMAT_UNDEFINED;             // VK_FORMAT_R16G16_SNORM
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;  // VK_IMAGE_LAYOUT_GENERAL, always; never transition it
  VkImageUsageFlags usage = 0;                       // includes SAMPLED
  VkImageSubresourceRange range{};
  uint32_t width = 0, height = 0, layers = 0;
};

// The GPU outputs of one recorded frame, valid until that frame's resources are reused (frame
// frameIndex + framesInFlight). Read them only after the barriers below, in a submission after (or
// the same as) the one holding swish's commands, on the same queue (or after a queue-family
// ownership transfer built with the same barriers).
struct FrameOutputs {
  uint64_t frameIndex = 0;
  uint32_t characters = 0, vertexCount = 0;
  // Draw with ModelInfo::triangleIndices in an index buffer of your own (uint32, triangle list).
  VertexStream positions;                     // R32G32B32_SFLOAT, world space
  VertexStream normals;                       // R32G32B32_SFLOAT, unit, world space
  VertexStream tangents;                      // R32G32B32A32_SFLOAT: xyz unit tangent (world), w = bitangent sign
  VertexStream uvs;                           // R32G32_SFLOAT (buffer VK_NULL_HANDLE when the model has no UVs)
  VkBufferUsageFlags bufferUsage = 0;         // VERTEX_BUFFER | STORAGE_BUFFER | TRANSFER_SRC | TRANSFER_DST
  std::optional<NormalMapOutput> normalMaps;  // absent for a model without maps or a batch without them
  uint32_t queueFamily = 0;                   // the family swish's resources belong to (exclusive sharing)

  // What swish's passes end with: compute-shader storage writes.
  static constexpr VkPipelineStageFlags2 kSrcStage = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
  static constexpr VkAccessFlags2 kSrcAccess = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;

  // The barriers a renderer records after swish's commands and before it reads the outputs: vertex
  // buffers -> vertex attribute input (or dstStage/dstAccess of its choice, e.g. a compute skinning
  // pass reading them as storage), normal maps -> fragment-shader sampled reads, layout unchanged.
  // dstQueueFamily other than queueFamily makes them an ownership transfer: record the same barriers
  // once in swish's command buffer (release, on swish's queue) and once in the renderer's (acquire).
  std::vector<VkBufferMemoryBarrier2> vertexBarriers(
      uint32_t dstQueueFamily = VK_QUEUE_FAMILY_IGNORED,
      VkPipelineStageFlags2 dstStage = VK_PIPELINE_STAGE_2_VERTEX_ATTRIBUTE_INPUT_BIT,
      VkAccessFlags2 dstAccess = VK_ACCESS_2_VERTEX_ATTRIBUTE_READ_BIT) const;
  std::optional<VkImageMemoryBarrier2> normalMapBarrier(
      uint32_t dstQueueFamily = VK_QUEUE_FAMILY_IGNORED,
      VkPipelineStageFlags2 dstStage = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
      VkAccessFlags2 dstAccess = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT) const;
};

// What recordFrame saw in the host's data: nothing stops a frame, nothing is silent.
struct FrameReport {
  uint64_t frameIndex = 0;
  std::vector<std::string> warnings;  // renormalised / replaced quaternions, bad dt, non-finite codes
  double cpuMilliseconds = 0;         // network, lookup and filter on the CPU for all characters
  // Per character: how far its pose is from the poses the model was trained on (NaN: the model has no
  // guard), and how far the guard blended its shape towards the mean shape (0: not at all, 1: fully).
  std::vector<float> novelty, guardBlend;
  std::vector<uint32_t> novelCharacters;  // novelty above ModelInfo::noveltyFlagAbove
  std::vector<uint32_t> qualityLevels;    // per character: the level it was recorded at (ModelInfo::qualityLevels)
};

// GPU time of each pass of a retired frame in milliseconds (NaN: not run or no timestamps).
struct GpuTimes {
  double deform = 0, tangentFrames = 0, normalMapDecode = 0, normalMapBlend = 0, total = 0;
};

// One character's deformed mesh read back to the host (tests, tools, exporters).
struct DeformedMesh {
  std::vector<float> positions;  // 3 per vertex
  std::vector<float> normals;    // 3 per vertex
  std::vector<float> tangents;   // 4 per vertex
  std::vector<float> uvs;        // 2 per vertex (empty without UVs)
};

}  // namespace swish::api
