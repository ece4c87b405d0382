#include "swish/gpu/gpu_model.hpp"

#include <vector>

#include "swish/core/error.hpp"
#include "swish/core/mesh_frames.hpp"
#include "swish/gpu/allocation_plan.hpp"
#include "swish/gpu/context.hpp"
#include "swish/gpu/tangent_frames_pass.hpp"

namespace swish::gpu {

namespace {

// Everything GpuModel uploads, in upload order: the buffer each goes to, its name and its bytes. The
// constructor uploads these and modelAllocations() lists them, so the two cannot disagree. The arrays
// the model does not hold as they go up (the frame topology, 32-bit joints, padded VQ data) live here.
struct ModelUploads {
  struct Upload {
    Buffer GpuModel::*target;
    const char* name;
    const void* data;  // nullptr: allocated, nothing uploaded (the 8-byte stand-in for missing UVs)
    VkDeviceSize bytes;
  };
  std::vector<Upload> list;

  std::vector<float> zeroBasis;  // K = 0: one column of zeros, so the kernel has a column to read
  std::vector<uint32_t> joints;
  MeshFrameTopology topo;
  std::vector<uint32_t> frameTriangles;
  std::vector<int8_t> codebook;
  std::vector<uint16_t> indices;
  std::vector<uint32_t> anchors;

