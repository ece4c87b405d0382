#pragma once
// Animation import: BVH (own strict reader, bvh_reader.hpp), glTF, FBX and the other formats assimp
// reads (source_animation.hpp), retargeted onto a character's skeleton (retarget.hpp).
#include <filesystem>

#include "swish/io/retarget.hpp"

namespace swish::io {

struct AnimationImportOptions {
  RetargetOptions retarget;
  double framesPerSecond = 0.0;  // resampling rate for key-framed formats (0: from the file); BVH keeps its own
};

// Reads only the clip (no retargeting), choosing the reader by extension.
SourceAnimation readSourceAnimation(const std::filesystem::path& file, double framesPerSecond = 0.0);

// Errors name the file (and for BVH the line): missing/corrupt file, NaN values, truncated motion,
// clips whose joints do not map onto the character.
AnimationClip importAnimation(const std::filesystem::path& file, const Skeleton& character,
                              const AnimationImportOptions& options = {}, RetargetReport* report = nullptr);

}  // namespace swish::io
