#include "swish/bake/pipeline/baked_character.hpp"

#include <system_error>

#include "swish/bake/character/default_character.hpp"
#include "swish/core/error.hpp"
#include "swish/io/character_import.hpp"

namespace swish::bake {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string str(const json& j, const char* key) {
  return j.is_object() && j.contains(key) && j.at(key).is_string() ? j.at(key).get<std::string>() : std::string();
}
std::vector<std::string> strings(const json& j, const char* key) {
  std::vector<std::string> out;
  if (j.is_object() && j.contains(key) && j.at(key).is_array())
    for (const auto& e : j.at(key))
      if (e.is_string()) out.push_back(e.get<std::string>());
  return out;
}

// A file the bake named: as written, else beside the model file.
fs::path findBakeFile(const std::string& name, const fs::path& modelFile) {
  std::error_code ec;
  if (fs::is_regular_file(name, ec)) return name;
  if (!modelFile.empty() && fs::path(name).is_relative() && fs::is_regular_file(modelFile.parent_path() / name, ec))
    return modelFile.parent_path() / name;
  return {};
}

}  // namespace

BakedCharacter findBakedCharacter(const std::string& modelMetadataJson, const fs::path& modelFile) {
  BakedCharacter out;
  const json meta = json::parse(modelMetadataJson, nullptr, false);
  if (meta.is_discarded() || !meta.is_object() || !meta.contains("dataset_settings") ||
      !meta["dataset_settings"].is_object()) {
    out.problem =
        "the model's metadata has no bake settings (\"dataset_settings\", written by swish bake): the character "
        "it was baked on is unknown";
    return out;
  }
  out.datasetSettings = meta["dataset_settings"];
  const json chj = out.datasetSettings.value("character", json::object());
  DatasetBuildSettings& s = out.settings;
  s.inputJoints = strings(out.datasetSettings, "input_joints");
  if (const std::string file = str(chj, "file"); !file.empty()) {
    out.kind = BakedCharacter::Kind::File;
    out.named = file;
    s.characterFile = findBakeFile(file, modelFile);
    s.bodyMeshNames = strings(chj, "body_mesh");
    s.garmentMeshNames = strings(chj, "garment_mesh");
    s.simulationMeshNames = strings(chj, "simulation_mesh");
    out.description = s.characterFile.empty() ? file : s.characterFile.string();
    if (s.characterFile.empty())
      out.problem = "the bake's character file " + file + " is not at hand (looked as written and beside the model)";
  } else if (const std::string recipe = str(chj, "recipe"); !recipe.empty()) {
    out.kind = BakedCharacter::Kind::Recipe;
    out.named = recipe;
    s.characterRecipe = findBakeFile(recipe, modelFile);
    out.description =
        "the default character from recipe " + (s.characterRecipe.empty() ? recipe : s.characterRecipe.string());
    if (s.characterRecipe.empty())
      out.problem =
          "the bake's character recipe " + recipe + " is not at hand (looked as written and beside the model)";
  } else {
    out.kind = BakedCharacter::Kind::EmbeddedDefault;
    out.description = "the embedded default character, rebuilt by code";
  }
  return out;
}

Character characterToDraw(const std::string& choice, const std::string& modelMetadataJson, const fs::path& modelFile,
                          std::string& label) {
  if (choice == "default") {
    label = "the embedded default mannequin";
    return makeDefaultCharacter();
  }
  if (choice != "auto") {
    label = "the body of " + choice;
    return io::importCharacter(choice);
  }
  BakedCharacter baked = findBakedCharacter(modelMetadataJson, modelFile);
  if (baked.kind == BakedCharacter::Kind::Unknown) {
    label = "the embedded default mannequin (the model names no bake character)";
    return makeDefaultCharacter();
  }
  if (!baked.problem.empty())
    throw Error(modelFile.string() + ": " + baked.problem +
                "; pass --character FILE with the character the model was baked on (" + baked.named +
                "), or --character default (the embedded mannequin) or none");
  label = "the body it was baked on, " + baked.description;
  return loadDatasetCharacter(baked.settings);
}

}  // namespace swish::bake
