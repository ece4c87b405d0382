#pragma once
// Plain triangle meshes from glTF (.glb/.gltf), FBX and the other formats assimp reads: the shapes a
// cloth tool writes (bake/cloth/external_simulation.hpp reads OBJ itself, keeping its vertex order). Skins
// and materials are ignored. glTF keeps its vertex order and count; FBX and the rest are unrolled per
// face corner by assimp and identical vertices joined again, so their order is assimp's.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "swish/core/types.hpp"

namespace swish::io {

struct ImportedMesh {
  std::string name;    // the mesh's name, else its node's
  Points3f positions;  // the file's units, node transforms applied (where the file places it)
  Triangles triangles;
  // Morph targets / blend shapes (a geometry cache stored as one shape per frame), absolute positions
  // in the same vertex order and space, in file order, each with its name (may be empty).
  std::vector<std::pair<std::string, Points3f>> frames;
};

// Every mesh of the file that has triangles, in file order (one per glTF primitive). Throws Error
// naming the file: missing, unreadable, corrupt, or holding no triangle mesh.
std::vector<ImportedMesh> importMeshes(const std::filesystem::path& file);

}  // namespace swish::io
