#include "swish/io/mesh_import.hpp"

#include <functional>

#include "swish/core/error.hpp"
#include "swish/io/assimp_scene.hpp"

namespace swish::io {

std::vector<ImportedMesh> importMeshes(const std::filesystem::path& file) {
  Assimp::Importer importer;
  const aiScene& scene = readAssimpScene(importer, file);
  // Where each mesh is placed: the global transform of the first node that uses it.
  std::vector<Eigen::Matrix4d> placement(scene.mNumMeshes, Eigen::Matrix4d::Zero());
  std::vector<std::string> nodeName(scene.mNumMeshes);
  std::function<void(const aiNode*, const Eigen::Matrix4d&)> walk = [&](const aiNode* n,
                                                                        const Eigen::Matrix4d& parent) {
    const Eigen::Matrix4d g = parent * toEigen(n->mTransformation);
    for (unsigned k = 0; k < n->mNumMeshes; ++k)
      if (n->mMeshes[k] < scene.mNumMeshes && placement[n->mMeshes[k]](3, 3) == 0.0) {
        placement[n->mMeshes[k]] = g;
        nodeName[n->mMeshes[k]] = n->mName.C_Str();
      }
    for (unsigned c = 0; c < n->mNumChildren; ++c) walk(n->mChildren[c], g);
  };
  walk(scene.mRootNode, Eigen::Matrix4d::Identity());

  std::vector<ImportedMesh> out;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh& a = *scene.mMeshes[m];
    if (!(a.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || a.mNumVertices == 0) continue;
    const Eigen::Matrix4d g = placement[m](3, 3) == 0.0 ? Eigen::Matrix4d::Identity() : placement[m];
    auto place = [&](const aiVector3D* v, unsigned count) {
      Points3f p(Eigen::Index(count), 3);
      for (unsigned i = 0; i < count; ++i) {
        const Eigen::Vector4d x = g * Eigen::Vector4d(v[i].x, v[i].y, v[i].z, 1.0);
        p.row(Eigen::Index(i)) = x.head<3>().cast<float>().transpose();
      }
      return p;
    };
    ImportedMesh im;
    im.name = a.mName.length ? a.mName.C_Str() : nodeName[m];
    im.positions = place(a.mVertices, a.mNumVertices);
    std::vector<uint32_t> tris;
    for (unsigned f = 0; f < a.mNumFaces; ++f)
      if (a.mFaces[f].mNumIndices == 3) tris.insert(tris.end(), a.mFaces[f].mIndices, a.mFaces[f].mIndices + 3);
    im.triangles = Eigen::Map<const Triangles>(tris.data(), Eigen::Index(tris.size() / 3), 3);
    for (unsigned k = 0; k < a.mNumAnimMeshes; ++k) {
      const aiAnimMesh& am = *a.mAnimMeshes[k];
      if (!am.mVertices || am.mNumVertices != a.mNumVertices)
        throw Error(file.string() + ": mesh '" + im.name + "' frame " + std::to_string(k) +
                    " has no positions or another vertex count than its mesh");
      im.frames.emplace_back(am.mName.C_Str(), place(am.mVertices, am.mNumVertices));
    }
    out.push_back(std::move(im));
  }
  if (out.empty()) throw Error(file.string() + ": no triangle mesh in the file");
  return out;
}

}  // namespace swish::io
