#include "swish/bake/training/model_builder.hpp"

#include <string>

#include "swish/core/error.hpp"
#include "swish/core/mesh_frames.hpp"

namespace swish::bake {

Model buildModel(const ModelParts& p) {
  if (!p.character || !p.regressor || !p.meshPca)
    throw Error("model builder: character, regressor and mesh PCA are required");
  if (p.regressor->activation != Activation::Selu)
    throw Error("model builder: the MLP uses " + activationName(p.regressor->activation) +
                " but the .swish runtime evaluates SELU only; train with activation \"selu\" to export a model");
  const Character& ch = *p.character;
  Model m;
  m.skeleton = ch.skeleton;
  if (m.skeleton.inverseBind.size() != m.skeleton.size()) m.skeleton.computeInverseBindFromRest();
  m.inputJoints = p.inputJoints;
  m.rootGravity = p.rootGravity;
  m.inputNorm = p.regressor->inputNorm;
  m.outputNorm = p.regressor->outputNorm;
  m.mlp = p.regressor->mlp;
  m.meshPca.mean = p.meshPca->mean;
  m.meshPca.basis = p.meshPca->basis;

  m.gameMesh = ch.garment;
  if (size_t(m.gameMesh.uvs.rows()) != m.gameMesh.vertexCount())
    throw Error("model builder: the game mesh of '" + ch.name + "' needs one UV per vertex (normal maps and tangents)");
  const MeshFrameTopology topo = buildFrameTopology(m.gameMesh.triangles, m.gameMesh.positions);
  computeVertexFrames(m.gameMesh.positions, m.gameMesh.uvs, m.gameMesh.triangles, topo, m.gameMesh.normals,
                      m.gameMesh.tangents);

  m.normalMaps = p.normalMaps;
  m.temporalFilter = p.temporalFilter;
  m.metadata = p.metadata.dump();
  if (m.mlp.outputSize() != m.lambdaSize())
    throw Error("model builder: the MLP predicts " + std::to_string(m.mlp.outputSize()) +
                " values but the model needs " + std::to_string(m.meshComponents()) + " mesh weights + " +
                std::to_string(m.normalCodeDims()) + " normal-code dimensions");
  m.validate("baked model of '" + ch.name + "'");
  return m;
}

}  // namespace swish::bake
