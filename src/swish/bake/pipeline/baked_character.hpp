#pragma once
// The character a model was baked on, found again from the bake settings its metadata carries
// ("dataset_settings", written by part 2 from part 1's settings): the embedded default character
// (rebuilt by code), the default character from a recipe file, or a glTF/FBX file with its mesh names.
// Files are looked for as the bake wrote them, then beside the model file. `swish replay --truth-every`
// rebuilds the source simulation on it; `swish render` draws its body.
#include <filesystem>
#include <string>

#include "swish/bake/pipeline/part1_dataset.hpp"

namespace swish::bake {

struct BakedCharacter {
  enum class Kind { Unknown, EmbeddedDefault, Recipe, File };
  Kind kind = Kind::Unknown;       // Unknown: the metadata names no bake (a procedural or hand-made model)
  DatasetBuildSettings settings;   // the character fields, and the bake's input joints when it named them
  std::string description;         // "the embedded default character", "recipe <path>", "<path>"
  std::string named;               // the file the bake named (Recipe, File), as written
  std::string problem;             // non-empty: why the character cannot be had here (e.g. the file is missing)
  nlohmann::json datasetSettings;  // the metadata's "dataset_settings" object (null when Unknown)

  bool available() const { return kind != Kind::Unknown && problem.empty(); }
};

// Never throws on metadata it cannot read: kind Unknown and `problem` say what was missing.
BakedCharacter findBakedCharacter(const std::string& modelMetadataJson, const std::filesystem::path& modelFile);

// The character to draw a model on (`swish render --character`): "auto" is the one it was baked on
// (the embedded default when the metadata names no bake; an Error naming the missing file and the
// option to pass when it cannot be had), "default" the embedded mannequin, anything else a glTF/FBX file.
// `label` names the body for the person reading the output.
Character characterToDraw(const std::string& choice, const std::string& modelMetadataJson,
                          const std::filesystem::path& modelFile, std::string& label);

}  // namespace swish::bake
