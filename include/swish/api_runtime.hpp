#pragma once
// The swish embedding API: a Runtime on a Vulkan device (the host's, or one swish makes), Models loaded
// on it, and CharacterBatches that record each frame's swish passes into the host's command buffer.
//
//   Runtime rt = Runtime::adopt(myDevice);              // or Runtime::create()
//   Model m = rt.loadModel("jersey.swish");
//   CharacterBatch b = m.createBatch({.characters = 22, .framesInFlight = 2});
//   per frame f:  wait for my fence of frame f - 2, then b.retireFrame(f - 2);
//                 b.recordFrame(cmd, f, poses);         // into MY command buffer, before my draws
//                 FrameOutputs out = b.outputs(f);      // buffers, images, barriers
//                 vkCmdPipelineBarrier2(cmd, ... out.vertexBarriers(), out.normalMapBarrier() ...);
//                 draw with out.positions/normals/tangents/uvs and out.normalMaps; submit with my fence
//
// Threading: one object is used by one thread at a time; different Runtimes (on different devices,
// or twice on one) are independent: the API has no global state.
// Lifetime: Runtime and Model are shared handles (copies refer to the same object, which lives until
// the last copy and every batch made from it are gone). Destroy a CharacterBatch only when the GPU no
// longer uses it: after retiring every frame it recorded (idle()).
// Errors: every call may throw swish::api::Error (api_error.hpp); try* variants return Result<T>.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "swish/api_error.hpp"
#include "swish/api_types.hpp"

namespace swish::api {

struct RuntimeOptions {
  std::string device;       // Runtime::create only: device index or name substring; "" = SWISH_DEVICE or automatic
  bool validation = false;  // Runtime::create only: VK_LAYER_KHRONOS_validation, messages collected
  std::string applicationName = "swish";
};

// What a host must enable on a device it creates for swish: Vulkan 1.3 with these features, and a
// queue family with compute (graphics + compute is simplest: one queue for everything).
// enableRequiredFeatures sets swish's features to VK_TRUE in the given structs (chain them into
// VkDeviceCreateInfo::pNext: features2 -> vulkan12 -> vulkan13); it leaves other members as they are.
// unsuitableReason returns "" when the physical device can run swish, else why it cannot.
void enableRequiredFeatures(VkPhysicalDevice physicalDevice, VkPhysicalDeviceFeatures2& features,
                            VkPhysicalDeviceVulkan12Features& vulkan12, VkPhysicalDeviceVulkan13Features& vulkan13);
std::string unsuitableReason(VkPhysicalDevice physicalDevice);

class Model;
class CharacterBatch;
struct RuntimeImpl;
struct ModelImpl;
struct BatchImpl;

class Runtime {
 public:
  // swish makes its own headless instance and device (DeviceUnsupported when it cannot).
  static Runtime create(const RuntimeOptions& options = {});
  static Result<Runtime> tryCreate(const RuntimeOptions& options = {}) noexcept;
  // swish runs on the host's device (see enableRequiredFeatures); the host owns the handles and
  // must not use `queue` from another thread while swish loads a model or reads back.
  static Runtime adopt(const DeviceHandles& host);
  static Result<Runtime> tryAdopt(const DeviceHandles& host) noexcept;

  DeviceHandles device() const;
  std::string deviceName() const;
  bool ownsDevice() const;
  bool supportsNormalMaps() const;  // storage images of R16G16_SNORM on this device

  // Reads and fully checks a .swish file, then uploads it (waits for the upload on the queue).
  Model loadModel(const std::filesystem::path& path) const;
  Result<Model> tryLoadModel(const std::filesystem::path& path) const noexcept;
  Model loadModelFromMemory(std::span<const uint8_t> fileBytes, const std::string& name) const;

  // Validation messages collected when swish made the device with validation on (else empty).
  std::vector<std::string> validationMessages() const;
  void clearValidationMessages() const;

  explicit Runtime(std::shared_ptr<RuntimeImpl> impl);
  const std::shared_ptr<RuntimeImpl>& impl() const { return impl_; }

