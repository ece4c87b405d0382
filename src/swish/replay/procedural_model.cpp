#include "swish/replay/procedural_model.hpp"

#include <algorithm>
#include <cmath>

#include "swish/bake/compression/vq_codebook.hpp"
#include "swish/core/character.hpp"
#include "swish/core/error.hpp"
#include "swish/core/mesh_frames.hpp"
#include "swish/core/rng.hpp"

namespace swish::replay {

namespace {

constexpr float kPi = 3.14159265358979f;

// The spine chain the tube is skinned to, bottom to top.
const std::vector<std::string>& spineChain() {
  static const std::vector<std::string> c = {"Hips", "LowerBack", "Spine", "Spine1"};
  return c;
}

// A tube around the spine: `rings` x (`segments` + 1) vertices (the seam column is duplicated so every
// vertex has one UV), skinned to the two spine joints nearest in height.
Mesh makeJerseyTube(const Skeleton& sk, const ProceduralModelSpec& spec) {
  const auto globals = sk.globalTransforms(sk.restPose());
  std::vector<int> chain;
  for (const auto& n : spineChain()) chain.push_back(sk.find(n));
  // CMU's Neck sits on Spine1 (chest height); Neck1 is the base of the neck, where a collar ends.
  const int neck = sk.find("Neck1") >= 0 ? sk.find("Neck1") : sk.find("Neck");
  std::vector<Vec3f> pts;
  for (int j : chain) pts.push_back(globals[size_t(j)].translation);
  const Vec3f topPoint = neck >= 0 ? globals[size_t(neck)].translation : pts.back() + Vec3f(0, 0.15f, 0);
  const float bottom = pts.front().y() - 0.12f, top = topPoint.y() - 0.04f;
  const float height = std::max(top - bottom, 0.1f);
  const float rx = 0.36f * height, rz = 0.24f * height;

  const uint32_t rings = std::max(2u, spec.rings), cols = std::max(3u, spec.segments) + 1;
  Mesh m;
  const size_t n = size_t(rings) * cols;
  m.positions.resize(Eigen::Index(n), 3);
  m.uvs.resize(Eigen::Index(n), 2);
  m.skin.influences = 2;
  m.skin.joints.assign(n * 2, 0);
  m.skin.weights.assign(n * 2, 0.f);
  for (uint32_t r = 0; r < rings; ++r) {
    const float v = float(r) / float(rings - 1), y = bottom + v * height;
    // Centre line and skin weights: piecewise linear between the chain joints (and the top point).
    std::vector<Vec3f> line = pts;
    line.push_back(topPoint);
    size_t seg = 0;
    while (seg + 2 < line.size() && y > line[seg + 1].y()) ++seg;
    const float span = std::max(line[seg + 1].y() - line[seg].y(), 1e-4f);
    const float t = std::clamp((y - line[seg].y()) / span, 0.f, 1.f);
    const Vec3f centre = line[seg] * (1.f - t) + line[seg + 1] * t;
    const uint16_t j0 = uint16_t(chain[std::min(seg, chain.size() - 1)]);
    const uint16_t j1 = uint16_t(chain[std::min(seg + 1, chain.size() - 1)]);
    for (uint32_t c = 0; c < cols; ++c) {
      const float u = float(c) / float(cols - 1), a = 2.f * kPi * u;
      const size_t i = size_t(r) * cols + c;
      // Slightly wider at the chest than at the waist, like a jersey.
      const float flare = 0.9f + 0.2f * v;
      m.positions.row(Eigen::Index(i)) =
          Vec3f(centre.x() + flare * rx * std::sin(a), y, centre.z() + flare * rz * std::cos(a));
      m.uvs.row(Eigen::Index(i)) = Vec2f(u, 1.f - v);
      m.skin.joints[2 * i] = j0;
      m.skin.joints[2 * i + 1] = j1;
      m.skin.weights[2 * i] = 1.f - t;
      m.skin.weights[2 * i + 1] = t;
    }
  }
  m.triangles.resize(Eigen::Index(size_t(rings - 1) * (cols - 1) * 2), 3);
  Eigen::Index t = 0;
  for (uint32_t r = 0; r + 1 < rings; ++r)
    for (uint32_t c = 0; c + 1 < cols; ++c) {
      const uint32_t a = r * cols + c, b = a + 1, d = a + cols, e = d + 1;
      m.triangles.row(t++) << a, d, b;  // outward (counter-clockwise seen from outside)
      m.triangles.row(t++) << b, d, e;
    }
  const MeshFrameTopology topo = buildFrameTopology(m.triangles, m.positions);
  computeVertexFrames(m.positions, m.uvs, m.triangles, topo, m.normals, m.tangents);
  return m;
}

// Smooth radial ripples: what folds of a jersey look like to a PCA, a few millimetres each.
MeshPca makeRippleBasis(const Mesh& mesh, const ProceduralModelSpec& spec, Rng& rng) {
  const Eigen::Index n = Eigen::Index(mesh.vertexCount());
  MeshPca pca;
  pca.mean.resize(3 * n);
  for (Eigen::Index v = 0; v < n; ++v) pca.mean.segment<3>(3 * v) = mesh.positions.row(v).transpose();
  pca.basis.resize(3 * n, Eigen::Index(spec.meshComponents));
  for (uint32_t k = 0; k < spec.meshComponents; ++k) {
    const float around = float(1 + rng.below(5)), along = 0.5f + float(rng.below(4));
    const float p0 = rng.uniformf(0.f, 2.f * kPi), p1 = rng.uniformf(0.f, 2.f * kPi);
    const float amplitude = 0.008f / (1.f + float(k) / 6.f);
    for (Eigen::Index v = 0; v < n; ++v) {
      const float u = mesh.uvs(v, 0), h = 1.f - mesh.uvs(v, 1);
      const float s = amplitude * std::cos(2.f * kPi * around * u + p0) * std::sin(kPi * along * h + p1);
      pca.basis.block<3, 1>(3 * v, k) = s * mesh.normals.row(v).transpose();
    }
  }
  return pca;
}

// Wrinkle maps: parallel folds of a different direction and frequency per map.
std::vector<bake::NormalMapImage> makeWrinkleMaps(const ProceduralModelSpec& spec) {
  std::vector<bake::NormalMapImage> maps(spec.normalMaps);
  const uint32_t w = spec.mapSize;
  for (uint32_t m = 0; m < spec.normalMaps; ++m) {
    auto& img = maps[m];
    img.width = img.height = w;
    img.xy.resize(size_t(w) * w * 2);
    const float theta = kPi * float(m) / float(spec.normalMaps), freq = 3.f + 2.f * float(m % 4);
    const float c = std::cos(theta), s = std::sin(theta);
    for (uint32_t y = 0; y < w; ++y)
      for (uint32_t x = 0; x < w; ++x) {
        const float p = (float(x) * c + float(y) * s) / float(w);
        const float slope = 0.4f * std::sin(2.f * kPi * freq * p + 0.7f * float(m));
        img.xy[(size_t(y) * w + x) * 2 + 0] = slope * c;
        img.xy[(size_t(y) * w + x) * 2 + 1] = slope * s;
      }
  }
  return maps;
}

MlpLayer randomLayer(Rng& rng, int in, int out) {
  MlpLayer l;
  l.weight.resize(out, in);
  l.bias.resize(out);
  const double sd = 1.0 / std::sqrt(double(in));  // LeCun normal: what SELU networks start from
  for (Eigen::Index i = 0; i < l.weight.size(); ++i) l.weight.data()[i] = float(rng.normal(0.0, sd));
  for (Eigen::Index i = 0; i < l.bias.size(); ++i) l.bias[i] = float(rng.normal(0.0, 0.05));
  return l;
}

}  // namespace

Model makeProceduralModel(const Skeleton& skeleton, const ProceduralModelSpec& spec) {
  std::vector<std::string> missing;
  for (const auto& n : spineChain())
    if (skeleton.find(n) < 0) missing.push_back(n);
  for (const auto& n : defaultInputJointNames())
    if (skeleton.find(n) < 0 && std::find(missing.begin(), missing.end(), n) == missing.end()) missing.push_back(n);
  if (!missing.empty()) {
    std::string list;
    for (const auto& n : missing) list += (list.empty() ? "" : ", ") + n;
    throw Error("procedural model: the skeleton lacks the joints " + list);
  }
  if (spec.mapSize % 4 || spec.mapSize == 0)
    throw Error("procedural model: the map size must be a positive multiple of 4");
  Rng rng(spec.seed);
  Model m;
  m.skeleton = skeleton;
  m.skeleton.computeInverseBindFromRest();
  for (const auto& n : defaultInputJointNames()) m.inputJoints.push_back(uint32_t(skeleton.find(n)));
  m.gameMesh = makeJerseyTube(m.skeleton, spec);
  m.meshPca = makeRippleBasis(m.gameMesh, spec, rng);

  const int theta = m.thetaSize(), lambda = int(spec.meshComponents + spec.codeDims);
  int in = theta;
  for (uint32_t l = 0; l < spec.hiddenLayers; ++l) {
    m.mlp.layers.push_back(randomLayer(rng, in, int(spec.hiddenWidth)));
    in = int(spec.hiddenWidth);
  }
  m.mlp.layers.push_back(randomLayer(rng, in, lambda));
  // Theta of the rest pose is [1,0,0, 0,1,0] per joint; poses move it by a few tenths.
  m.inputNorm.mean = VecXf::Zero(theta);
  for (int j = 0; j < theta / 6; ++j) m.inputNorm.mean[6 * j] = m.inputNorm.mean[6 * j + 4] = 1.f;
  m.inputNorm.scale = VecXf::Constant(theta, 0.3f);
  m.outputNorm.mean = VecXf::Zero(lambda);
  m.outputNorm.scale = VecXf::Ones(lambda);

  if (spec.normalMaps > 0) {
    const auto maps = makeWrinkleMaps(spec);
    std::vector<const bake::NormalMapImage*> ptrs;
    for (const auto& mp : maps) ptrs.push_back(&mp);
    bake::VqOptions vq;
    vq.codebookSize = spec.codebookSize;
    vq.trainingBlocks = 8192;
    vq.iterations = 6;
    vq.seed = spec.seed;
    bake::encodeVq(ptrs, vq, m.normalMaps);
    m.normalMaps.keys.resize(Eigen::Index(spec.normalMaps), Eigen::Index(spec.codeDims));
    for (Eigen::Index i = 0; i < m.normalMaps.keys.size(); ++i) m.normalMaps.keys.data()[i] = float(rng.normal());
  }
  m.temporalFilter.timeConstantSeconds = 0.1f;
  m.metadata = std::string("{\"generator\": \"swish::replay::makeProceduralModel\", \"label\": \"") +
               kProceduralModelLabel + "\", \"seed\": " + std::to_string(spec.seed) + "}";
  m.validate("procedural model");
  return m;
}

}  // namespace swish::replay
