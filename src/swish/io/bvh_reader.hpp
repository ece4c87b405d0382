#pragma once
// A strict BVH reader. assimp reads BVH too, but silently accepts NaN values and truncated motion
// sections; this one reports every problem with the file name and line number. Rotation channels are
// applied in the order listed (intrinsic: "Zrotation Yrotation Xrotation" means Rz * Ry * Rx), in
// degrees; position channels replace the joint's offset. "End Site" blocks are read and dropped.
#include <filesystem>
#include <istream>

#include "swish/io/source_animation.hpp"

namespace swish::io {

SourceAnimation readBvh(const std::filesystem::path& file);
// `name` stands for the file in error messages.
SourceAnimation readBvh(std::istream& in, const std::string& name);

}  // namespace swish::io
