#include "swish/bake/character/default_character_recipe.hpp"

#include <cctype>
#include <cmath>
#include <set>

#include "swish/core/error.hpp"
#include "swish/core/skeleton.hpp"
#include "swish/files/json_file.hpp"

namespace swish::bake {
namespace {

// Byte-for-byte the committed assets/default/recipe.json (test_default_character checks it).
constexpr const char* kEmbeddedRecipe = R"recipe({
  "format": "swish-default-character-recipe",
  "version": 1,
  "name": "swish_default_mannequin",
  "units": "metres, Y up, faces +Z, feet at y = 0, rest pose: A-pose (upper arms 50 degrees below horizontal)",
  "skeleton": {
    "mirror": true,
    "joints": [
      {"name": "Hips", "parent": "", "head": [0.0, 0.98, 0.0]},
      {"name": "LHipJoint", "parent": "Hips", "head": [0.0, 0.98, 0.0]},
      {"name": "LeftUpLeg", "parent": "LHipJoint", "head": [0.095, 0.93, 0.0]},
      {"name": "LeftLeg", "parent": "LeftUpLeg", "head": [0.105, 0.51, 0.01]},
      {"name": "LeftFoot", "parent": "LeftLeg", "head": [0.115, 0.09, -0.02]},
      {"name": "LeftToeBase", "parent": "LeftFoot", "head": [0.125, 0.02, 0.12]},
      {"name": "LowerBack", "parent": "Hips", "head": [0.0, 1.03, -0.01]},
      {"name": "Spine", "parent": "LowerBack", "head": [0.0, 1.18, -0.01]},
      {"name": "Spine1", "parent": "Spine", "head": [0.0, 1.33, -0.01]},
      {"name": "LeftShoulder", "parent": "Spine1", "head": [0.03, 1.44, 0.0]},
      {"name": "LeftArm", "parent": "LeftShoulder", "head": [0.18, 1.43, -0.02]},
      {"name": "LeftForeArm", "parent": "LeftArm", "head": [0.366, 1.208, -0.02]},
      {"name": "LeftHand", "parent": "LeftForeArm", "head": [0.533, 1.009, 0.0]},
      {"name": "LThumb", "parent": "LeftHand", "head": [0.545, 0.985, 0.03]},
      {"name": "LeftFingerBase", "parent": "LeftHand", "head": [0.555, 0.982, 0.0]},
      {"name": "LeftHandFinger1", "parent": "LeftFingerBase", "head": [0.585, 0.946, 0.0]},
      {"name": "Neck", "parent": "Spine1", "head": [0.0, 1.50, -0.015]},
      {"name": "Neck1", "parent": "Neck", "head": [0.0, 1.56, 0.0]},
      {"name": "Head", "parent": "Neck1", "head": [0.0, 1.62, 0.01]}
    ]
  },
  "body": {
    "ringSegments": 28,
    "parts": [
      {"name": "torso", "mirror": false, "ringsPerSpan": 4, "segments": 36, "stations": [
        {"joint": "Hips", "center": [0.0, 0.84, 0.0], "halfWidth": 0.10, "halfDepth": 0.08},
        {"joint": "Hips", "center": [0.0, 0.90, 0.0], "halfWidth": 0.165, "halfDepth": 0.105},
        {"joint": "Hips", "center": [0.0, 0.97, 0.0], "halfWidth": 0.175, "halfDepth": 0.112},
        {"joint": "LowerBack", "center": [0.0, 1.05, 0.0], "halfWidth": 0.16, "halfDepth": 0.105},
        {"joint": "LowerBack", "center": [0.0, 1.12, 0.0], "halfWidth": 0.152, "halfDepth": 0.10},
        {"joint": "Spine", "center": [0.0, 1.20, 0.0], "halfWidth": 0.158, "halfDepth": 0.105},
        {"joint": "Spine", "center": [0.0, 1.28, 0.005], "halfWidth": 0.172, "halfDepth": 0.115},
        {"joint": "Spine1", "center": [0.0, 1.35, 0.005], "halfWidth": 0.185, "halfDepth": 0.118},
        {"joint": "Spine1", "center": [0.0, 1.41, 0.0], "halfWidth": 0.2, "halfDepth": 0.112},
        {"joint": "Spine1", "center": [0.0, 1.455, -0.005], "halfWidth": 0.19, "halfDepth": 0.095},
        {"joint": "Spine1", "center": [0.0, 1.49, -0.01], "halfWidth": 0.12, "halfDepth": 0.07},
        {"joint": "Neck", "center": [0.0, 1.51, -0.012], "halfWidth": 0.06, "halfDepth": 0.055}
      ]},
      {"name": "head", "mirror": false, "ringsPerSpan": 4, "segments": 24, "stations": [
        {"joint": "Neck", "center": [0.0, 1.48, -0.015], "halfWidth": 0.056, "halfDepth": 0.054},
        {"joint": "Neck1", "center": [0.0, 1.57, 0.0], "halfWidth": 0.054, "halfDepth": 0.054},
        {"joint": "Head", "center": [0.0, 1.64, 0.02], "halfWidth": 0.078, "halfDepth": 0.09},
        {"joint": "Head", "center": [0.0, 1.72, 0.02], "halfWidth": 0.085, "halfDepth": 0.1},
        {"joint": "Head", "center": [0.0, 1.80, 0.01], "halfWidth": 0.06, "halfDepth": 0.07},
        {"joint": "Head", "center": [0.0, 1.835, 0.005], "halfWidth": 0.02, "halfDepth": 0.02}
      ]},
      {"name": "LeftArmPart", "mirror": true, "ringsPerSpan": 6, "segments": 16, "stations": [
        {"joint": "LeftArm", "at": "LeftArm", "offset": [0.005, -0.005, 0.0], "halfWidth": 0.056, "halfDepth": 0.056},
        {"joint": "LeftArm", "at": "LeftArm", "offset": [0.06, -0.07, 0.0], "halfWidth": 0.055, "halfDepth": 0.052},
        {"joint": "LeftForeArm", "at": "LeftForeArm", "halfWidth": 0.043, "halfDepth": 0.043},
        {"joint": "LeftHand", "at": "LeftHand", "halfWidth": 0.032, "halfDepth": 0.026},
        {"joint": "LeftHand", "at": "LeftHandFinger1", "halfWidth": 0.04, "halfDepth": 0.016},
        {"joint": "LeftHandFinger1", "at": "LeftHandFinger1", "offset": [0.045, -0.055, 0.0], "halfWidth": 0.012, "halfDepth": 0.008}
      ]},
      {"name": "LeftLegPart", "mirror": true, "ringsPerSpan": 5, "segments": 16, "stations": [
        {"joint": "LeftUpLeg", "at": "LeftUpLeg", "offset": [0.0, 0.02, 0.0], "halfWidth": 0.085, "halfDepth": 0.09},
        {"joint": "LeftUpLeg", "at": "LeftUpLeg", "offset": [0.004, -0.2, 0.01], "halfWidth": 0.075, "halfDepth": 0.078},
        {"joint": "LeftLeg", "at": "LeftLeg", "halfWidth": 0.053, "halfDepth": 0.055},
        {"joint": "LeftLeg", "at": "LeftLeg", "offset": [0.004, -0.16, -0.015], "halfWidth": 0.05, "halfDepth": 0.058},
        {"joint": "LeftFoot", "at": "LeftFoot", "offset": [0.0, 0.02, 0.0], "halfWidth": 0.036, "halfDepth": 0.038}
      ]},
      {"name": "LeftFootPart", "mirror": true, "ringsPerSpan": 4, "segments": 14, "stations": [
        {"joint": "LeftFoot", "at": "LeftFoot", "offset": [0.0, -0.01, -0.06], "halfWidth": 0.035, "halfDepth": 0.04},
        {"joint": "LeftFoot", "at": "LeftFoot", "offset": [0.0, -0.05, 0.02], "halfWidth": 0.045, "halfDepth": 0.035},
        {"joint": "LeftToeBase", "at": "LeftToeBase", "halfWidth": 0.045, "halfDepth": 0.02},
        {"joint": "LeftToeBase", "at": "LeftToeBase", "offset": [0.0, 0.0, 0.07], "halfWidth": 0.02, "halfDepth": 0.012}
      ]}
    ],
    "blends": [
      {"joint": "LeftArm", "at": "LeftArm", "offset": [0.0, -0.02, 0.0], "radius": 0.09, "mirror": true},
      {"joint": "LeftShoulder", "at": "LeftShoulder", "offset": [0.05, 0.01, 0.0], "radius": 0.08, "mirror": true},
      {"joint": "LeftUpLeg", "at": "LeftUpLeg", "offset": [0.0, -0.04, 0.0], "radius": 0.1, "mirror": true}
    ]
  },
  "jersey": {
    "offset": 0.012,
    "clearance": 0.008,
    "columns": 72,
    "rows": 34,
    "hemY": 0.93,
    "collarY": 1.505,
    "armholeBottomY": 1.31,
    "armholeTopY": 1.485,
    "armholeHalfWidth": 0.075,
    "sleeveLength": 0.14,
    "sleeveRings": 8,
    "skinTransferNeighbours": 4,
    "skinSmoothingIterations": 40,
    "maxInfluences": 4
  }
}
)recipe";

