#pragma once
// Which joint of an animation clip drives which joint of a character. Names are compared after
// normalisation (namespace prefixes such as "mixamorig:" or "Armature|" dropped, case and '_', ' ', '.'
// ignored). Where a clip's naming differs from the character's (CMU), a small table of conventions
// translates it: Mixamo and Unreal mannequin names onto CMU names. Explicit pairs override everything.
#include <string>
#include <utility>
#include <vector>

#include "swish/core/skeleton.hpp"

namespace swish::io {

enum class JointNaming { Auto, Same, Mixamo, Unreal };

struct JointMapOptions {
  JointNaming naming = JointNaming::Auto;  // Auto: whichever convention maps the most joints
  // Explicit clip joint name -> character joint name pairs, applied first.
  std::vector<std::pair<std::string, std::string>> explicitPairs;
};

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
