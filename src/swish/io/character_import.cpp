#include "swish/io/character_import.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <map>
#include <unordered_map>

#include "swish/core/error.hpp"
#include "swish/io/assimp_scene.hpp"
#include "swish/io/mesh_topology_check.hpp"

namespace swish::io {
namespace {

using Mat4d = Eigen::Matrix4d;

struct SkeletonBuild {
  Skeleton skeleton;
  std::vector<Mat4d> globalWithScale;  // the file's global node matrices of the joints (may carry scale)
  std::unordered_map<std::string, int> index;
};

SkeletonBuild buildSkeleton(const aiScene& scene, const std::string& file) {
  std::unordered_map<std::string, bool> isBone;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m)
    for (unsigned b = 0; b < scene.mMeshes[m]->mNumBones; ++b)
      isBone[scene.mMeshes[m]->mBones[b]->mName.C_Str()] = true;
  if (isBone.empty()) throw Error(file + ": no skin (no mesh is bound to a skeleton)");

  SkeletonBuild out;
  std::vector<int> roots;
  // Depth-first, parents before children; a joint's parent is its nearest ancestor that is a joint.
  struct Item {
    const aiNode* node;
    Mat4d parentGlobal;
    int parentJoint;
  };
  std::vector<Item> stack{{scene.mRootNode, Mat4d::Identity(), -1}};
  while (!stack.empty()) {
    Item it = stack.back();
    stack.pop_back();
    const Mat4d global = it.parentGlobal * toEigen(it.node->mTransformation);
    int jointHere = it.parentJoint;
    const std::string name = it.node->mName.C_Str();
    if (isBone.count(name)) {
      if (out.index.count(name)) throw Error(file + ": two skeleton nodes are named '" + name + "'");
      jointHere = int(out.skeleton.joints.size());
      out.index[name] = jointHere;
      Joint j;
      j.name = name;
      j.parent = it.parentJoint;
      out.skeleton.joints.push_back(j);
      out.globalWithScale.push_back(global);
      if (it.parentJoint < 0) roots.push_back(jointHere);
    }
    for (unsigned c = it.node->mNumChildren; c-- > 0;) stack.push_back({it.node->mChildren[c], global, jointHere});
  }
  for (const auto& [name, _] : isBone)
    if (!out.index.count(name)) throw Error(file + ": skin joint '" + name + "' has no node in the scene");
  if (roots.size() != 1) {
    std::string names;
    for (int r : roots) names += (names.empty() ? "" : ", ") + out.skeleton.joints[size_t(r)].name;
    throw Error(file + ": the skin's joints form " + std::to_string(roots.size()) + " separate hierarchies (" + names +
                "); one skeleton root is required");
  }
  // Rigid rest globals: rotation from the normalised columns; uniform scale is left to the vertices
  // (which go through the full matrices), non-uniform scale or shear is refused.
  std::vector<RigidTransform> rigid(out.skeleton.size());
  for (size_t j = 0; j < rigid.size(); ++j) {
    const Mat4d& g = out.globalWithScale[j];
    Eigen::Matrix3d r = g.topLeftCorner<3, 3>();
    const Eigen::Vector3d s(r.col(0).norm(), r.col(1).norm(), r.col(2).norm());
    if (!g.allFinite() || s.minCoeff() <= 1e-12 || (s.maxCoeff() - s.minCoeff()) > 1e-3 * s.maxCoeff())
      throw Error(file + ": joint '" + out.skeleton.joints[j].name +
                  "' has a non-uniform, zero or non-finite scale in its rest transform");
    for (int c = 0; c < 3; ++c) r.col(c) /= s[c];
    Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
    r = svd.matrixU() * svd.matrixV().transpose();
    if (r.determinant() < 0)
      throw Error(file + ": joint '" + out.skeleton.joints[j].name + "' has a mirrored rest transform");
    rigid[j].rotation = Quatf(Eigen::Quaterniond(r).normalized().cast<float>());
    rigid[j].translation = g.topRightCorner<3, 1>().cast<float>();
  }
  for (size_t j = 0; j < rigid.size(); ++j) {
    const int p = out.skeleton.joints[j].parent;
    out.skeleton.joints[j].rest = p < 0 ? rigid[j] : rigid[size_t(p)].inverse() * rigid[j];
    out.skeleton.joints[j].rest.rotation.normalize();
  }
  out.skeleton.computeInverseBindFromRest();
  return out;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return s;
}

// Sub-meshes of the first candidate name that matches a mesh name (or the name with a "-N"/"_N"
// primitive suffix) or the name of a node that holds meshes.
std::vector<unsigned> findMeshes(const aiScene& scene, const std::vector<std::string>& candidates,
                                 std::string& matched) {
  std::vector<std::pair<std::string, unsigned>> named;  // lower-cased mesh or owning-node name, mesh index
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) named.push_back({lower(scene.mMeshes[m]->mName.C_Str()), m});
  std::vector<const aiNode*> stack{scene.mRootNode};
  while (!stack.empty()) {
    const aiNode* n = stack.back();
    stack.pop_back();
    for (unsigned k = 0; k < n->mNumMeshes; ++k) named.push_back({lower(n->mName.C_Str()), n->mMeshes[k]});
    for (unsigned c = 0; c < n->mNumChildren; ++c) stack.push_back(n->mChildren[c]);
  }
  for (const auto& cand : candidates) {
    const std::string c = lower(cand);
    std::vector<unsigned> hits;
    for (const auto& [name, m] : named) {
      const bool exact = name == c;
      const bool suffixed = name.size() > c.size() + 1 && name.rfind(c, 0) == 0 &&
                            (name[c.size()] == '-' || name[c.size()] == '_' || name[c.size()] == '.') &&
                            std::all_of(name.begin() + long(c.size()) + 1, name.end(), ::isdigit);
      if ((exact || suffixed) && std::find(hits.begin(), hits.end(), m) == hits.end()) hits.push_back(m);
    }
    if (!hits.empty()) {
      matched = cand;
      std::sort(hits.begin(), hits.end());
      return hits;
    }
  }
  return {};
}

