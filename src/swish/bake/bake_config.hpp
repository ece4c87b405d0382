#pragma once
// The `swish bake CONFIG` recipe: a JSON file, validated completely before any work starts. Unknown
// keys and out-of-range values are errors naming the key ("train.codebook_size: 70000 is outside
// 1..65536"). Paths are relative to the config file's folder.
//
//   {
//     "name": "default_jersey",          model file <output>/<name>.swish, report <output>/report/
//     "output": "out",
//     "dataset": "out/dataset",          the dataset folder (bake/dataset_io.hpp): part 1 writes it,
//                                        part 2 reads it
//     "part1": { ... },                  part 1 settings (character, clips, thinning, simulation...);
//                                        passed through to part 1 as given
//     "train": {                         part 2 settings (every key optional; defaults in bake_training.hpp)
//       "mesh_components", "mesh_variance", "normal_code_dims", "database_size", "codebook_size",
//       "vq_training_blocks", "vq_iterations", "hidden_layers", "hidden_width", "activation",
//       "learning_rate", "batch_size", "max_epochs", "patience", "validation_fraction",
//       "max_training_seconds", "test_fraction", "temporal_time_constant", "seed", "bc5_baseline"
//     }
//   }
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "swish/bake/bake_training.hpp"

namespace swish::bake {

struct BakeConfig {
  std::string name = "model";
  std::filesystem::path output;
  std::filesystem::path dataset;
  nlohmann::json part1;            // null when absent
  BakeTrainSettings train;

  std::filesystem::path modelPath() const { return output / (name + ".swish"); }
  std::filesystem::path reportDir() const { return output / "report"; }
};

// `source` names the config in error messages; `baseDir` resolves relative paths.
BakeConfig parseBakeConfig(const nlohmann::json& json, const std::string& source, const std::filesystem::path& baseDir);
BakeConfig loadBakeConfig(const std::filesystem::path& file);

}  // namespace swish::bake
