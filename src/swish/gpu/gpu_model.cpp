#include "swish/gpu/gpu_model.hpp"

#include <vector>

#include "swish/core/error.hpp"
#include "swish/core/mesh_frames.hpp"
#include "swish/gpu/context.hpp"
#include "swish/gpu/tangent_frames_pass.hpp"

namespace swish::gpu {

namespace {

template <class T>
Buffer uploaded(Context& ctx, const std::string& name, const T* data, size_t count) {
  Buffer b(ctx, count * sizeof(T), MemoryKind::DeviceLocal, name);
  b.upload(ctx, data, count * sizeof(T));
  return b;
}
template <class T>
Buffer uploaded(Context& ctx, const std::string& name, const std::vector<T>& v) {
  return uploaded(ctx, name, v.data(), v.size());
}

}  // namespace

GpuModel::GpuModel(Context& ctx, const Model& m, const std::string& name) : name_(name), bodyProxy_(m.bodyProxy) {
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

  mean = uploaded(ctx, name + ": PCA mean", m.meshPca.mean.data(), 3 * n);
  if (meshComponents_ == 0) {
    const std::vector<float> zero(3 * n, 0.f);
    basis = uploaded(ctx, name + ": PCA basis", zero);
  } else {
    basis = uploaded(ctx, name + ": PCA basis", m.meshPca.basis.data(),
                     size_t(m.meshPca.basis.size()));  // column-major = [k][3N]
  }
  const std::vector<uint32_t> joints(g.skin.joints.begin(), g.skin.joints.end());
  skinJoints = uploaded(ctx, name + ": skin joints", joints);
  skinWeights = uploaded(ctx, name + ": skin weights", g.skin.weights);
  if (hasUvs_)
    uvs = uploaded(ctx, name + ": UVs", g.uvs.data(), 2 * n);
  else
    uvs = Buffer(ctx, 8, MemoryKind::DeviceLocal, name + ": UVs (none)");
  triangles = uploaded(ctx, name + ": triangles", g.triangles.data(), size_t(g.triangles.size()));

  const MeshFrameTopology topo = buildFrameTopology(g.triangles, g.positions);
  normalOffsets = uploaded(ctx, name + ": normal adjacency offsets", topo.normalAdjacency.offsets);
  normalTriangles = uploaded(ctx, name + ": normal adjacency", topo.normalAdjacency.triangles);
  tangentOffsets = uploaded(ctx, name + ": tangent adjacency offsets", topo.tangentAdjacency.offsets);
  tangentTriangles = uploaded(ctx, name + ": tangent adjacency", topo.tangentAdjacency.triangles);
  frameTriangles = uploaded(ctx, name + ": flagged adjacency", TangentFramesPass::frameTriangles(topo));

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
    // Padded to whole 32-bit words: the kernel reads words.
    std::vector<int8_t> cb(db.codebook);
    cb.resize((cb.size() + 3) / 4 * 4, 0);
    codebook = uploaded(ctx, name + ": VQ codebook", cb);
    std::vector<uint16_t> idx(db.indices);
    idx.resize((idx.size() + 1) / 2 * 2, 0);
    indices = uploaded(ctx, name + ": VQ indices", idx);
  }
}

}  // namespace swish::gpu
