#pragma once
// The models a scene's characters wear, each loaded once however many characters share it, and the
// embedded default model. The default is looked up in this order:
//   1. SWISH_DEFAULT_MODEL (environment): a .swish file;
//   2. assets/default/*.swish (the bake's committed default; the first in name order), searched from
//      the current folder and from the executable's folder and its parent;
//   3. otherwise a procedural stand-in (procedural_model.hpp) built on the skeleton of the Debian CMU
//      clip /usr/share/assimp/models/BVH/01_01.bvh, and every report says so (ModelEntry::label).
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/core/character.hpp"
#include "swish/model/model.hpp"
#include "swish/runtime/scene.hpp"

namespace swish::replay {

struct ModelEntry {
  std::string key;             // SceneCharacter::model
  std::filesystem::path file;  // empty for the procedural stand-in
  std::string label;           // what reports print about where the model came from
  bool procedural = false;
  Model model;
};

class ModelLibrary {
 public:
  // Loads every model the scene names (Error naming the scene, character and file on failure).
  explicit ModelLibrary(const runtime::Scene& scene);
  // For tests: models given directly, keyed as the scene names them.
  explicit ModelLibrary(std::vector<ModelEntry> entries);

  const ModelEntry& at(const std::string& key) const;
  std::map<std::string, const Model*> modelMap() const;
  const std::vector<std::unique_ptr<ModelEntry>>& entries() const { return entries_; }

  // The clip of `file` retargeted onto model `key`'s skeleton through `jointMap` (io/joint_map.hpp's
  // JSON form; null: by naming convention), imported once per (file, model, joint map). Errors in the
  // map name `source` and the JSON path from `path` (files/json_reader.hpp): "scene.json:
  // characters[2].animation.jointMap.chest: ..." for an inline map, "daz.json: chest: ..." for a map
  // file (source the file, path empty).
  std::shared_ptr<const AnimationClip> clip(const std::filesystem::path& file, const std::string& key,
                                            const nlohmann::json& jointMap = nullptr, const std::string& source = "",
                                            const std::string& path = "jointMap");

 private:
  std::vector<std::unique_ptr<ModelEntry>> entries_;
  std::map<std::tuple<std::string, std::string, std::string>, std::shared_ptr<const AnimationClip>> clips_;
};

// Where the project's assets/ folder is looked for, in order: the current folder, the swish
// executable's folder, and its parent (a build folder inside the source tree).
std::vector<std::filesystem::path> assetSearchRoots();

// The default model as described above (never throws for a missing asset when the clip exists).
ModelEntry loadDefaultModel();
// The CMU skeleton of a BVH file in metres, standing on y = 0, identity rest rotations.
Skeleton skeletonFromBvh(const std::filesystem::path& bvh);

}  // namespace swish::replay
