#include "swish/io/animation_import.hpp"

#include <algorithm>

#include "swish/core/error.hpp"
#include "swish/io/bvh_reader.hpp"

namespace swish::io {

SourceAnimation readSourceAnimation(const std::filesystem::path& file, double framesPerSecond) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  if (ext == ".bvh") return readBvh(file);
  return readAnimationWithAssimp(file, framesPerSecond);
}

AnimationClip importAnimation(const std::filesystem::path& file, const Skeleton& character,
                              const AnimationImportOptions& options, RetargetReport* report) {
  SourceAnimation source = readSourceAnimation(file, options.framesPerSecond);
  try {
    return retarget(source, character, options.retarget, report);
  } catch (const Error& e) {
    throw Error(file.string() + ": " + e.what());
  }
}

}  // namespace swish::io
