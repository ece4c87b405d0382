#pragma once
// The GPU resources of ONE frame in flight of a FrameRecorder: the per-frame inputs (host-visible,
// written by the CPU each frame), the outputs (device-local: deformed positions, normals, tangents,
// the decoded-map slots and the per-character normal maps), the descriptor sets that bind them to the
// passes (made once) and the frame's timestamp queries.
// A frame in flight owns its outputs: while the host renderer still reads frame f's outputs, frame
// f + 1 writes another FrameResources.
//
// Output layouts for a renderer (one vertex stream per attribute, instance i at byte offset
// i * vertexCount * stride): positions and normals R32G32B32_SFLOAT (stride 12), tangents
// R32G32B32A32_SFLOAT (stride 16, w = bitangent sign); UVs are the model's (GpuModel::uvs).
// Every buffer has STORAGE | VERTEX | TRANSFER | texel-buffer usage; normal maps are described in
// normal_map_images.hpp.
#include <cstdint>
#include <vector>

#include "swish/gpu/buffer.hpp"
#include "swish/gpu/descriptor_binding.hpp"
#include "swish/gpu/normal_map_images.hpp"
#include "swish/gpu/timestamp_queries.hpp"
#include "swish/gpu/vk_unique.hpp"

namespace swish::gpu {

class Context;
class GpuModel;

struct FrameResources {
  FrameResources() = default;
  // withNormalMaps: allocate the decode slots and per-character images (the model must have a database);
  // shareTexels: lay the images over the blend's output where the device allows it (NormalMapImages).
  FrameResources(Context& ctx, const GpuModel& model, uint32_t instanceCapacity, bool withTangentFrames,
                 bool withNormalMaps, uint32_t slot, bool shareTexels = true);

  // Inputs, written by FrameRecorder::record.
  Buffer meshWeights;     // float[instances][K4] (DeformPass::packWeights), zero beyond each instance's k
  Buffer instanceOrder;   // uint[instances]: the deform's instances by quality band (DeformPass::packLevels)
  Buffer skinMatrices;    // vec4[instances][joints][3] (DeformPass::packSkinMatrices)
  Buffer decodeSlotMaps;  // the VQ decode jobs: uint[2][instances], maps then the slots they go to
  // layout::NormalMapBlendCharacter[instances], then uint[instances]: the layer of each (the blend's
  // characters are the instances with a map this frame)
  Buffer blendCharacters;
  // Outputs.
  Buffer positions;            // float[instances][N][3]
  Buffer normals;              // float[instances][N][3]
  Buffer tangents;             // float[instances][N][4]
  Buffer decodedMaps;          // uint16[slots][H][W] (snorm8 X | Y << 8): decoded database maps, one slot per instance
  Buffer triangleTerms;        // vec4[instances][T][3], scratch of the two-pass tangent frames
  NormalMapImages normalMaps;  // one layer per instance
  // uint32[instances][H][W] (snorm16 X | Y << 16): the blend's output, copied into normalMaps; empty
  // where normalMaps.sharesTexels() (the blend writes normalMaps.texels(), the images' own memory).
  Buffer blendedTexels;
  // Where the blend writes (and the next frame's blend reads): normalMaps.texels() or blendedTexels.
  const Buffer& blendOutput() const { return normalMaps.sharesTexels() ? normalMaps.texels() : blendedTexels; }
  DescriptorBinding deformInputs;   // meshWeights, skinMatrices
  DescriptorBinding tangentFrames;  // positions, triangleTerms, the model's adjacency, normals, tangents
  DescriptorBinding blendBinding;   // prev frame's blendOutput() -> this frame's blendOutput(), decodedMaps

  // Which database map each slot of decodedMaps holds (kNoMap: none yet) and the last frame that
  // selected it. Database maps never change, so a decoded slot stays valid until it is given to another
  // map: a frame decodes only the maps not already in a slot (FrameRecorder::record).
  static constexpr uint32_t kNoMap = 0xFFFFFFFFu;
  std::vector<uint32_t> slotMap;
  std::vector<uint64_t> slotLastUsed;
  // Per layer of normalMaps (and of blendOutput()): the version of that instance's map it holds
  // (FrameRecorder counts a version per blend or upload; kUnknownVersion: not known). An instance
  // without a map this frame keeps its map: its layer here is brought to the current version by a copy
  // from a slot that holds it, unless it holds it already (always with one frame in flight).
  static constexpr uint64_t kUnknownVersion = ~uint64_t(0);
  std::vector<uint64_t> layerVersion;
  TimestampQueries timestamps;

  // What the last record() into this frame did (for readback and timings).
  uint32_t instanceCount = 0;
  uint32_t decodedSlotCount = 0;  // distinct maps the frame selected (slots it read)
  uint32_t decodeJobCount = 0;    // of those, maps it decoded (not already in a slot)
  uint32_t blendedCount = 0;      // instances whose map it blended (those with a map this frame)
  uint32_t carriedLayers = 0;     // layers of instances without a map it copied from another slot
  bool recordedTangentFrames = false;
  bool recordedNormalMaps = false;
};

}  // namespace swish::gpu
