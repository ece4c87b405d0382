#pragma once
// Animation as a file carries it, before retargeting: the clip's own skeleton (names, parents, rest
// local transforms in the file's units) and, per frame, every joint's local transform. The BVH reader
// and the assimp reader produce it; retarget.hpp maps it onto a character.
#include <filesystem>
#include <string>
#include <vector>

#include "swish/core/types.hpp"

namespace swish::io {

struct SourceAnimation {
  std::string name;
  std::vector<std::string> jointNames;  // parents before children
  std::vector<int> parents;             // -1 for roots
  std::vector<RigidTransform> rest;     // local rest transforms (BVH: offset, identity rotation)
  double framesPerSecond = 30.0;
  std::vector<std::vector<RigidTransform>> frames;  // frames[f][j]: local transform of joint j

  size_t jointCount() const { return jointNames.size(); }
  int find(const std::string& name) const;
  // Character-space (clip-space) transforms of all joints, for the rest pose or a frame.
  std::vector<RigidTransform> restGlobals() const;
  std::vector<RigidTransform> frameGlobals(size_t frame) const;
};

// Any format assimp reads with node animation (glTF, FBX, BVH, Collada...): the nodes of the scene
// become the joints, the first animation is sampled at its key times' rate (`fps`, or the file's ticks
// per second when 0, capped to 240). Scale keys are ignored (only rotations and root translation matter
// for cloth). Throws Error naming the file for missing files, unreadable files, or files with no animation.
SourceAnimation readAnimationWithAssimp(const std::filesystem::path& file, double fps = 0.0);

}  // namespace swish::io
