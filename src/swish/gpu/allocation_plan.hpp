#pragma once
// The GPU memory of a model and of one frame in flight, by name and size, known without a device.
// GpuModel and FrameResources size their buffers with the functions below (the same code, not a copy),
// so what `swish replay --plan` announces is what the replay allocates; tests/e2e/test_replay.cpp
// compares the two buffer by buffer on a device.
#include <cstdint>
#include <string>
#include <vector>

#include "swish/model/model.hpp"

namespace swish::gpu {

struct Allocation {
  std::string name;    // the buffer's name on the device, without the "<model>: " prefix
  uint64_t bytes = 0;  // the bytes allocated (gpu::Buffer rounds 0 up to 4)
  bool image = false;  // an image's texels (width x height x layers x 4 bytes), not a buffer
};

// What GpuModel(ctx, model, name, withNormalMaps) uploads, in upload order. `model` must be one that
// Model::validate accepts (the upload's own structure checks are not repeated here).
std::vector<Allocation> modelAllocations(const Model& model, bool withNormalMaps);

// What one FrameResources for `instances` instances of `model` allocates. shareTexels: the device lays
// the normal-map images over the blend's output (NormalMapImages::sharesTexels), so there is no
// separate blended-maps buffer; without a device that is not known, and false gives the upper bound.
std::vector<Allocation> frameAllocations(const Model& model, uint32_t instances, bool tangentFrames, bool normalMaps,
                                         bool shareTexels);

}  // namespace swish::gpu
