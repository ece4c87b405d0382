#pragma once
// Recorded pose streams: what a game records of a character, frame by frame, for `swish replay`.
// A JSON file:
//   {
//     "format": "swish-pose-stream", "version": 1,
//     "framesPerSecond": 30,
//     "joints": ["Hips", "LowerBack", ...],          names; matched to the model's skeleton by name
//     "frames": [
//       { "root": [x, y, z],                          root translation, metres, character space
//         "rotations": [[x, y, z, w], ...] },         local rotations, one per listed joint
//       ...
//     ]
//   }
// Bad data is read, not rejected, so that the replay can report it with its frame and character and go
// on (see character_motion.hpp for how each case is handled): a component that is null (JSON has no
// NaN) reads as NaN, a rotation that is null or absent (a shorter "rotations" array) is a missing joint.
// Structural problems (not JSON, wrong types, no frames) are an Error naming the file and JSON path.
#include <filesystem>
#include <string>
#include <vector>

#include "swish/core/types.hpp"

namespace swish::replay {

struct PoseStreamFrame {
  Vec3f root = Vec3f::Zero();    // NaN components when the file had null
  std::vector<Quatf> rotations;  // per stream joint
  std::vector<bool> present;     // false: the joint was missing in this frame
};

struct PoseStream {
  std::string name;
  double framesPerSecond = 30.0;
  std::vector<std::string> joints;
  std::vector<PoseStreamFrame> frames;
};

PoseStream readPoseStream(const std::filesystem::path& file);
// Writes atomically. NaN components are written as null, absent joints as null.
void writePoseStream(const std::filesystem::path& file, const PoseStream& stream);

}  // namespace swish::replay