 private:
  std::shared_ptr<RuntimeImpl> impl_;
};

struct BatchOptions {
  uint32_t characters = 1;      // characters of this model drawn per frame
  uint32_t framesInFlight = 2;  // 1..8: sets of frame resources; frame f uses set f % framesInFlight
  bool normalMaps = true;       // per-character normal maps (ignored when the model or device has none)
  // Keep the deformed garment off the body the model was baked on (a step at the end of the deform
  // pass): each vertex stays outside the ball of its body anchor (the largest ball inside the rest
  // body that touches it at the vertex's closest point, skinned with the body's weights there;
  // ModelInfo::bodyAnchors), a margin off it, so the body the host draws does not show through where
  // the network puts the cloth inside it. No effect for a model without anchors (formats before 1.3: `swish body-proxy`
  // adds them).
  bool pushOut = false;
  // The model's novelty guard (ModelInfo::hasNoveltyGuard): clamp the mesh weights to the range seen in
  // training and blend towards the mean shape as a pose grows novel. Novelty is reported either way.
  bool noveltyGuard = true;
};

class Model {
 public:
  const ModelInfo& info() const;
  // Skinning matrices of a pose (jointNames order), world space: characterToWorld * global * inverseBind.
  // For hosts that skin other meshes (the body) on the same skeleton.
  std::vector<Mat4> skinningMatrices(const CharacterPose& pose) const;
  CharacterBatch createBatch(const BatchOptions& options = {}) const;

  explicit Model(std::shared_ptr<ModelImpl> impl);
  const std::shared_ptr<ModelImpl>& impl() const { return impl_; }

 private:
  std::shared_ptr<ModelImpl> impl_;
};

class CharacterBatch {
 public:
  CharacterBatch(CharacterBatch&&) noexcept;
  CharacterBatch& operator=(CharacterBatch&&) noexcept;
  ~CharacterBatch();

  uint32_t characters() const;
  uint32_t framesInFlight() const;

  // Evaluates the network for every character (poses.size() == characters()) and records the deform,
  // tangent-frame and normal-map passes into `cmd` (begun by the host, not submitted by swish).
  // frameIndex: 0 first, then +1 per call (each frame's normal-map filter reads the previous frame's
  // maps). FrameInFlight error if frame frameIndex - framesInFlight was recorded and not retired:
  // its resources may still be read by the GPU. On any error nothing was recorded.
  FrameReport recordFrame(VkCommandBuffer cmd, uint64_t frameIndex, std::span<const CharacterPose> poses);
  // The host's fence (or timeline semaphore) for the submission holding frame frameIndex has
  // signalled: its resources may be reused. Retiring a frame also retires every earlier one.
  void retireFrame(uint64_t frameIndex);
  bool idle() const;  // every recorded frame retired

  // The outputs of a recorded frame still held (one of the last framesInFlight recorded).
  FrameOutputs outputs(uint64_t frameIndex) const;
  // After retirement: GPU time per pass, and the deformed mesh / normal map of one character read back
  // (waits on the runtime's queue). Normal map: X, Y snorm16 pairs, row-major (empty without maps).
  GpuTimes gpuTimes(uint64_t frameIndex) const;
  DeformedMesh readBackMesh(uint64_t frameIndex, uint32_t character) const;
  std::vector<int16_t> readBackNormalMap(uint64_t frameIndex, uint32_t character) const;

  // The character's next frame starts without history (teleport, respawn): no temporal blend.
  void resetCharacter(uint32_t character);

  // Quality levels (ModelInfo::qualityLevels; every character starts at level 0, full quality). A host
  // with its own LOD system sets each character's level; from then on that character stays at it.
  // InvalidArgument for a character or level out of range.
  void setQualityLevel(uint32_t character, uint32_t level);
  uint32_t qualityLevel(uint32_t character) const;
  // Or swish chooses, every frame, the level of each character the host has not set (LevelPlanning).
  void planQualityLevels(const LevelPlanning& planning);

  explicit CharacterBatch(std::unique_ptr<BatchImpl> impl);

 private:
  std::unique_ptr<BatchImpl> impl_;
};

}  // namespace swish::api
