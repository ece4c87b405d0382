#pragma once
// Which joint of an animation clip drives which joint of a character. Names are compared after
// normalisation (namespace prefixes such as "mixamorig:" or "Armature|" dropped, case and '_', ' ', '.'
// ignored). Where a clip's naming differs from the character's (CMU), a small table of conventions
// translates it: Mixamo and Unreal mannequin names onto CMU names. Explicit pairs override everything.
//
// A clip joint may also drive a chain of character joints (JointChain): a skeleton with fewer spine
// joints than the character's (the Daz rig's abdomen + chest against CMU's LowerBack, Spine, Spine1)
// drives the chain's last joint, and that joint's rotation relative to the chain's parent is shared out
// along the chain (retarget.hpp), so the spine bends over all its joints instead of one.
//
// Joint maps as JSON (a bake recipe's clips, a scene's animation, or a file they name):
//   {"clip joint": "character joint",                       one pair
//    "chest": ["Spine", "Spine1"],                          a chain, equal shares, parent first
//    "chest": {"joints": ["Spine", "Spine1"], "shares": [0.4, 0.6]}}   a chain with its shares
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/core/skeleton.hpp"

namespace swish {
class JsonReader;
}

namespace swish::io {

enum class JointNaming { Auto, Same, Mixamo, Unreal };

// The character joints `joints` (parent first, each the next one's parent) are driven together by the
// clip joint paired with the last of them; joint i takes shares[i] of the rotation (the shares sum to 1).
struct JointChain {
  std::vector<std::string> joints;
  std::vector<float> shares;
};

struct JointMapOptions {
  JointNaming naming = JointNaming::Auto;  // Auto: whichever convention maps the most joints
  // Explicit clip joint name -> character joint name pairs, applied first.
  std::vector<std::pair<std::string, std::string>> explicitPairs;
  std::vector<JointChain> chains;  // each chain's last joint is one of explicitPairs' character joints
  bool empty() const { return explicitPairs.empty() && chains.empty(); }
};

// A joint map from its JSON form (above), read at `map`'s node: errors read "<source>: <path>.<clip joint>:
// <problem>" (files/json_reader.hpp), e.g. "recipe.json: part1.clips[3].joint_map.chest.shares[1]: 1.5 is
// outside 0..1", for a non-object, an empty or non-string joint name, an empty chain, an unknown key of a
// chain object, shares that do not match the joints, are not numbers in 0..1 or do not sum to 1.
JointMapOptions parseJointMap(const JsonReader& map);
// The same with `what` as the start of every error, the map's path ("scene.json: characters[2].animation.
// jointMap" gives "scene.json: characters[2].animation.jointMap.chest: ...").
JointMapOptions parseJointMap(const nlohmann::json& json, const std::string& what);
// A joint map file: a JSON object of the same form; errors name the file ("<file>: cannot open the joint
// map file", "<file>: not valid JSON: ...") and the JSON path ("<file>: chest.shares: must sum to 1 ...").
JointMapOptions readJointMapFile(const std::filesystem::path& file);
// The JSON form back (for manifests, fingerprints and reports).
nlohmann::json jointMapToJson(const JointMapOptions& map);

struct JointMapping {
  std::vector<int> sourceOf;  // per character joint: index of the clip joint that drives it, or -1
  JointNaming naming = JointNaming::Same;
  size_t mappedCount() const;
};

std::string normaliseJointName(const std::string& name);

// Maps clip joints (by name) onto the character's skeleton. Never maps one clip joint twice.
JointMapping mapJoints(const std::vector<std::string>& clipJointNames, const Skeleton& character,
                       const JointMapOptions& options = {});

const char* jointNamingName(JointNaming n);

}  // namespace swish::io
