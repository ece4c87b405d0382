#pragma once
// Pictures of a dataset for a person to look at: for each chosen pose, a front view (orthographic,
// looking down -Z at a character that faces +Z, Y up) of the posed game mesh shaded with its baked
// normal map, the normal map itself as an 8-bit PNG, and a residual summary (preview.json).
#include <filesystem>
#include <vector>

#include "swish/bake/dataset/dataset.hpp"

namespace swish::bake {

// Renders the game mesh (positions = one pose's gameMeshWorld) with the garment's UVs and triangles,
// Lambert-shaded with `normalMap` (nearest texel) in the tangent frame of core/mesh_frames.hpp.
// Returns an 8-bit RGB image, background grey; size x size pixels.
struct PreviewImage {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgb;
};
PreviewImage renderShadedFrontView(const Mesh& garment, const Points3f& positions, const NormalMapImage& normalMap,
                                   uint32_t size = 512);

// Writes <folder>/pose_<id>_front.png, pose_<id>_normal_map.png for up to maxPoses poses spread over
// the dataset, and preview.json (per pose residuals and normal-map statistics). Returns files written.
std::vector<std::filesystem::path> writeDatasetPreview(const Dataset& dataset, const std::filesystem::path& folder,
                                                       size_t maxPoses = 4, uint32_t size = 512);

}  // namespace swish::bake