template <class T>
T get(const nlohmann::json& j, const char* key, const std::string& what) {
  if (!j.is_object() || !j.contains(key)) throw Error(what + ": missing '" + key + "'");
  try {
    return j.at(key).get<T>();
  } catch (const nlohmann::json::exception&) {
    throw Error(what + ": '" + key + "' has the wrong type");
  }
}

template <class T>
T getOr(const nlohmann::json& j, const char* key, T fallback, const std::string& what) {
  return j.contains(key) ? get<T>(j, key, what) : fallback;
}

float positive(const nlohmann::json& j, const char* key, const std::string& what, float lo = 1e-6f, float hi = 10.f) {
  const float v = get<float>(j, key, what);
  if (!std::isfinite(v) || v < lo || v > hi)
    throw Error(what + ": '" + key + "' = " + std::to_string(v) + " is outside [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "]");
  return v;
}

int count(const nlohmann::json& j, const char* key, const std::string& what, int lo, int hi) {
  const int v = get<int>(j, key, what);
  if (v < lo || v > hi)
    throw Error(what + ": '" + key + "' = " + std::to_string(v) + " is outside [" + std::to_string(lo) + ", " +
                std::to_string(hi) + "]");
  return v;
}

Vec3f vec3(const nlohmann::json& j, const char* key, const std::string& what) {
  const auto v = get<std::vector<float>>(j, key, what);
  if (v.size() != 3) throw Error(what + ": '" + key + "' must have 3 components");
  for (float x : v)
    if (!std::isfinite(x) || std::abs(x) > 10.f)
      throw Error(what + ": '" + key + "' has a non-finite or huge component");
  return {v[0], v[1], v[2]};
}

}  // namespace