std::string meshList(const aiScene& scene) {
  std::string s;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m)
    s += (m ? ", '" : "'") + std::string(scene.mMeshes[m]->mName.C_Str()) + "'";
  return s.empty() ? "none" : s;
}

Mesh convertMeshes(const aiScene& scene, const std::vector<unsigned>& meshes, const SkeletonBuild& sk,
                   const std::string& what) {
  struct Influence {
    int joint;
    double weight;
  };
  std::vector<Eigen::Vector3d> pos, nrm;
  std::vector<Eigen::Vector2f> uv;
  std::vector<std::vector<Influence>> infl;
  std::vector<std::array<uint32_t, 3>> tris;
  bool allNormals = true, allUVs = true;
  for (unsigned mi : meshes) {
    const aiMesh& m = *scene.mMeshes[mi];
    if (m.mNumBones == 0) throw Error(what + " (sub-mesh '" + m.mName.C_Str() + "') has no skin weights");
    const size_t base = pos.size();
    std::vector<std::vector<Influence>> local(m.mNumVertices);
    std::vector<Mat4d> bind(m.mNumBones);
    for (unsigned b = 0; b < m.mNumBones; ++b) {
      const aiBone& bone = *m.mBones[b];
      const int j = sk.index.at(bone.mName.C_Str());
      bind[b] = sk.globalWithScale[size_t(j)] * toEigen(bone.mOffsetMatrix);
      for (unsigned w = 0; w < bone.mNumWeights; ++w) {
        const auto& vw = bone.mWeights[w];
        if (vw.mVertexId >= m.mNumVertices)
          throw Error(what + ": skin weight for vertex " + std::to_string(vw.mVertexId) + " out of range");
        if (!std::isfinite(vw.mWeight) || vw.mWeight < 0.f)
          throw Error(what + ": vertex " + std::to_string(base + vw.mVertexId) +
                      " has a negative or non-finite skin weight");
        if (vw.mWeight > 0.f) local[vw.mVertexId].push_back({int(b), double(vw.mWeight)});
      }
    }
    allNormals = allNormals && m.HasNormals();
    allUVs = allUVs && m.HasTextureCoords(0);
    for (unsigned v = 0; v < m.mNumVertices; ++v) {
      auto& inf = local[v];
      double total = 0;
      for (const auto& i : inf) total += i.weight;
      if (inf.empty() || total <= 0)
        throw Error(what + ": vertex " + std::to_string(base + v) + " has no skin weights");
      Mat4d blend = Mat4d::Zero();
      for (const auto& i : inf) blend += (i.weight / total) * bind[size_t(i.joint)];
      const Eigen::Vector4d p(m.mVertices[v].x, m.mVertices[v].y, m.mVertices[v].z, 1.0);
      pos.push_back((blend * p).head<3>());
      if (m.HasNormals()) {
        const Eigen::Vector3d n(m.mNormals[v].x, m.mNormals[v].y, m.mNormals[v].z);
        nrm.push_back((blend.topLeftCorner<3, 3>().inverse().transpose() * n).normalized());
      }
      if (m.HasTextureCoords(0)) uv.push_back({m.mTextureCoords[0][v].x, m.mTextureCoords[0][v].y});
      for (auto& i : inf) i.joint = sk.index.at(m.mBones[i.joint]->mName.C_Str());
      infl.push_back(std::move(inf));
    }
    for (unsigned f = 0; f < m.mNumFaces; ++f) {
      const aiFace& face = m.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines carry no surface
      tris.push_back(
          {uint32_t(base + face.mIndices[0]), uint32_t(base + face.mIndices[1]), uint32_t(base + face.mIndices[2])});
    }
  }
  if (tris.empty()) throw Error(what + " has no triangles");

  Mesh out;
  const auto n = Eigen::Index(pos.size());
  out.positions.resize(n, 3);
  for (Eigen::Index v = 0; v < n; ++v) out.positions.row(v) = pos[size_t(v)].cast<float>().transpose();
  if (allNormals) {
    out.normals.resize(n, 3);
    for (Eigen::Index v = 0; v < n; ++v) out.normals.row(v) = nrm[size_t(v)].cast<float>().transpose();
  }
  if (allUVs) {
    out.uvs.resize(n, 2);
    for (Eigen::Index v = 0; v < n; ++v) out.uvs.row(v) = uv[size_t(v)].transpose();
  }
  out.triangles.resize(Eigen::Index(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) out.triangles(Eigen::Index(t), k) = tris[t][size_t(k)];

  // Strongest influences first, at most kMaxInfluences, renormalised; the width is the widest vertex's.
  int width = 1;
  for (auto& inf : infl) {
    std::stable_sort(inf.begin(), inf.end(),
                     [](const Influence& a, const Influence& b) { return a.weight > b.weight; });
    if (inf.size() > size_t(kMaxInfluences)) inf.resize(kMaxInfluences);
    width = std::max(width, int(inf.size()));
  }
  out.skin.influences = width;
  out.skin.joints.assign(pos.size() * size_t(width), 0);
  out.skin.weights.assign(pos.size() * size_t(width), 0.f);
  for (size_t v = 0; v < infl.size(); ++v) {
    double total = 0;
    for (const auto& i : infl[v]) total += i.weight;
    for (size_t k = 0; k < infl[v].size(); ++k) {
      out.skin.joints[v * size_t(width) + k] = uint16_t(infl[v][k].joint);
      out.skin.weights[v * size_t(width) + k] = float(infl[v][k].weight / total);
    }
  }
  return out;
}

}  // namespace

