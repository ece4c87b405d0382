#pragma once
// A character as the bake sees it: skeleton, skinned body, and the garment's game mesh, all in the
// rest (A-)pose, glTF units and axes (metres, Y up). Plain data; importers in io/ fill it.
#include <optional>
#include <string>
#include <vector>

#include "swish/core/mesh.hpp"
#include "swish/core/skeleton.hpp"

namespace swish {

struct Character {
  std::string name;
  Skeleton skeleton;
  Mesh body;                           // skinned to `skeleton`; the collider of the cloth simulation
  Mesh garment;                        // the low-resolution game mesh: skinned, with UVs
  std::optional<Mesh> simulationMesh;  // optional high-resolution garment; else the bake subdivides `garment`
};

// Animation already mapped onto a character's skeleton: one Pose per frame.
struct AnimationClip {
  std::string name;
  float framesPerSecond = 30.f;
  std::vector<Pose> frames;
};

// The default Theta joints (paper: "we uniformly use the character's spine joints only"; a jersey with
// sleeves also follows the upper arms). CMU names.
inline std::vector<std::string> defaultInputJointNames() {
  return {"LowerBack", "Spine", "Spine1", "LeftArm", "RightArm"};
}

}  // namespace swish