DefaultCharacterRecipe parseDefaultCharacterRecipe(const nlohmann::json& j, const std::string& what) {
  if (get<std::string>(j, "format", what) != "swish-default-character-recipe")
    throw Error(what + ": not a swish default character recipe ('format')");
  if (get<int>(j, "version", what) != 1) throw Error(what + ": unsupported recipe version");
  DefaultCharacterRecipe r;
  r.name = get<std::string>(j, "name", what);
  const auto& sk = get<nlohmann::json>(j, "skeleton", what);
  r.mirrorSkeleton = getOr<bool>(sk, "mirror", true, what);
  std::set<std::string> names;
  for (const auto& jj : get<nlohmann::json>(sk, "joints", what + ": skeleton")) {
    RecipeJoint joint;
    const std::string w = what + ": skeleton joint";
    joint.name = get<std::string>(jj, "name", w);
    joint.parent = get<std::string>(jj, "parent", w + " '" + joint.name + "'");
    joint.head = vec3(jj, "head", w + " '" + joint.name + "'");
    if (!joint.parent.empty() && !names.count(joint.parent))
      throw Error(w + " '" + joint.name + "': parent '" + joint.parent + "' must be listed before it");
    if (!names.insert(joint.name).second) throw Error(w + " '" + joint.name + "' repeats");
    r.joints.push_back(joint);
  }
  if (r.joints.empty() || !r.joints[0].parent.empty())
    throw Error(what + ": the first joint must be the root (parent \"\")");
  auto known = [&](const std::string& n) {
    return names.count(n) || (r.mirrorSkeleton && names.count(mirroredJointName(n)));
  };

  const auto& body = get<nlohmann::json>(j, "body", what);
  for (const auto& pj : get<nlohmann::json>(body, "parts", what + ": body")) {
    RecipePart p;
    p.name = get<std::string>(pj, "name", what + ": body part");
    const std::string w = what + ": body part '" + p.name + "'";
    p.mirror = getOr<bool>(pj, "mirror", false, w);
    p.ringsPerSpan = count(pj, "ringsPerSpan", w, 1, 64);
    p.segments = count(pj, "segments", w, 6, 256);
    for (const auto& sj : get<nlohmann::json>(pj, "stations", w)) {
      RecipeStation s;
      s.joint = get<std::string>(sj, "joint", w);
      if (!known(s.joint)) throw Error(w + ": unknown joint '" + s.joint + "'");
      if (sj.contains("at")) {
        s.at = get<std::string>(sj, "at", w);
        if (!known(s.at)) throw Error(w + ": unknown joint '" + s.at + "'");
        if (sj.contains("offset")) s.offset = vec3(sj, "offset", w);
      } else {
        s.center = vec3(sj, "center", w);
      }
      s.halfWidth = positive(sj, "halfWidth", w, 1e-3f, 1.f);
      s.halfDepth = positive(sj, "halfDepth", w, 1e-3f, 1.f);
      p.stations.push_back(s);
    }
    if (p.stations.size() < 2) throw Error(w + ": needs at least two stations");
    r.parts.push_back(p);
  }
  if (body.contains("blends"))
    for (const auto& bj : body.at("blends")) {
      RecipeBlend b;
      b.joint = get<std::string>(bj, "joint", what + ": blend");
      b.at = get<std::string>(bj, "at", what + ": blend");
      if (!known(b.joint) || !known(b.at)) throw Error(what + ": blend refers to an unknown joint");
      if (bj.contains("offset")) b.offset = vec3(bj, "offset", what + ": blend");
      b.radius = positive(bj, "radius", what + ": blend", 1e-3f, 1.f);
      b.mirror = getOr<bool>(bj, "mirror", false, what + ": blend");
      r.blends.push_back(b);
    }

  const auto& js = get<nlohmann::json>(j, "jersey", what);
  const std::string w = what + ": jersey";
  RecipeJersey& g = r.jersey;
  g.offset = positive(js, "offset", w, 1e-3f, 0.1f);
  g.clearance = positive(js, "clearance", w, 1e-4f, 0.1f);
  g.columns = count(js, "columns", w, 16, 1024);
  g.rows = count(js, "rows", w, 4, 1024);
  g.hemY = positive(js, "hemY", w, -10.f, 10.f);
  g.collarY = positive(js, "collarY", w, -10.f, 10.f);
  g.armholeBottomY = positive(js, "armholeBottomY", w, -10.f, 10.f);
  g.armholeTopY = positive(js, "armholeTopY", w, -10.f, 10.f);
  g.armholeHalfWidth = positive(js, "armholeHalfWidth", w, 1e-3f, 1.f);
  g.sleeveLength = positive(js, "sleeveLength", w, 1e-3f, 1.f);
  g.sleeveRings = count(js, "sleeveRings", w, 1, 256);
  g.skinTransferNeighbours = count(js, "skinTransferNeighbours", w, 1, 16);
  g.skinSmoothingIterations = count(js, "skinSmoothingIterations", w, 0, 10000);
  g.maxInfluences = count(js, "maxInfluences", w, 1, 8);
  if (!(g.hemY < g.armholeBottomY && g.armholeBottomY < g.armholeTopY && g.armholeTopY < g.collarY))
    throw Error(w + ": need hemY < armholeBottomY < armholeTopY < collarY");
  return r;
}

DefaultCharacterRecipe loadDefaultCharacterRecipe(const std::filesystem::path& file) {
  return parseDefaultCharacterRecipe(readJsonFile(file, "recipe"), file.string());
}

const char* embeddedDefaultRecipeJson() { return kEmbeddedRecipe; }

DefaultCharacterRecipe embeddedDefaultRecipe() {
  return parseDefaultCharacterRecipe(nlohmann::json::parse(kEmbeddedRecipe), "embedded default recipe");
}

}  // namespace swish::bake
