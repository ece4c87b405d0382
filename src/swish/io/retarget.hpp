#pragma once
// Retargeting a clip onto a character's skeleton with rest-pose correction.
//
// The clip's rest (a BVH T-pose with its own offsets) and the character's rest (an A-pose with
// identity joint rotations) differ, so copying local rotations would be wrong. Instead, per mapped
// joint h driven by clip joint s, a rest alignment A_h (a world rotation) takes the character's rest
// bone directions (to its mapped children) onto the clip's rest bone directions: for one child the
// smallest rotation after the parent's alignment (so the twist follows the parent), for several the
// least-squares rotation (Kabsch) of all of them, or, where that is ambiguous (the directions fit best
// mirrored and two singular values nearly tie: two rotations up to 180 degrees apart fit alike), the
// smallest turn of their mean onto the clip's after the parent's alignment. Then, per frame,
//     R_h(t) = R_s(t) * R_s(rest)^-1 * A_h * R_h(rest)          (global rotations)
// so each character bone points where the clip's bone points. Unmapped joints keep their rest local
// rotation, except along a joint map chain (joint_map.hpp): there the rotation D the chain adds to its
// rest rotations (global(last) = G_parent * D * Q_last, Q_i the product of the chain's rest locals up to
// joint i) is shared out, local_i = Q_{i-1}^-1 * D^share_i * Q_i, so the last joint's global rotation
// (and all below it) stays the clip's while the bend spreads over the chain. Root translation: the character's rest
// root plus the clip root's displacement from its first frame, scaled by the ratio of the skeletons' mapped bone
// lengths (clip units -> metres).
#include <string>
#include <vector>

#include "swish/core/character.hpp"
#include "swish/io/joint_map.hpp"
#include "swish/io/source_animation.hpp"

namespace swish::io {

struct RetargetOptions {
  JointMapOptions jointMap;
  // Character joints that must be driven by the clip (Error naming the unmatched ones). The root is
  // always required.
  std::vector<std::string> requiredJoints = defaultInputJointNames();
  float rootTranslationScale = 0.f;  // 0: from the bone length ratio
};

struct RetargetReport {
  JointMapping mapping;
  float rootTranslationScale = 1.f;
  std::vector<std::string> unmappedCharacterJoints;
};

AnimationClip retarget(const SourceAnimation& clip, const Skeleton& character, const RetargetOptions& options = {},
                       RetargetReport* report = nullptr);

}  // namespace swish::io
