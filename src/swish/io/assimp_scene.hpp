#pragma once
// Shared assimp plumbing of the character and animation importers (private to io/: it exposes assimp
// types). Reads a file with the flags swish wants and turns assimp's failures into swish::Error.
#include <assimp/scene.h>

#include <Eigen/Core>
#include <assimp/Importer.hpp>
#include <filesystem>

namespace swish::io {

// Throws Error naming the file when it is missing, unreadable, or assimp cannot make a scene of it.
// UVs come out in glTF's convention (v = 0 at the top of the image) whatever the format; glTF files
// keep their vertex order and count (no vertex joining), other formats get identical vertices joined.
// animationOnly: a file with animation but no meshes (assimp flags those incomplete) is accepted.
const aiScene& readAssimpScene(Assimp::Importer& importer, const std::filesystem::path& file,
                               bool animationOnly = false);

inline Eigen::Matrix4d toEigen(const aiMatrix4x4& m) {
  Eigen::Matrix4d e;
  e << m.a1, m.a2, m.a3, m.a4, m.b1, m.b2, m.b3, m.b4, m.c1, m.c2, m.c3, m.c4, m.d1, m.d2, m.d3, m.d4;
  return e;
}

}  // namespace swish::io
