#include "swish/io/joint_map.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <unordered_map>

#include "swish/core/error.hpp"
#include "swish/files/json_file.hpp"
#include "swish/files/json_reader.hpp"

namespace swish::io {
namespace {

struct NamePair {
  const char* clip;
  const char* cmu;
};

// Mixamo's spine has one more segment below the neck than CMU's; the chest (Spine2) drives Spine1.
// Variants within the CMU family itself: the BVH clips call the finger joint LFingers, exporters of
// CMU-named rigs (MakeHuman's, the shared test character) call it LeftHandFinger1.
constexpr NamePair kCmuVariants[] = {
    {"lfingers", "LeftHandFinger1"},
    {"rfingers", "RightHandFinger1"},
    {"lefthandfinger1", "LFingers"},
    {"righthandfinger1", "RFingers"},
};

constexpr NamePair kMixamoToCmu[] = {
    {"hips", "Hips"},
    {"spine", "LowerBack"},
    {"spine1", "Spine"},
    {"spine2", "Spine1"},
    {"neck", "Neck"},
    {"head", "Head"},
    {"leftshoulder", "LeftShoulder"},
    {"leftarm", "LeftArm"},
    {"leftforearm", "LeftForeArm"},
    {"lefthand", "LeftHand"},
    {"lefthandthumb1", "LThumb"},
    {"lefthandindex1", "LeftFingerBase"},
    {"lefthandindex2", "LeftHandFinger1"},
    {"rightshoulder", "RightShoulder"},
    {"rightarm", "RightArm"},
    {"rightforearm", "RightForeArm"},
    {"righthand", "RightHand"},
    {"righthandthumb1", "RThumb"},
    {"righthandindex1", "RightFingerBase"},
    {"righthandindex2", "RightHandFinger1"},
    {"leftupleg", "LeftUpLeg"},
    {"leftleg", "LeftLeg"},
    {"leftfoot", "LeftFoot"},
    {"lefttoebase", "LeftToeBase"},
    {"rightupleg", "RightUpLeg"},
    {"rightleg", "RightLeg"},
    {"rightfoot", "RightFoot"},
    {"righttoebase", "RightToeBase"},
};

constexpr NamePair kUnrealToCmu[] = {
    {"pelvis", "Hips"},
    {"spine01", "LowerBack"},
    {"spine02", "Spine"},
    {"spine03", "Spine1"},
    {"neck01", "Neck"},
    {"head", "Head"},
    {"claviclel", "LeftShoulder"},
    {"upperarml", "LeftArm"},
    {"lowerarml", "LeftForeArm"},
    {"handl", "LeftHand"},
    {"thumb01l", "LThumb"},
    {"index01l", "LeftFingerBase"},
    {"clavicler", "RightShoulder"},
    {"upperarmr", "RightArm"},
    {"lowerarmr", "RightForeArm"},
    {"handr", "RightHand"},
    {"thumb01r", "RThumb"},
    {"index01r", "RightFingerBase"},
    {"thighl", "LeftUpLeg"},
    {"calfl", "LeftLeg"},
    {"footl", "LeftFoot"},
    {"balll", "LeftToeBase"},
    {"thighr", "RightUpLeg"},
    {"calfr", "RightLeg"},
    {"footr", "RightFoot"},
    {"ballr", "RightToeBase"},
};

constexpr int kDrivenByChain = -2;  // mapWith's mark while matching names: not free for a clip joint

JointMapping mapWith(const std::vector<std::string>& clip, const Skeleton& character, JointNaming naming,
                     const JointMapOptions& options) {
  JointMapping m;
  m.naming = naming;
  m.sourceOf.assign(character.size(), -1);
  std::vector<bool> used(clip.size(), false);
  auto assign = [&](int charJoint, int clipJoint) {
    if (charJoint < 0 || clipJoint < 0 || m.sourceOf[size_t(charJoint)] != -1 || used[size_t(clipJoint)]) return;
    m.sourceOf[size_t(charJoint)] = clipJoint;
    used[size_t(clipJoint)] = true;
  };
  std::unordered_map<std::string, int> clipByNorm;
  for (size_t i = 0; i < clip.size(); ++i) clipByNorm.emplace(normaliseJointName(clip[i]), int(i));
  auto clipIndex = [&](const std::string& name) {
    auto it = clipByNorm.find(normaliseJointName(name));
    return it == clipByNorm.end() ? -1 : it->second;
  };
  for (const auto& [clipName, charName] : options.explicitPairs) {
    const int c = clipIndex(clipName), j = character.find(charName);
    if (j < 0) throw Error("joint map: character has no joint '" + charName + "' (explicit pair '" + clipName + "')");
    assign(j, c);
  }
  // A chain's joints other than its last are driven through it (retarget.hpp), never by a clip joint
  // of the same name.
  for (const JointChain& chain : options.chains)
    for (size_t i = 0; i < chain.joints.size(); ++i) {
      const int j = character.find(chain.joints[i]);
      if (j < 0) throw Error("joint map: character has no joint '" + chain.joints[i] + "' (a chain)");
      if (i + 1 < chain.joints.size()) m.sourceOf[size_t(j)] = kDrivenByChain;
    }
  auto table = [&](const NamePair* begin, const NamePair* end) {
    for (const NamePair* p = begin; p != end; ++p) assign(character.find(p->cmu), clipIndex(p->clip));
  };
  if (naming == JointNaming::Mixamo) table(std::begin(kMixamoToCmu), std::end(kMixamoToCmu));
  if (naming == JointNaming::Unreal) table(std::begin(kUnrealToCmu), std::end(kUnrealToCmu));
  // Names that agree after normalisation (the whole map for naming == Same), then CMU variants.
  for (size_t j = 0; j < character.size(); ++j) assign(int(j), clipIndex(character.joints[j].name));
  table(std::begin(kCmuVariants), std::end(kCmuVariants));
  for (int& s : m.sourceOf)
    if (s == kDrivenByChain) s = -1;
  return m;
}

// A joint name: a non-empty string.
std::string jointName(const JsonReader& r) {
  const nlohmann::json& v = r.value();
  if (!v.is_string()) r.fail("must be a non-empty joint name, is " + std::string(v.type_name()));
  if (v.get<std::string>().empty()) r.fail("must be a non-empty joint name");
  return v.get<std::string>();
}

}  // namespace

JointMapOptions parseJointMap(const JsonReader& map) {
  if (!map.value().is_object())
    map.fail("must be a JSON object {\"clip joint\": \"character joint\" or [chain joints, parent first]}");
  JointMapOptions out;
  for (const auto& [clipJoint, value] : map.value().items()) {
    if (clipJoint.empty())
      JsonReader(value, map.source(), map.path().empty() ? "\"\"" : map.path() + ".\"\"")
          .fail("an empty clip joint name");
    const JsonReader v = map.child(clipJoint);
    if (v.value().is_string()) {
      out.explicitPairs.emplace_back(clipJoint, jointName(v));
      continue;
    }
    // A chain: an array of joints, or {"joints": [..], "shares": [..]}.
    if (v.value().is_object()) {
      v.requireObject({"joints", "shares"});
      if (!v.has("joints")) v.child("joints").fail("is required (the chain, parent first)");
    } else if (!v.value().is_array()) {
      v.fail("must be a character joint name, an array of chain joints or {\"joints\", \"shares\"}");
    }
    const JsonReader joints = v.value().is_object() ? v.child("joints") : v;
    if (!joints.value().is_array() || joints.value().empty())
      joints.fail("a chain must list at least one character joint, parent first");
    JointChain chain;
    for (size_t i = 0; i < joints.value().size(); ++i) chain.joints.push_back(jointName(joints.at(i)));
    if (v.value().is_object() && v.has("shares")) {
      const JsonReader shares = v.child("shares");
      if (!shares.value().is_array() || shares.value().size() != chain.joints.size())
        shares.fail("must hold one number per chain joint (" + std::to_string(chain.joints.size()) + ")");
      double sum = 0.0;
      for (size_t i = 0; i < chain.joints.size(); ++i) {
        const double x = shares.at(i).number(0.0, 1.0);
        chain.shares.push_back(float(x));
        sum += x;
      }
      if (std::abs(sum - 1.0) > 1e-3) shares.fail("must sum to 1 (they sum to " + std::to_string(sum) + ")");
    } else {
      chain.shares.assign(chain.joints.size(), 1.f / float(chain.joints.size()));
    }
    out.explicitPairs.emplace_back(clipJoint, chain.joints.back());
    if (chain.joints.size() > 1) out.chains.push_back(std::move(chain));
  }
  return out;
}

JointMapOptions parseJointMap(const nlohmann::json& json, const std::string& what) {
  return parseJointMap(JsonReader(json, "", what));  // no source: every message starts with `what`
}

JointMapOptions readJointMapFile(const std::filesystem::path& file) {
  const nlohmann::json j = readJsonFile(file, "joint map file");
  return parseJointMap(JsonReader(j, file.string()));
}

nlohmann::json jointMapToJson(const JointMapOptions& map) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [clip, character] : map.explicitPairs) {
    out[clip] = character;
    for (const JointChain& c : map.chains)
      if (!c.joints.empty() && c.joints.back() == character) out[clip] = {{"joints", c.joints}, {"shares", c.shares}};
  }
  return out;
}

