#pragma once
// Simulations made elsewhere (Marvelous Designer, Houdini...): the paper's own pipeline. We export the
// pose list as one long clip of the character's skeleton (BVH and glTF; pose_export.hpp writes the
// whole folder an artist gets), and import the per-pose cloth results (ExternalShapeSource below):
// meshes in the simulation mesh's vertex order are used as they are, re-meshed garments are bound to
// the simulation mesh by closest point on their surface (mesh_transfer.hpp, the paper's binding).
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
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/cloth/cloth_solver.hpp"
#include "swish/bake/transfer/mesh_transfer.hpp"
#include "swish/core/skeleton.hpp"

namespace swish::bake {

struct TransitionClipSettings {
  float framesPerSecond = 30.f;
  float transitionSeconds = 1.f;
  float holdSeconds = 0.5f;
};

// The clip that matches the built-in solver's transition: its frame rate, A-pose -> target time and
// settle time, so an external tool simulates what ClothSolver::simulate would.
inline TransitionClipSettings clipSettingsOf(const ClothSimSettings& s) {
  return {s.frameRate, s.transitionSeconds, s.settleSeconds};
}

struct TransitionMarker {
  uint32_t poseId = 0;
  uint32_t firstFrame = 0;   // the A-pose frame that starts the transition
  uint32_t targetFrame = 0;  // the frame whose cloth shape is this pose's result
};

// The frames of the clip (poses on the skeleton) and the markers; pose ids are indices into `poses`.
std::vector<Pose> buildTransitionFrames(const Skeleton& skeleton, const std::vector<Pose>& poses,
                                        const TransitionClipSettings& settings, std::vector<TransitionMarker>& markers);

// Writes the clip of `poses` to <bvhPath> and, beside it, <bvhPath>.markers.json (both atomically).
// Throws Error.
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

// OBJ text of a mesh ("v" with 9 significant digits, which give a float back exactly; "f" 1-based).
std::string objText(const Points3f& positions, const Triangles& triangles, const std::string& comment = "");

// Where part 1 takes its simulated shapes from when not from its own solver (bake config
// part1.simulation "source": "external").
struct ExternalSimulationSettings {
  // A folder of pose_<id, 6 digits>.{obj,glb,gltf,fbx} files (plus rest.* for a re-meshed garment),
  // or one .glb/.gltf/.fbx file whose mesh holds the shapes as morph targets (one per pose, or one per
  // frame of the exported clip; targets named pose_<id> are matched by name). Empty: not external.
  std::filesystem::path path;
  // "character": metres, Y up, the character at the origin (the exported files' space). "world": the
  // tool's own scene, world = origin + unitsPerMetre * R_up * character, R_up turning Y up into Z up
  // when upAxis is 'z' (x, y, z) -> (x, -z, y).
  bool worldSpace = false;
  double unitsPerMetre = 1.0;
  char upAxis = 'y';
  Vec3d origin = Vec3d::Zero();

  bool enabled() const { return !path.empty(); }
  Vec3f toCharacter(const Vec3d& p) const;
  nlohmann::json toJson() const;
};

// Result files of pose `id` in a folder: pose_000012.obj and the other extensions, in this order.
std::vector<std::filesystem::path> externalPoseCandidates(const std::filesystem::path& folder, uint32_t id);

// The external shapes of a pose list, in the simulation mesh's vertex order and character space.
// Per pose file: when its vertex count is the simulation mesh's and its faces (if any) use only the
// simulation mesh's edges, it is taken as it is; otherwise it is a re-meshed garment, bound to the
// simulation mesh through its rest shape (rest.* in the folder; the base mesh of a multi-frame file):
// each simulation vertex follows its closest point on that surface (MeshTransfer). Thread-safe.
class ExternalShapeSource {
 public:
  // simRest/simTriangles: the simulation mesh (garment.obj of the export). targetFrames: per pose id,
  // its frame in the exported clip. poseListDigest: checked against poses.json when the folder (or its
  // parent) holds the export's one. Throws Error naming the file: a missing path, a multi-frame file
  // whose frames do not map to the poses, a rest mesh that is broken or lies off the garment.
  ExternalShapeSource(const ExternalSimulationSettings& settings, const Points3f& simRest,
                      const Triangles& simTriangles, const std::vector<uint32_t>& targetFrames,
                      uint64_t poseListDigest);
  ~ExternalShapeSource();

  // Pose `id`'s shape. Throws Error naming the file and the problem (missing, unreadable, wrong
  // vertex count, non-finite values, no rest mesh for a re-meshed garment).
  Points3f shape(uint32_t poseId) const;

  // For the log: where the shapes come from and how they are matched.
  std::string description() const;
  // A digest of every file the shapes come from (names and bytes): the dataset is rebuilt when it changes.
  uint64_t digest() const { return digest_; }
  // Bound through a rest mesh: the largest rest-pose distance of a simulation vertex from it (m).
  float maxBindingDistance() const;

 private:
  Points3f fromMesh(const Points3f& filePositions, const Triangles& fileTriangles, const std::string& what) const;

  ExternalSimulationSettings settings_;
  Points3f simRest_;
  std::vector<uint64_t> simEdges_;  // sorted (min << 32 | max)
  std::vector<uint32_t> targetFrames_;
  std::string description_;
  uint64_t digest_ = 0;
  std::unique_ptr<MeshTransfer> restBinding_;  // null: no rest mesh given
  size_t restVertexCount_ = 0;
  std::string restFile_;
  // Multi-frame file: the shapes per pose id (empty optional: no frame for it).
  bool multiFrame_ = false;
  std::vector<std::optional<Points3f>> frames_;
  Triangles frameTriangles_;
};

}  // namespace swish::bake