Character importCharacter(const std::filesystem::path& path, const CharacterImportOptions& options) {
  const std::string file = path.string();
  Assimp::Importer importer;
  const aiScene& scene = readAssimpScene(importer, path);
  SkeletonBuild sk = buildSkeleton(scene, file);
  sk.skeleton.validate(file);
  {
    std::string missing;
    for (const auto& name : options.requiredJoints)
      if (sk.skeleton.find(name) < 0) missing += (missing.empty() ? "'" : ", '") + name + "'";
    if (!missing.empty()) throw Error(file + ": the skeleton lacks required joint(s) " + missing);
  }

  Character c;
  c.name = path.stem().string();
  std::string matched;
  auto body = findMeshes(scene, options.bodyNames, matched);
  if (body.empty())
    throw Error(file + ": no body mesh (looked for a mesh or node named one of the body names; meshes here: " +
                meshList(scene) + ")");
  c.body = convertMeshes(scene, body, sk, file + ": body mesh '" + matched + "'");
  auto garment = findMeshes(scene, options.garmentNames, matched);
  if (garment.empty())
    throw Error(
        file + ": no garment mesh (looked for 'shirt', 'garment', 'jersey'... ; meshes here: " + meshList(scene) + ")");
  const std::string garmentWhat = file + ": garment mesh '" + matched + "'";
  c.garment = convertMeshes(scene, garment, sk, garmentWhat);
  auto sim = findMeshes(scene, options.simulationMeshNames, matched);
  std::string simWhat = file + ": simulation mesh '" + matched + "'";
  if (!sim.empty()) c.simulationMesh = convertMeshes(scene, sim, sk, simWhat);

  c.skeleton = std::move(sk.skeleton);
  const size_t nj = c.skeleton.size();
  c.body.validate(file + ": body mesh", nj);
  c.garment.validate(garmentWhat, nj);
  if (c.garment.uvs.rows() == 0)
    throw Error(garmentWhat + " has no UVs (texture coordinates are needed for its normal map)");
  if (c.simulationMesh) c.simulationMesh->validate(simWhat, nj);
  if (options.checkGarmentTopology) {
    checkGarmentTopology(c.garment, garmentWhat);
    if (c.simulationMesh) checkGarmentTopology(*c.simulationMesh, simWhat);
  }
  return c;
}

}  // namespace swish::io
