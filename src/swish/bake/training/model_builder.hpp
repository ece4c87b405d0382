#pragma once
// Assembles the .swish Model from the pieces the bake produced (paper 2.3's run-time data): skeleton,
// Theta joints, MLP with its norms, mesh PCA, the game mesh with rest normals/tangents (computed with
// core/mesh_frames, the one definition the runtime shares), the VQ normal-map database, the temporal
// filter and metadata JSON. The result is validated before it is returned.
#include <nlohmann/json.hpp>

#include "swish/bake/compression/pca.hpp"
#include "swish/bake/training/mlp_trainer.hpp"
#include "swish/core/character.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct ModelParts {
  const Character* character = nullptr;  // skeleton + garment (game mesh, skinned, with UVs)
  std::vector<uint32_t> inputJoints;
  bool rootGravity = false;  // Theta ends with the gravity direction in the root's frame (Model::rootGravity)
  const MlpTrainResult* regressor = nullptr;
  const PcaResult* meshPca = nullptr;  // over 3N pre-skin coordinates (vertex v, axis a at 3v + a)
  NormalMapDatabase normalMaps;        // keys + VQ data (may be empty)
  TemporalFilterParams temporalFilter;
  nlohmann::json metadata = nlohmann::json::object();
};

// Throws Error if a part is missing, sizes disagree (e.g. the MLP's output is not K + C), the MLP was
// trained with an activation the runtime does not run (only SELU), or Model::validate fails.
Model buildModel(const ModelParts& parts);

}  // namespace swish::bake