size_t JointMapping::mappedCount() const {
  return size_t(std::count_if(sourceOf.begin(), sourceOf.end(), [](int s) { return s >= 0; }));
}

std::string normaliseJointName(const std::string& name) {
  std::string s = name;
  const size_t cut = s.find_last_of(":|");
  if (cut != std::string::npos) s = s.substr(cut + 1);
  std::string out;
  for (unsigned char c : s)
    if (c != '_' && c != ' ' && c != '.' && c != '-') out += char(std::tolower(c));
  return out;
}

const char* jointNamingName(JointNaming n) {
  switch (n) {
    case JointNaming::Auto:
      return "auto";
    case JointNaming::Same:
      return "same names";
    case JointNaming::Mixamo:
      return "Mixamo";
    case JointNaming::Unreal:
      return "Unreal";
  }
  return "?";
}

JointMapping mapJoints(const std::vector<std::string>& clip, const Skeleton& character,
                       const JointMapOptions& options) {
  if (options.naming != JointNaming::Auto) return mapWith(clip, character, options.naming, options);
  // A Mixamo clip also matches many CMU names as they are (LeftArm...), but its spine is off by one:
  // prefer a convention only when it maps strictly more joints, and Mixamo when the clip has Spine2.
  JointMapping best = mapWith(clip, character, JointNaming::Same, options);
  const bool hasSpine2 =
      std::any_of(clip.begin(), clip.end(), [](const std::string& n) { return normaliseJointName(n) == "spine2"; });
  for (JointNaming n : {JointNaming::Mixamo, JointNaming::Unreal}) {
    JointMapping m = mapWith(clip, character, n, options);
    if (m.mappedCount() > best.mappedCount() ||
        (n == JointNaming::Mixamo && hasSpine2 && m.mappedCount() >= best.mappedCount()))
      best = std::move(m);
  }
  return best;
}

}  // namespace swish::io
