#pragma once
// Simulations made elsewhere (Marvelous Designer, Houdini...): the paper's own pipeline. We export the
// pose list as one long BVH clip of the character's skeleton, and import the per-pose cloth results as
// OBJ files mapped onto the simulation mesh by vertex order.
//
// The clip: for each pose in order, a transition of transitionSeconds from the A-pose (rest) to the
// target pose, every joint slerped with smoothstep easing (zero velocity at both ends, as the paper's
// "slow 1 second transition" intends), then holdSeconds at the target for the cloth to settle. The
// frame to export from the external tool for pose i is targetFrame (the last frame of its hold); the
// sidecar JSON lists firstFrame and targetFrame per pose id. BVH joints: OFFSET = the joint's rest
// translation, root channels "Xposition Yposition Zposition Zrotation Xrotation Yrotation", other
// joints "Zrotation Xrotation Yrotation" (intrinsic, degrees: R = Rz * Rx * Ry, the joint's local
// rotation); position channels hold the pose's root translation. Leaf joints get an End Site of zero
// length. A skeleton with more than one root cannot be written as one BVH hierarchy: Error.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/core/skeleton.hpp"

namespace swish::bake {

struct TransitionClipSettings {
  float framesPerSecond = 30.f;
  float transitionSeconds = 1.f;
  float holdSeconds = 0.5f;
};

struct TransitionMarker {
  uint32_t poseId = 0;
  uint32_t firstFrame = 0;   // the A-pose frame that starts the transition
  uint32_t targetFrame = 0;  // the frame whose cloth shape is this pose's result
};

// The frames of the clip (poses on the skeleton) and the markers; pose ids are indices into `poses`.
std::vector<Pose> buildTransitionFrames(const Skeleton& skeleton, const std::vector<Pose>& poses,
                                        const TransitionClipSettings& settings, std::vector<TransitionMarker>& markers);

// Writes <bvhPath> and, beside it, <bvhPath>.markers.json (both atomically). Throws Error.
void writeTransitionBvh(const std::filesystem::path& bvhPath, const Skeleton& skeleton, const std::vector<Pose>& poses,
                        const TransitionClipSettings& settings = {});

// Any pose sequence as BVH text (the writer behind writeTransitionBvh).
std::string bvhText(const Skeleton& skeleton, const std::vector<Pose>& frames, float framesPerSecond);

struct ObjMesh {
  Points3f positions;
  Triangles triangles;  // polygons fan-triangulated
};

// A small strict OBJ reader: "v x y z [w]" and "f" with any of the index forms (a, a/b, a/b/c, a//c,
// negative = relative); other statements are ignored. Errors name the file and line.
ObjMesh readObj(const std::filesystem::path& path);

// One pose's result from an external tool: the OBJ's vertices in the simulation mesh's vertex order
// (the tool must keep the order it was given). Throws Error naming the file when the count differs.
Points3f importSimulatedPositions(const std::filesystem::path& objPath, size_t simulationVertexCount);

}  // namespace swish::bake
