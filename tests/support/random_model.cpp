#include "support/random_model.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "swish/core/mesh_frames.hpp"

namespace swish::test {

uint64_t testSeed(uint64_t fallback) {
  if (const char* s = std::getenv("SWISH_TEST_SEED")) return std::strtoull(s, nullptr, 0);
  return fallback;
}

uint64_t announcedTestSeed(uint64_t fallback) {
  const uint64_t seed = testSeed(fallback);
  std::printf("seed %llu (set SWISH_TEST_SEED to override)\n", static_cast<unsigned long long>(seed));
  return seed;
}

static Quatf randomRotation(Rng& rng, float maxAngle) {
  Vec3f axis(float(rng.normal()), float(rng.normal()), float(rng.normal()));
  if (axis.norm() < 1e-6f) axis = Vec3f::UnitY();
  return Quatf(Eigen::AngleAxisf(rng.uniformf(-maxAngle, maxAngle), axis.normalized()));
}

Pose makeRandomPose(Rng& rng, const Skeleton& sk, float maxAngle) {
  Pose p = sk.restPose();
  for (auto& q : p.local) q = (q * randomRotation(rng, maxAngle)).normalized();
  return p;
}

// A body anchor for vertex v near its rest position (first joint: the vertex's own first influence).
static BodyAnchor randomAnchor(Rng& rng, const Model& m, uint32_t v, uint32_t joints) {
  const SkinWeights& skin = m.gameMesh.skin;
  BodyAnchor a;
  a.normal = Vec3f(rng.uniformf(-.5f, .5f), rng.uniformf(-.5f, .5f), -1.f).normalized();
  a.position = m.gameMesh.positions.row(v).transpose() + a.normal * rng.uniformf(-.03f, .02f);
  a.radius = rng.uniformf(.015f, .08f);
  a.clearance = v % 3 == 0 ? m.bodyAnchors.margin : rng.uniformf(-.01f, m.bodyAnchors.margin);
  float sum = 0.f;
  for (int i = 0; i < kAnchorInfluences; ++i) {
    a.joints[size_t(i)] = i == 0 ? skin.joints[size_t(v) * size_t(skin.influences)] : uint16_t(rng.below(joints));
    a.weights[size_t(i)] = i == 3 && v % 2 ? 0.f : rng.uniformf(0.05f, 1.f);
    sum += a.weights[size_t(i)];
  }
  for (float& w : a.weights) w /= sum;
  return a;
}

Model makeRandomModel(Rng& rng, const RandomModelSpec& s) {
  Model m;
  // Skeleton: joint i's parent is a random earlier joint, offsets ~10 cm.
  for (uint32_t i = 0; i < s.joints; ++i) {
    Joint j;
    j.name = "joint" + std::to_string(i);
    j.parent = i == 0 ? -1 : int(rng.below(i));
    j.rest.translation =
        i == 0 ? Vec3f(0, 1, 0) : Vec3f(rng.uniformf(-.1f, .1f), rng.uniformf(.05f, .15f), rng.uniformf(-.05f, .05f));
    j.rest.rotation = Quatf::Identity();
    m.skeleton.joints.push_back(j);
  }
  m.skeleton.computeInverseBindFromRest();
  for (uint32_t i = 0; i < s.inputJoints; ++i) m.inputJoints.push_back(i % s.joints);
  m.rootGravity = s.rootGravity;

  // Mesh: vertices on a grid of cols x rows (the last row may be partial), triangles between full cells.
  const uint32_t n = s.vertices;
  const uint32_t cols = std::max<uint32_t>(1, uint32_t(std::ceil(std::sqrt(double(n)))));
  Mesh& g = m.gameMesh;
  g.positions.resize(n, 3);
  g.uvs.resize(n, 2);
  for (uint32_t v = 0; v < n; ++v) {
    const float x = float(v % cols), y = float(v / cols);
    g.positions.row(v) << 0.02f * x + rng.uniformf(-.002f, .002f), 1.f + 0.02f * y, rng.uniformf(-.01f, .01f);
    g.uvs.row(v) << (x + .5f) / float(cols), (y + .5f) / float(cols);
  }
  std::vector<std::array<uint32_t, 3>> tris;
  for (uint32_t v = 0; v < n; ++v) {
    const uint32_t x = v % cols;
    if (x + 1 >= cols || v + cols + 1 >= n) continue;
    tris.push_back({v, v + 1, v + cols});
    tris.push_back({v + 1, v + cols + 1, v + cols});
  }
  if (tris.empty()) tris.push_back({0, 0, 0});  // a degenerate triangle keeps tiny meshes valid
  g.triangles.resize(Eigen::Index(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t) g.triangles.row(Eigen::Index(t)) << tris[t][0], tris[t][1], tris[t][2];
  g.skin.influences = int(s.influences);
  for (uint32_t v = 0; v < n; ++v) {
    float sum = 0;
    std::vector<float> w(s.influences);
    for (auto& x : w) sum += (x = float(rng.uniform(0.05, 1.0)));
    for (uint32_t k = 0; k < s.influences; ++k) {
      g.skin.joints.push_back(uint16_t(rng.below(s.joints)));
      g.skin.weights.push_back(w[k] / sum);
    }
  }
  const auto topo = buildFrameTopology(g.triangles, g.positions);
  computeVertexFrames(g.positions, g.uvs, g.triangles, topo, g.normals, g.tangents);

  // PCA: mean = rest positions, basis columns of a few millimetres.
  m.meshPca.mean = Eigen::Map<const VecXf>(g.positions.data(), 3 * n);
  m.meshPca.basis.resize(3 * n, s.meshComponents);
  for (Eigen::Index i = 0; i < m.meshPca.basis.size(); ++i) m.meshPca.basis.data()[i] = float(rng.normal(0, 0.003));

  // Normal-map database.
  auto& db = m.normalMaps;
  if (s.normalMaps > 0) {
    db.width = db.height = s.mapSize;
    db.keys.resize(s.normalMaps, s.codeDims);
    for (Eigen::Index i = 0; i < db.keys.size(); ++i) db.keys.data()[i] = float(rng.normal());
    db.codebookSize = s.codebookSize;
    db.codebook.resize(size_t(s.codebookSize) * 32);
    for (auto& c : db.codebook) c = int8_t(int(rng.below(181)) - 90);  // |X|,|Y| <= 0.71 keeps Z real
    db.indices.resize(size_t(s.normalMaps) * db.blocksPerMap());
    for (auto& i : db.indices) i = uint16_t(rng.below(s.codebookSize));
  }

  // MLP.
  const int in = m.thetaSize(), out = int(s.meshComponents + (s.normalMaps ? s.codeDims : 0));
  int prev = in;
  for (uint32_t l = 0; l <= s.hiddenLayers; ++l) {
    const int width = l == s.hiddenLayers ? out : int(s.hiddenWidth);
    MlpLayer L;
    L.weight.resize(width, prev);
    L.bias.resize(width);
    const double sd = 1.0 / std::sqrt(double(prev));  // LeCun normal, as SELU wants
    for (Eigen::Index i = 0; i < L.weight.size(); ++i) L.weight.data()[i] = float(rng.normal(0, sd));
    for (Eigen::Index i = 0; i < L.bias.size(); ++i) L.bias[i] = float(rng.normal(0, 0.1));
    m.mlp.layers.push_back(std::move(L));
    prev = width;
  }
  m.inputNorm.mean = VecXf::Zero(in);
  m.inputNorm.scale = VecXf::Constant(in, 0.5f);
  m.outputNorm.mean = VecXf::Zero(out);
  m.outputNorm.scale = VecXf::Ones(out);
  m.metadata = R"({"generator":"makeRandomModel"})";
  // Body anchors: each vertex's anchor a few centimetres from its rest position, on either side of it
  // along a normal near -z (the mesh lies in z ~ 0), with balls of 1.5 to 8 cm, so that the skinned
  // mesh enters some balls and not others; four random influences, the first the vertex's own first
  // joint (so that ball and vertex move together), the last often 0; every 7th vertex without one.
  if (s.bodyAnchors) {
    m.bodyAnchors.margin = 0.002f;
    m.bodyAnchors.anchors.resize(n);
    for (uint32_t v = 0; v < n; ++v)
      if (v % 7 != 3) m.bodyAnchors.anchors[v] = randomAnchor(rng, m, v, s.joints);
  }
  // Novelty guard: centres near the origin of the normalised input space, weight ranges around 0.
  if (s.noveltyCentres > 0) {
    NoveltyGuard& g = m.noveltyGuard;
    g.centres.resize(s.noveltyCentres, in);
    for (Eigen::Index i = 0; i < g.centres.size(); ++i) g.centres.data()[i] = float(rng.normal(0, 1));
    g.unit = rng.uniformf(0.5f, 1.5f);
    g.weightMin.resize(s.meshComponents);
    g.weightMax.resize(s.meshComponents);
    for (uint32_t k = 0; k < s.meshComponents; ++k) {
      g.weightMin[k] = -rng.uniformf(0.1f, 1.f);
      g.weightMax[k] = rng.uniformf(0.1f, 1.f);
    }
    g.blendStart = 1.5f;
    g.blendEnd = 3.f;
    g.flagAbove = 1.5f;
  }
  if (s.bodyAnchors && s.secondAnchors) {
    m.bodyAnchors.second.resize(n);
    for (uint32_t v = 0; v < n; ++v)
      if (v % 5 != 1) m.bodyAnchors.second[v] = randomAnchor(rng, m, v, s.joints);
  }
  if (s.bodyAnchors && s.secondAnchors && s.thirdAnchors) {
    m.bodyAnchors.third.resize(n);
    for (uint32_t v = 0; v < n; ++v)
      if (v % 3 != 2) m.bodyAnchors.third[v] = randomAnchor(rng, m, v, s.joints);
  }
  m.validate("random model");
  return m;
}

}  // namespace swish::test
