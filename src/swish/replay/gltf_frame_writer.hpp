#pragma once
// Per-frame meshes of a replay as glTF 2.0 (.gltf, JSON with the binary buffer embedded as a base64
// data URI): one mesh and one node per on-screen character, the vertices in CHARACTER space and the
// placement (yaw + translation, the translation in double) on the node, so that a character at 1e4 m
// keeps its local precision in the file. Positions, normals when the frame has them, UVs and the
// model's triangles. Written by io/gltf_export; this adapts the replay's per-frame data to it.
#include <filesystem>
#include <string>
#include <vector>

#include "swish/core/mesh.hpp"
#include "swish/runtime/scene.hpp"

namespace swish::replay {

struct GltfCharacterMesh {
  std::string name;
  runtime::ScenePlacement placement;
  const Points3f* positions = nullptr;
  const Points3f* normals = nullptr;  // may be null; left out unless one per position
  const Points2f* uvs = nullptr;      // may be null; left out unless one per position
  const Triangles* triangles = nullptr;
};

// Writes atomically; throws Error naming the file.
void writeGltfFrame(const std::filesystem::path& file, const std::vector<GltfCharacterMesh>& characters);

}  // namespace swish::replay
