// The smallest host of swish: it makes its own Vulkan device (as a renderer would), hands it to swish,
// loads a model, records a few frames of swish's passes into ITS OWN command buffers with two frames
// in flight, and reads one deformed vertex back. Only the public header swish/swish.hpp is used.
// Walkthrough: docs/integration.md.   Usage: minimal_host MODEL.swish
#include <cmath>
#include <cstdio>
#include <vector>

#include "swish/swish.hpp"

namespace {

void check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed: VkResult " + std::to_string(int(r)));
}

struct HostVulkan {  // what the host renderer already has
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physicalDevice = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;

  HostVulkan() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "minimal swish host";
    app.apiVersion = VK_API_VERSION_1_3;  // swish needs Vulkan 1.3
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    check(vkCreateInstance(&ici, nullptr, &instance), "vkCreateInstance");
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> devices(n);
    vkEnumeratePhysicalDevices(instance, &n, devices.data());
    for (VkPhysicalDevice pd : devices) {
      if (!swish::api::unsuitableReason(pd).empty()) continue;  // swish says why a device cannot run it
      uint32_t nf = 0;
      vkGetPhysicalDeviceQueueFamilyProperties(pd, &nf, nullptr);
      std::vector<VkQueueFamilyProperties> fams(nf);
      vkGetPhysicalDeviceQueueFamilyProperties(pd, &nf, fams.data());
      for (uint32_t f = 0; f < nf && !physicalDevice; ++f)
        if ((fams[f].queueFlags & (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT)) ==
            (VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT))
          physicalDevice = pd, family = f;
      if (physicalDevice) break;
    }
    if (!physicalDevice)
      throw std::runtime_error("no Vulkan 1.3 device with a graphics+compute queue that can run swish");
    // The host's own features go into the same structs; swish adds what it needs.
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.synchronization2 = VK_TRUE;  // this host uses vkCmdPipelineBarrier2
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES, &f13};
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &f12};
    swish::api::enableRequiredFeatures(physicalDevice, features, f12, f13);
    const float priority = 1.f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = family;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &features};
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    check(vkCreateDevice(physicalDevice, &dci, nullptr, &device), "vkCreateDevice");
    vkGetDeviceQueue(device, family, 0, &queue);
  }
  ~HostVulkan() {
    if (device) vkDestroyDevice(device, nullptr);
    if (instance) vkDestroyInstance(instance, nullptr);
  }
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s MODEL.swish\n", argv[0]);
    return 2;
  }
  try {
    HostVulkan host;
    constexpr uint32_t kFramesInFlight = 2;
    // Inner scope: every swish object is gone before the host destroys its device.
    {
      swish::api::Runtime runtime =
          swish::api::Runtime::adopt({host.instance, host.physicalDevice, host.device, host.queue, host.family});
      swish::api::Model model = runtime.loadModel(argv[1]);
      const swish::api::ModelInfo& info = model.info();
      std::printf("model %s: %u vertices, %zu joints, normal maps %s, on %s\n", info.name.c_str(), info.vertexCount,
                  info.jointNames.size(), info.hasNormalMaps ? "yes" : "no", runtime.deviceName().c_str());
      swish::api::CharacterBatch batch = model.createBatch({.characters = 1, .framesInFlight = kFramesInFlight});

      // The host's per-frame command buffers and fences.
      VkCommandPoolCreateInfo pci{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
      pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
      pci.queueFamilyIndex = host.family;
      VkCommandPool pool;
      check(vkCreateCommandPool(host.device, &pci, nullptr, &pool), "vkCreateCommandPool");
      VkCommandBuffer cmds[kFramesInFlight];
      VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
      ai.commandPool = pool;
      ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
      ai.commandBufferCount = kFramesInFlight;
      check(vkAllocateCommandBuffers(host.device, &ai, cmds), "vkAllocateCommandBuffers");
      VkFence fences[kFramesInFlight];
      for (VkFence& f : fences) {
        VkFenceCreateInfo fci{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        fci.flags = VK_FENCE_CREATE_SIGNALED_BIT;
        check(vkCreateFence(host.device, &fci, nullptr, &f), "vkCreateFence");
      }

      std::vector<swish::api::Quat> rotations = info.restRotations;
      const uint64_t frames = 5;
      for (uint64_t frame = 0; frame < frames; ++frame) {
        const uint32_t slot = uint32_t(frame % kFramesInFlight);
        // 1. Wait until the GPU is done with this slot's previous frame, and tell swish.
        check(vkWaitForFences(host.device, 1, &fences[slot], VK_TRUE, UINT64_MAX), "vkWaitForFences");
        check(vkResetFences(host.device, 1, &fences[slot]), "vkResetFences");
        if (frame >= kFramesInFlight) batch.retireFrame(frame - kFramesInFlight);
        // 2. This frame's pose: the rest pose with the spine bending a little more each frame.
        const float angle = 0.1f * float(frame);
        rotations[info.inputJoints[0]] = {std::sin(angle / 2), 0.f, 0.f, std::cos(angle / 2)};
        swish::api::CharacterPose pose;
        pose.localRotations = rotations;
        pose.dtSeconds = 1.f / 60.f;
        // 3. Record swish's passes into the host's command buffer, then the consumer barriers.
        VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        check(vkBeginCommandBuffer(cmds[slot], &bi), "vkBeginCommandBuffer");
        const swish::api::FrameReport report = batch.recordFrame(cmds[slot], frame, {&pose, 1});
        for (const auto& w : report.warnings) std::printf("frame %llu: %s\n", (unsigned long long)frame, w.c_str());
        const swish::api::FrameOutputs out = batch.outputs(frame);
        const auto bufferBarriers = out.vertexBarriers();
        const auto mapBarrier = out.normalMapBarrier();
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.bufferMemoryBarrierCount = uint32_t(bufferBarriers.size());
        dep.pBufferMemoryBarriers = bufferBarriers.data();
        dep.imageMemoryBarrierCount = mapBarrier ? 1 : 0;
        dep.pImageMemoryBarriers = mapBarrier ? &*mapBarrier : nullptr;
        vkCmdPipelineBarrier2(cmds[slot], &dep);
        // 4. A renderer draws here: vertex buffers out.positions/normals/tangents/uvs (per-attribute
        //    bindings at the given offsets and strides), index buffer from info.triangleIndices, and
        //    out.normalMaps->view sampled in layout out.normalMaps->layout (GENERAL), layer = character.
        check(vkEndCommandBuffer(cmds[slot]), "vkEndCommandBuffer");
        VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
        si.commandBufferCount = 1;
        si.pCommandBuffers = &cmds[slot];
        check(vkQueueSubmit(host.queue, 1, &si, fences[slot]), "vkQueueSubmit");
      }
      check(vkWaitForFences(host.device, kFramesInFlight, fences, VK_TRUE, UINT64_MAX), "vkWaitForFences");
      batch.retireFrame(frames - 1);

      const swish::api::DeformedMesh mesh = batch.readBackMesh(frames - 1, 0);
      std::printf("frame %llu, vertex 0: position (%.4f, %.4f, %.4f) normal (%.4f, %.4f, %.4f)\n",
                  (unsigned long long)(frames - 1), mesh.positions[0], mesh.positions[1], mesh.positions[2],
                  mesh.normals[0], mesh.normals[1], mesh.normals[2]);
      const float len = std::sqrt(mesh.normals[0] * mesh.normals[0] + mesh.normals[1] * mesh.normals[1] +
                                  mesh.normals[2] * mesh.normals[2]);
      for (VkFence f : fences) vkDestroyFence(host.device, f, nullptr);
      vkDestroyCommandPool(host.device, pool, nullptr);
      if (!std::isfinite(mesh.positions[0]) || std::abs(len - 1.f) > 1e-3f) {
        std::fprintf(stderr, "unexpected vertex: not finite, or its normal is not unit\n");
        return 1;
      }
    }
    return 0;
  } catch (const swish::api::Error& e) {
    std::fprintf(stderr, "swish error (%s): %s\n", swish::api::errorCodeName(e.code()), e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}
