#include "swish/runtime/reference_frame.hpp"

#include <algorithm>
#include <span>

#include "swish/core/error.hpp"
#include "swish/core/mesh_frames.hpp"
#include "swish/runtime/reference_pca.hpp"
#include "swish/runtime/reference_push_out.hpp"
#include "swish/runtime/reference_skinning.hpp"
#include "swish/runtime/reference_tangent_frames.hpp"

namespace swish::runtime {

void FrameKernelInputs::validate(const Model& m) const {
  const size_t n = instanceCount, k = size_t(m.meshComponents()), j = m.skeleton.size();
  if (meshWeights.size() != n * k)
    throw Error("frame inputs: " + std::to_string(meshWeights.size()) + " mesh weights for " + std::to_string(n) +
                " instances x " + std::to_string(k) + " components");
  if (skinMatrices.size() != n * j)
    throw Error("frame inputs: " + std::to_string(skinMatrices.size()) + " skinning matrices for " + std::to_string(n) +
                " instances x " + std::to_string(j) + " joints");
  if (!meshComponents.empty() && meshComponents.size() != n)
    throw Error("frame inputs: " + std::to_string(meshComponents.size()) + " per-instance mesh component counts for " +
                std::to_string(n) + " instances");
  for (size_t i = 0; i < meshComponents.size(); ++i)
    if (meshComponents[i] > k)
      throw Error("frame inputs: instance " + std::to_string(i) + " reads " + std::to_string(meshComponents[i]) +
                  " mesh components; the model has " + std::to_string(k));
  if (selectedMaps.empty()) return;
  if (selectedMaps.size() != n || blendAlpha.size() != n)
    throw Error("frame inputs: " + std::to_string(selectedMaps.size()) + " selected maps and " +
                std::to_string(blendAlpha.size()) + " blend weights for " + std::to_string(n) + " instances");
  const bool anyMap = std::any_of(selectedMaps.begin(), selectedMaps.end(), [](uint32_t s) { return s != kNoMap; });
  if (anyMap && m.normalMaps.empty())
    throw Error("frame inputs: normal maps selected but the model has no normal-map database");
  for (size_t i = 0; i < n; ++i)
    if (selectedMaps[i] != kNoMap && selectedMaps[i] >= m.normalMaps.mapCount())
      throw Error("frame inputs: instance " + std::to_string(i) + " selected map " + std::to_string(selectedMaps[i]) +
                  " of a database of " + std::to_string(m.normalMaps.mapCount()));
}

Points3f referencePositions(const Model& m, const FrameKernelInputs& in, uint32_t i, bool pushOut) {
  if (i >= in.instanceCount)
    throw Error("reference positions: instance " + std::to_string(i) + " of " + std::to_string(in.instanceCount));
  const size_t k = size_t(m.meshComponents()), j = m.skeleton.size();
  if (in.meshWeights.size() < (i + 1) * k || in.skinMatrices.size() < (i + 1) * j)
    throw Error("reference positions: frame inputs too short for instance " + std::to_string(i));
  if (!in.meshComponents.empty() && in.meshComponents.size() != in.instanceCount)
    throw Error("reference positions: " + std::to_string(in.meshComponents.size()) +
                " per-instance mesh component counts for " + std::to_string(in.instanceCount) + " instances");
  const uint32_t components = in.meshComponents.empty() ? uint32_t(k) : in.meshComponents[i];
  const Points3f pre = referencePcaReconstruct(m.meshPca, std::span(in.meshWeights).subspan(i * k, k), components);
  const std::span<const Mat4f> mats = std::span(in.skinMatrices).subspan(i * j, j);
  Points3f out = referenceSkin(pre, m.gameMesh.skin, std::vector<Mat4f>(mats.begin(), mats.end()));
  if (pushOut && !m.bodyAnchors.empty()) referencePushOut(out, m.bodyAnchors, mats);
  return out;
}

ReferenceFrameOutputs referenceFrame(const Model& m, const FrameKernelInputs& in,
                                     const std::vector<BlendedNormalMap>& prev) {
  in.validate(m);
  const MeshFrameTopology topo = buildFrameTopology(m.gameMesh.triangles, m.gameMesh.positions);
  ReferenceFrameOutputs out;
  for (uint32_t i = 0; i < in.instanceCount; ++i) {
    out.positions.push_back(referencePositions(m, in, i, in.pushOut));
    ReferenceTangentFrames f = referenceTangentFrames(out.positions.back(), m.gameMesh, topo);
    out.normals.push_back(std::move(f.normals));
    out.tangents.push_back(std::move(f.tangents));
  }
  if (!in.selectedMaps.empty() && !m.normalMaps.empty()) {  // (all kNoMap where the model has no database)
    if (!prev.empty() && prev.size() != in.instanceCount)
      throw Error("reference frame: " + std::to_string(prev.size()) + " previous maps for " +
                  std::to_string(in.instanceCount) + " instances");
    const auto& db = m.normalMaps;
    for (uint32_t i = 0; i < in.instanceCount; ++i) {
      BlendedNormalMap map = prev.empty() ? BlendedNormalMap::zeros(db.width, db.height) : prev[i];
      if (in.selectedMaps[i] != kNoMap)  // else no decode and no blend: the map stays as it was
        referenceNormalBlend(map, referenceVqDecode(db, in.selectedMaps[i]), in.blendAlpha[i]);
      out.normalMaps.push_back(std::move(map));
    }
  }
  return out;
}

}  // namespace swish::runtime