  ModelUploads(const Model& m, bool withNormalMaps) {
    const Mesh& g = m.gameMesh;
    const size_t n = g.vertexCount();
    auto add = [&](Buffer GpuModel::*target, const char* name, const void* data, size_t bytes) {
      list.push_back({target, name, data, VkDeviceSize(bytes)});
    };
    add(&GpuModel::mean, "PCA mean", m.meshPca.mean.data(), 3 * n * 4);
    if (m.meshPca.components() == 0) {
      zeroBasis.assign(3 * n, 0.f);
      add(&GpuModel::basis, "PCA basis", zeroBasis.data(), zeroBasis.size() * 4);
    } else {  // column-major = [k][3N]
      add(&GpuModel::basis, "PCA basis", m.meshPca.basis.data(), size_t(m.meshPca.basis.size()) * 4);
    }
    joints.assign(g.skin.joints.begin(), g.skin.joints.end());
    add(&GpuModel::skinJoints, "skin joints", joints.data(), joints.size() * 4);
    add(&GpuModel::skinWeights, "skin weights", g.skin.weights.data(), g.skin.weights.size() * 4);
    if (size_t(g.uvs.rows()) == n)
      add(&GpuModel::uvs, "UVs", g.uvs.data(), 2 * n * 4);
    else
      add(&GpuModel::uvs, "UVs (none)", nullptr, 8);
    add(&GpuModel::triangles, "triangles", g.triangles.data(), size_t(g.triangles.size()) * 4);
    topo = buildFrameTopology(g.triangles, g.positions);
    frameTriangles = TangentFramesPass::frameTriangles(topo);
    add(&GpuModel::normalOffsets, "normal adjacency offsets", topo.normalAdjacency.offsets.data(),
        topo.normalAdjacency.offsets.size() * 4);
    add(&GpuModel::normalTriangles, "normal adjacency", topo.normalAdjacency.triangles.data(),
        topo.normalAdjacency.triangles.size() * 4);
    add(&GpuModel::tangentOffsets, "tangent adjacency offsets", topo.tangentAdjacency.offsets.data(),
        topo.tangentAdjacency.offsets.size() * 4);
    add(&GpuModel::tangentTriangles, "tangent adjacency", topo.tangentAdjacency.triangles.data(),
        topo.tangentAdjacency.triangles.size() * 4);
    add(&GpuModel::frameTriangles, "flagged adjacency", frameTriangles.data(), frameTriangles.size() * 4);
    const NormalMapDatabase& db = m.normalMaps;
    if (withNormalMaps && !db.empty()) {
      // Padded to whole 32-bit words: the kernel reads words.
      codebook.assign(db.codebook.begin(), db.codebook.end());
      codebook.resize((codebook.size() + 3) / 4 * 4, 0);
      add(&GpuModel::codebook, "VQ codebook", codebook.data(), codebook.size());
      indices.assign(db.indices.begin(), db.indices.end());
      indices.resize((indices.size() + 1) / 2 * 2, 0);
      add(&GpuModel::indices, "VQ indices", indices.data(), indices.size() * 2);
    }
    if (!m.bodyAnchors.empty()) {
      anchors = DeformPass::packAnchors(m.bodyAnchors, m.gameMesh.skin, uint32_t(m.skeleton.size()));
      add(&GpuModel::anchors, "body anchors", anchors.data(), anchors.size() * 4);
    }
  }
};

}  // namespace

std::vector<Allocation> modelAllocations(const Model& model, bool withNormalMaps) {
  const ModelUploads uploads(model, withNormalMaps);
  std::vector<Allocation> out;
  for (const auto& u : uploads.list) out.push_back({u.name, u.bytes == 0 ? 4 : u.bytes, false});
  return out;
}

GpuModel::GpuModel(Context& ctx, const Model& m, const std::string& name) : name_(name) {
  const Mesh& g = m.gameMesh;
  const auto fail = [&](const std::string& what) { throw Error(name + ": cannot upload to the GPU: " + what); };
  vertexCount_ = uint32_t(g.vertexCount());
  triangleCount_ = uint32_t(g.triangleCount());
  jointCount_ = uint32_t(m.skeleton.size());
  meshComponents_ = uint32_t(m.meshPca.components());
  kernelComponents_ = std::max(1u, meshComponents_);
  influences_ = uint32_t(g.skin.influences);
  const size_t n = vertexCount_;
  if (n == 0) fail("the game mesh has no vertices");
  if (size_t(m.meshPca.mean.size()) != 3 * n || size_t(m.meshPca.basis.rows()) != 3 * n)
    fail("mesh PCA has " + std::to_string(m.meshPca.mean.size()) + " mean values and " +
         std::to_string(m.meshPca.basis.rows()) + " basis rows, 3 x " + std::to_string(n) + " vertices expected");
  if (influences_ < 1 || influences_ > uint32_t(kMaxInfluences) || g.skin.weights.size() != n * influences_ ||
      g.skin.joints.size() != n * influences_)
    fail("skin weights do not have 1..8 influences for each of the " + std::to_string(n) + " vertices");
  for (size_t i = 0; i < g.skin.joints.size(); ++i)
    if (g.skin.joints[i] >= jointCount_)
      fail("skin joint " + std::to_string(g.skin.joints[i]) + " of vertex " + std::to_string(i / influences_) +
           " is not in the skeleton of " + std::to_string(jointCount_) + " joints");
  for (Eigen::Index t = 0; t < g.triangles.rows(); ++t)
    for (int k = 0; k < 3; ++k)
      if (g.triangles(t, k) >= n)
        fail("triangle " + std::to_string(t) + " refers to vertex " + std::to_string(g.triangles(t, k)));
  hasUvs_ = size_t(g.uvs.rows()) == n;

  const NormalMapDatabase& db = m.normalMaps;
  if (!db.empty()) {
    if (db.width == 0 || db.height == 0 || db.width % 4 || db.height % 4)
      fail("normal-map size " + std::to_string(db.width) + "x" + std::to_string(db.height) +
           " is not a positive multiple of 4");
    if (db.codebook.size() != size_t(db.codebookSize) * 32) fail("VQ codebook size does not match its entry count");
    if (db.indices.size() != size_t(db.mapCount()) * db.blocksPerMap())
      fail("VQ index count does not match maps x blocks");
    mapCount_ = db.mapCount();
    mapWidth_ = db.width;
    mapHeight_ = db.height;
    codebookSize_ = db.codebookSize;
  }

  if (!m.bodyAnchors.empty()) {
    for (uint32_t s = 0; s < m.bodyAnchors.slots(); ++s) {
      const std::vector<BodyAnchor>& set = m.bodyAnchors.slot(s);
      const std::string what = s ? std::string(anchorSlotName(s)) + " body anchor" : "body anchor";
      if (set.size() != n) fail(std::to_string(set.size()) + " " + what + "s for " + std::to_string(n) + " vertices");
      for (size_t v = 0; v < n; ++v)
        for (const uint16_t j : set[v].joints)
          if (j >= jointCount_)
            fail(what + " joint " + std::to_string(j) + " of vertex " + std::to_string(v) +
                 " is not in the skeleton of " + std::to_string(jointCount_) + " joints");
    }
    anchorSlots_ = m.bodyAnchors.slots();
    anchorExtraJoints_ = DeformPass::anchorExtraJointsOf(m.bodyAnchors, g.skin);
    anchorZeroSkip_ = DeformPass::anchorsSkipZeroWeights(anchorExtraJoints_, g.skin);
  }

  const ModelUploads uploads(m, true);
  for (const auto& u : uploads.list) {
    Buffer& b = this->*u.target;
    b = Buffer(ctx, u.bytes, MemoryKind::DeviceLocal, name + ": " + u.name);
    if (u.data) b.upload(ctx, u.data, u.bytes);
  }
}

DeformPass GpuModel::makeDeformPass(Context& ctx) const {
  return DeformPass(ctx, kernelComponents_, influences_, true, basis.size() / sizeof(float), anchorSlots_,
                    anchorExtraJoints_, anchorZeroSkip_);
}

DeformPass::Args GpuModel::deformArgs(VkDescriptorSet instanceInputs, const Buffer& positionsOut,
                                      uint32_t instances) const {
  DeformPass::Args a;
  a.mean = mean.address();
  a.basis = basis.address();
  a.instanceInputs = instanceInputs;
  a.skinJoints = skinJoints.address();
  a.skinWeights = skinWeights.address();
  a.positionsOut = positionsOut.address();
  a.vertexCount = vertexCount_;
  a.instanceCount = instances;
  a.jointCount = jointCount_;
  return a;
}

}  // namespace swish::gpu
