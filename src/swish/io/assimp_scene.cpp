#include "swish/io/assimp_scene.hpp"

#include <assimp/config.h>
#include <assimp/postprocess.h>

#include <algorithm>
#include <system_error>

#include "swish/core/error.hpp"

namespace swish::io {

const aiScene& readAssimpScene(Assimp::Importer& importer, const std::filesystem::path& path, bool animationOnly) {
  const std::string file = path.string();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(file + ": no such file");
  if (!std::filesystem::is_regular_file(path, ec)) throw Error(file + ": not a regular file");
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  const bool gltf = ext == ".glb" || ext == ".gltf";
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  unsigned flags = aiProcess_Triangulate | aiProcess_FlipUVs | aiProcess_ValidateDataStructure;
  if (!gltf) flags |= aiProcess_JoinIdenticalVertices;
  const aiScene* scene = importer.ReadFile(file, flags);
  if (!scene || !scene->mRootNode) {
    const std::string why = importer.GetErrorString();
    throw Error(file + ": cannot read (" + (why.empty() ? "unknown format or corrupt file" : why) + ")");
  }
  if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) && !(animationOnly && scene->mNumAnimations > 0))
    throw Error(file + ": the file is incomplete or corrupt (assimp could only read part of it)");
  return *scene;
}

}  // namespace swish::io
