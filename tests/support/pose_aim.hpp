#pragma once
// Test poses built by turning joints in character space: a joint's first child, a character-space turn
// of one joint (and everything below it), and a bone aimed along a direction. Shared by the limb
// clearance tests and the cloth stability cases, which aim arms through the chest, overhead and so on.
#include <stdexcept>
#include <string>
#include <vector>

#include "swish/core/character.hpp"

namespace swish::test {

// The first joint whose parent is `j` (-1: none).
inline int childOf(const Skeleton& sk, int j) {
  for (size_t c = 0; c < sk.size(); ++c)
    if (sk.joints[c].parent == j) return int(c);
  return -1;
}

// Applies the character-space rotation `r` to joint `name` (and so to everything below it). Throws
// std::invalid_argument for a joint the skeleton lacks.
inline void turnWorld(const Skeleton& sk, Pose& p, const std::string& name, const Quatf& r) {
  const int j = sk.find(name);
  if (j < 0) throw std::invalid_argument("no joint " + name);
  const std::vector<RigidTransform> g = sk.globalTransforms(p);
  const int parent = sk.joints[size_t(j)].parent;
  const Quatf parentWorld = parent >= 0 ? g[size_t(parent)].rotation : Quatf::Identity();
  p.local[size_t(j)] = (parentWorld.conjugate() * r * g[size_t(j)].rotation).normalized();
}

// Turns joint `name` so that its bone (towards its first child) points along `dir` (character space).
// Throws std::invalid_argument for a joint the skeleton lacks or one without a child.
inline void aim(const Skeleton& sk, Pose& p, const std::string& name, const Vec3f& dir) {
  const int j = sk.find(name);
  const int c = j >= 0 ? childOf(sk, j) : -1;
  if (c < 0) throw std::invalid_argument("no joint " + name + " with a child");
  const std::vector<RigidTransform> g = sk.globalTransforms(p);
  const Vec3f bone = (g[size_t(c)].translation - g[size_t(j)].translation).normalized();
  turnWorld(sk, p, name, Quatf::FromTwoVectors(bone, dir.normalized()));
}

}  // namespace swish::test
