#include "swish/model/model.hpp"

#include <cmath>

#include "swish/core/error.hpp"

namespace swish {

namespace {
std::string n2s(size_t v) { return std::to_string(v); }
}  // namespace

void Model::validate(const std::string& what) const {
  auto fail = [&](const std::string& part, const std::string& problem) {
    throw Error(what + ": " + part + ": " + problem);
  };
  skeleton.validate(what + ": skeleton");
  if (skeleton.inverseBind.size() != skeleton.size()) fail("skeleton", "needs one inverse bind matrix per joint");
  if (inputJoints.empty()) fail("input joints", "none given");
  for (uint32_t j : inputJoints)
    if (j >= skeleton.size()) fail("input joints", "index " + n2s(j) + " >= joint count " + n2s(skeleton.size()));

  // MLP shape chain: Theta -> ... -> Lambda.
  if (mlp.layers.empty()) fail("mlp", "has no layers");
  for (size_t l = 0; l < mlp.layers.size(); ++l) {
    const auto& L = mlp.layers[l];
    if (L.weight.rows() == 0 || L.weight.cols() == 0) fail("mlp", "layer " + n2s(l) + " is empty");
    if (L.bias.size() != L.weight.rows()) fail("mlp", "layer " + n2s(l) + " bias size differs from its output size");
    if (l > 0 && L.weight.cols() != mlp.layers[l - 1].weight.rows())
      fail("mlp", "layer " + n2s(l) + " input size " + n2s(L.weight.cols()) + " != previous output size " +
                      n2s(mlp.layers[l - 1].weight.rows()));
    if (!L.weight.allFinite() || !L.bias.allFinite()) fail("mlp", "layer " + n2s(l) + " has non-finite values");
  }
  if (mlp.inputSize() != thetaSize()) {
    const std::string gravity = rootGravity ? " + 3 gravity values" : "";
    fail("mlp",
         "input size " + n2s(mlp.inputSize()) + " != 6 x " + n2s(inputJoints.size()) + " input joints" + gravity);
  }
  // In 64 bits: a corrupt file's sizes may not fit an int (found by fuzz_model_loader).
  if (int64_t(mlp.outputSize()) != int64_t(meshPca.basis.cols()) + int64_t(normalMaps.keys.cols()))
    fail("mlp", "output size " + n2s(mlp.outputSize()) + " != " + n2s(meshPca.basis.cols()) + " mesh components + " +
                    n2s(normalMaps.keys.cols()) + " normal-code dimensions");
  auto checkNorm = [&](const Normalisation& nrm, int size, const char* name) {
    if (nrm.mean.size() != size || nrm.scale.size() != size)
      fail(name, "size " + n2s(nrm.mean.size()) + "/" + n2s(nrm.scale.size()) + ", expected " + n2s(size));
    if (!nrm.mean.allFinite() || !nrm.scale.allFinite()) fail(name, "has non-finite values");
    for (Eigen::Index i = 0; i < nrm.scale.size(); ++i)
      if (!(nrm.scale[i] > 0.f)) fail(name, "scale " + n2s(i) + " is not positive");
  };
  checkNorm(inputNorm, thetaSize(), "input normalisation");
  checkNorm(outputNorm, lambdaSize(), "output normalisation");

  // Mesh and its PCA.
  gameMesh.validate(what + ": game mesh", skeleton.size());
  const size_t n = gameMesh.vertexCount();
  if (gameMesh.triangleCount() == 0) fail("game mesh", "has no triangles");
  if (gameMesh.skin.weights.empty()) fail("game mesh", "has no skin weights");
  if (size_t(gameMesh.uvs.rows()) != n) fail("game mesh", "needs one UV per vertex");
  if (size_t(gameMesh.normals.rows()) != n || size_t(gameMesh.tangents.rows()) != n)
    fail("game mesh", "needs rest normals and tangents for every vertex");
  // Mesh::validate leaves these alone (they are optional there); the runtime's tangent frames use them.
  if (!gameMesh.normals.allFinite() || !gameMesh.tangents.allFinite())
    fail("game mesh", "has non-finite rest normals or tangents");
  if (size_t(meshPca.mean.size()) != 3 * n)
    fail("mesh pca", "mean has " + n2s(meshPca.mean.size()) + " values for " + n2s(n) + " vertices (3 each)");
  if (size_t(meshPca.basis.rows()) != 3 * n)
    fail("mesh pca", "basis has " + n2s(meshPca.basis.rows()) + " rows for " + n2s(n) + " vertices (3 each)");
  if (!meshPca.mean.allFinite() || !meshPca.basis.allFinite()) fail("mesh pca", "has non-finite values");

  // Normal-map database.
  const auto& db = normalMaps;
  if (!db.empty()) {
    if (db.width == 0 || db.height == 0 || db.width % 4 || db.height % 4)
      fail("normal maps", "size " + n2s(db.width) + "x" + n2s(db.height) + " is not a positive multiple of 4");
    if (db.width > 16384 || db.height > 16384) fail("normal maps", "larger than 16384 texels a side");
    if (db.codebookSize == 0 || db.codebookSize > 65536)
      fail("normal maps", "codebook size " + n2s(db.codebookSize) + " outside 1..65536");
    if (db.codebook.size() != size_t(db.codebookSize) * 32)
      fail("normal maps",
           "codebook holds " + n2s(db.codebook.size()) + " bytes, expected " + n2s(size_t(db.codebookSize) * 32));
    if (db.indices.size() != size_t(db.mapCount()) * db.blocksPerMap())
      fail("normal maps", "holds " + n2s(db.indices.size()) + " block indices, expected " +
                              n2s(size_t(db.mapCount()) * db.blocksPerMap()));
    for (size_t i = 0; i < db.indices.size(); ++i)
      if (db.indices[i] >= db.codebookSize)
        fail("normal maps",
             "block index " + n2s(i) + " = " + n2s(db.indices[i]) + " >= codebook size " + n2s(db.codebookSize));
    if (!db.keys.allFinite()) fail("normal maps", "keys have non-finite values");
  } else if (db.codeDims() != 0) {
    fail("normal maps", "keys have dimensions but no maps");
  }
  if (bodyAnchors.empty() && !bodyAnchors.second.empty()) fail("body anchors", "second anchors without first ones");
  if (bodyAnchors.second.empty() && !bodyAnchors.third.empty())
    fail("body anchors", "third anchors without second ones");
  if (!bodyAnchors.empty()) {
    const BodyAnchors& ba = bodyAnchors;
    if (ba.anchors.size() != n)
      fail("body anchors",
           n2s(ba.anchors.size()) + " anchors for " + n2s(n) + " game-mesh vertices (one each, or none)");
    if (!ba.second.empty() && ba.second.size() != n)
      fail("body anchors",
           n2s(ba.second.size()) + " second anchors for " + n2s(n) + " game-mesh vertices (one each, or none)");
    if (!ba.third.empty() && ba.third.size() != n)
      fail("body anchors",
           n2s(ba.third.size()) + " third anchors for " + n2s(n) + " game-mesh vertices (one each, or none)");
    if (!(ba.margin >= 0.f && ba.margin <= kMaxAnchorMargin))
      fail("body anchors", "margin " + std::to_string(ba.margin) + " m is not in [0, 0.05] metres");
    for (size_t e = 0; e < ba.slots() * n; ++e) {
      const size_t v = e % n;
      const BodyAnchor& a = ba.slot(uint32_t(e / n))[v];
      const std::string which =
          (e < n ? std::string("anchor") : std::string(anchorSlotName(uint32_t(e / n))) + " anchor") + " of vertex " +
          n2s(v);
      if (!a.present()) {
        if (a.position != Vec3f::Zero() || a.normal != Vec3f::Zero() || a.radius != 0.f || a.clearance != 0.f)
          fail("body anchors", which + " has no weights (no anchor) but a position, normal, radius or clearance");
        continue;
      }
      if (!a.position.allFinite()) fail("body anchors", which + " has a non-finite position");
      if (!a.normal.allFinite() || !(std::abs(a.normal.norm() - 1.f) <= 1e-3f))
        fail("body anchors", which + " has a normal that is not of unit length");
      if (!(a.radius >= kMinAnchorRadius && a.radius <= kMaxAnchorRadius))
        fail("body anchors", which + " has radius " + std::to_string(a.radius) + " m, not in [0.001, 1]");
      if (!(a.clearance <= ba.margin && a.clearance >= -kMaxAnchorDepth && a.reach() > 0.f))
        fail("body anchors", which + " has clearance " + std::to_string(a.clearance) +
                                 " m, not in [-0.2 m, margin] or not above minus its radius");
      float sum = 0.f;
      for (int i = 0; i < kAnchorInfluences; ++i) {
        if (!(a.weights[size_t(i)] >= 0.f) || !std::isfinite(a.weights[size_t(i)]))
          fail("body anchors", which + " has a negative or non-finite weight");
        if (a.joints[size_t(i)] >= skeleton.size())  // the kernel fetches every influence's matrix
          fail("body anchors",
               which + " joint " + n2s(a.joints[size_t(i)]) + " >= joint count " + n2s(skeleton.size()));
        sum += a.weights[size_t(i)];
      }
      if (!(std::abs(sum - 1.f) <= 1e-3f))
        fail("body anchors", which + " has weights summing to " + std::to_string(sum) + ", not 1");
    }
  }
  const NoveltyGuard& g = noveltyGuard;
  if (!g.empty()) {
    if (g.centres.cols() != thetaSize())
      fail("novelty guard",
           "centres have " + n2s(size_t(g.centres.cols())) + " inputs, Theta " + n2s(size_t(thetaSize())));
    if (!g.centres.allFinite()) fail("novelty guard", "centres are not finite");
    if (!(g.unit > 0.f) || !std::isfinite(g.unit)) fail("novelty guard", "unit must be finite and > 0");
    if (g.weightMin.size() != g.weightMax.size() || (g.weightMin.size() != 0 && g.weightMin.size() != meshComponents()))
      fail("novelty guard", "weight ranges have " + n2s(size_t(g.weightMin.size())) + " and " +
                                n2s(size_t(g.weightMax.size())) + " values for " + n2s(size_t(meshComponents())) +
                                " mesh components");
    for (Eigen::Index k = 0; k < g.weightMin.size(); ++k)
      if (!(g.weightMin[k] <= g.weightMax[k]) || !std::isfinite(g.weightMin[k]) || !std::isfinite(g.weightMax[k]))
        fail("novelty guard", "weight range " + n2s(size_t(k)) + " is empty or not finite");
    if (!std::isfinite(g.blendStart) || !std::isfinite(g.blendEnd) || !std::isfinite(g.flagAbove) ||
        g.blendStart < 0.f || g.flagAbove < 0.f)
      fail("novelty guard", "blend and flag thresholds must be finite and >= 0");
  }
  for (size_t i = 0; i < bodyCoverage.covered.size(); ++i)
    if (bodyCoverage.covered[i] >= bodyCoverage.bodyTriangles ||
        (i > 0 && bodyCoverage.covered[i] <= bodyCoverage.covered[i - 1]))
      fail("body coverage", "triangle " + n2s(bodyCoverage.covered[i]) + " (entry " + n2s(i) +
                                ") is not ascending below the body's " + n2s(bodyCoverage.bodyTriangles) +
                                " triangles");
  if (!(temporalFilter.timeConstantSeconds >= 0.f) || !std::isfinite(temporalFilter.timeConstantSeconds))
    fail("temporal filter", "time constant must be finite and >= 0");
}

size_t BodyAnchors::anchored(uint32_t s) const {
  size_t k = 0;
  if (s >= slots()) return 0;
  for (const BodyAnchor& a : slot(s)) k += a.present() ? 1 : 0;
  return k;
}

}  // namespace swish
