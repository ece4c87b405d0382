#pragma once
// glTF 2.0 export of meshes, with optional skin and normal-map texture, for previews, replays and the
// default character: binary (.glb), or JSON (.gltf) with the binary buffer embedded as a base64 data
// URI (same content). .glb files are written atomically (swish::writeFileAtomic).
//
// Each mesh becomes one node with one primitive: POSITION, NORMAL, TANGENT and TEXCOORD_0 when the
// Mesh has them, indices as uint32; a skinned mesh (with a skeleton in the scene) also gets
// JOINTS_0/WEIGHTS_0 (and JOINTS_1/WEIGHTS_1 beyond 4 influences) and the skin. The skeleton becomes
// joint nodes with their rest transforms and inverse bind matrices, so importCharacter reads back
// exactly what was written. Output is deterministic: same input, same bytes.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "swish/core/character.hpp"

namespace swish::io {

struct GltfMaterial {
  std::string name = "material";
  Vec4f baseColor = Vec4f(0.8f, 0.8f, 0.8f, 1.f);
  float roughness = 0.8f;
  // Tangent-space normal map as PNG bytes, embedded in the .glb (empty: none).
  std::vector<uint8_t> normalMapPng;
};

struct GltfMeshEntry {
  std::string name;
  const Mesh* mesh = nullptr;
  bool skinned = true;             // ignored when the scene has no skeleton
  std::optional<size_t> material;  // index into GltfScene::materials
  RigidTransform transform;        // node transform (unskinned meshes only; skinned ones follow the joints)
  // When set, the node's translation in double precision instead of transform.translation (unskinned
  // meshes only): a mesh kept local and placed 1e4 m away keeps its placement exact in the file.
  std::optional<Eigen::Vector3d> preciseTranslation = std::nullopt;
};

// A skeletal animation of GltfScene::skeleton: frame f at time f / framesPerSecond, every joint's
// local rotation and the root joints' translations (Pose::rootTranslation), linearly interpolated.
struct GltfAnimation {
  std::string name = "animation";
  float framesPerSecond = 30.f;
  const std::vector<Pose>* frames = nullptr;
};

struct GltfScene {
  const Skeleton* skeleton = nullptr;  // optional
  std::vector<GltfMeshEntry> meshes;
  std::optional<GltfAnimation> animation;  // needs the skeleton
  std::vector<GltfMaterial> materials;
  std::string generator = "swish";
};

std::vector<uint8_t> encodeGlb(const GltfScene& scene);
// Throws Error naming the path when it cannot be written (nothing half-written is left behind).
void writeGlb(const std::filesystem::path& file, const GltfScene& scene);
// The same scene as .gltf text: one JSON document, the buffer as a data:...;base64 URI (write it with
// swish::writeTextFileAtomic).
std::string encodeGltf(const GltfScene& scene);

// A character as the importer expects it: meshes "body" and "shirt" (garment) and, when present,
// "simulation", skinned to the skeleton; plain materials (the garment's with `garmentNormalMapPng`).
void writeCharacterGlb(const std::filesystem::path& file, const Character& character,
                       const std::vector<uint8_t>& garmentNormalMapPng = {});
std::vector<uint8_t> encodeCharacterGlb(const Character& character,
                                        const std::vector<uint8_t>& garmentNormalMapPng = {});

}  // namespace swish::io
