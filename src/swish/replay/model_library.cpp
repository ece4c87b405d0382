#include "swish/replay/model_library.hpp"

#include <algorithm>
#include <cstdlib>

#include "swish/core/error.hpp"
#include "swish/files/json_reader.hpp"
#include "swish/io/animation_import.hpp"
#include "swish/io/bvh_reader.hpp"
#include "swish/model/model_file.hpp"
#include "swish/replay/procedural_model.hpp"

namespace swish::replay {

namespace {

namespace fs = std::filesystem;

// CMU's BVH export scales its ASF units (inches / 0.45): one unit is 2.54 / 0.45 cm.
constexpr float kCmuBvhUnitMetres = 0.0254f / 0.45f;
const fs::path kDefaultClip = "/usr/share/assimp/models/BVH/01_01.bvh";

std::vector<fs::path> defaultAssetFolders() {
  std::vector<fs::path> dirs;
  for (const fs::path& root : assetSearchRoots()) dirs.push_back(root / "assets/default");
  return dirs;
}

}  // namespace

std::vector<fs::path> assetSearchRoots() {
  std::vector<fs::path> roots = {fs::current_path()};
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    roots.push_back(exe.parent_path());
    roots.push_back(exe.parent_path().parent_path());
  }
  return roots;
}

Skeleton skeletonFromBvh(const fs::path& bvh) {
  const io::SourceAnimation a = io::readBvh(bvh);
  Skeleton s;
  for (size_t j = 0; j < a.jointCount(); ++j) {
    Joint joint;
    joint.name = a.jointNames[j];
    joint.parent = a.parents[j];
    joint.rest.translation = a.rest[j].translation * kCmuBvhUnitMetres;
    s.joints.push_back(joint);
  }
  float minY = 0.f;
  for (const auto& g : s.globalTransforms(s.restPose())) minY = std::min(minY, g.translation.y());
  s.joints[0].rest.translation.y() -= minY;  // feet on the ground
  s.computeInverseBindFromRest();
  s.validate(bvh.string());
  return s;
}

ModelEntry loadDefaultModel() {
  ModelEntry e;
  e.key = runtime::kDefaultModelName;
  if (const char* env = std::getenv("SWISH_DEFAULT_MODEL"); env && *env) {
    e.file = env;
    e.model = loadModel(e.file);
    e.label = "default model from SWISH_DEFAULT_MODEL (" + e.file.string() + ")";
    return e;
  }
  for (const fs::path& dir : defaultAssetFolders()) {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) continue;
    std::vector<fs::path> files;
    for (const auto& f : fs::directory_iterator(dir, ec))
      if (f.path().extension() == ".swish") files.push_back(f.path());
    std::sort(files.begin(), files.end());
    if (files.empty()) continue;
    e.file = files.front();
    e.model = loadModel(e.file);
    e.label = "embedded default model (" + e.file.string() + ")";
    return e;
  }
  if (!fs::exists(kDefaultClip))
    throw Error("no default model: assets/default/*.swish is absent and the CMU clip " + kDefaultClip.string() +
                " (Debian package assimp-testmodels), whose skeleton the procedural stand-in uses, is missing too");
  e.procedural = true;
  e.model = makeProceduralModel(skeletonFromBvh(kDefaultClip));
  e.label = std::string("assets/default/*.swish is absent: ") + kProceduralModelLabel + ", on the skeleton of " +
            kDefaultClip.string();
  return e;
}

ModelLibrary::ModelLibrary(const runtime::Scene& scene) {
  const std::string where = scene.source.empty() ? std::string("scene") : scene.source.string();
  for (size_t c = 0; c < scene.characters.size(); ++c) {
    const std::string& key = scene.characters[c].model;
    bool have = false;
    for (const auto& e : entries_) have = have || e->key == key;
    if (have) continue;
    try {
      if (key == runtime::kDefaultModelName) {
        entries_.push_back(std::make_unique<ModelEntry>(loadDefaultModel()));
      } else {
        auto e = std::make_unique<ModelEntry>();
        e->key = key;
        e->file = key;
        e->model = loadModel(key);
        e->label = key;
        entries_.push_back(std::move(e));
      }
    } catch (const Error& err) {
      throw Error(where + ": characters[" + std::to_string(c) + "].model: " + err.what());
    }
  }
}

ModelLibrary::ModelLibrary(std::vector<ModelEntry> entries) {
  for (auto& e : entries) entries_.push_back(std::make_unique<ModelEntry>(std::move(e)));
}

const ModelEntry& ModelLibrary::at(const std::string& key) const {
  for (const auto& e : entries_)
    if (e->key == key) return *e;
  throw Error("model '" + key + "' is not loaded");
}

std::map<std::string, const Model*> ModelLibrary::modelMap() const {
  std::map<std::string, const Model*> m;
  for (const auto& e : entries_) m[e->key] = &e->model;
  return m;
}

std::shared_ptr<const AnimationClip> ModelLibrary::clip(const fs::path& file, const std::string& key,
                                                        const nlohmann::json& jointMap, const std::string& source,
                                                        const std::string& path) {
  auto& slot = clips_[{file.string(), key, jointMap.dump()}];
  if (!slot) {
    io::AnimationImportOptions o;
    if (!jointMap.is_null()) o.retarget.jointMap = io::parseJointMap(JsonReader(jointMap, source, path));
    o.retarget.requiredJoints.clear();  // a model's input joints are checked below, by the caller's model
    for (uint32_t j : at(key).model.inputJoints)
      o.retarget.requiredJoints.push_back(at(key).model.skeleton.joints[j].name);
    slot = std::make_shared<AnimationClip>(io::importAnimation(file, at(key).model.skeleton, o));
  }
  return slot;
}

}  // namespace swish::replay
