#include "swish/bake/cloth/pose_export.hpp"

#include <cstdio>

#include "swish/bake/cloth/external_simulation.hpp"
#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/io/gltf_export.hpp"

namespace swish::bake {

namespace fs = std::filesystem;

std::string exportedResultName(uint32_t id) {
  char name[48];
  std::snprintf(name, sizeof name, "results/pose_%06u.obj", id);
  return name;
}

namespace {

std::string readme(const DatasetPoseList& list, const TransitionClipSettings& clip, size_t clipFrames,
                   const std::vector<TransitionMarker>& markers, size_t simVertices, size_t simTriangles) {
  char head[8192];
  std::snprintf(head, sizeof head,
                R"(# Poses to simulate for swish

This folder holds %zu poses of the character '%s' for your cloth tool. swish learns the garment's
shape in each pose from what you send back.

## What is here

- `poses.bvh` and `poses.glb`: one clip, %zu frames at %g fps. For each pose, the character starts in
  the A-pose (the rest pose), turns to the pose over %g s (eased in and out) and holds it %g s for
  the cloth to settle. `poses.glb` also holds the skinned body and the garment in the rest pose.
- `body.obj`: the body in the rest pose. It is the collider: the garment should not end inside it.
- `garment.obj`: the garment to simulate, in the rest pose (%zu vertices, %zu triangles).
- `poses.json`: per pose, its `id`, `first_frame` (the A-pose frame that starts it), `target_frame`
  (the frame whose cloth shape is the result) and the file name swish expects for it.

All files are in metres, Y up, the character at the origin (if your tool works in centimetres or
Z up, say so in the bake recipe, below).

## What to do

Simulate each pose on its own: start from the garment at rest at `first_frame`, play the clip to
`target_frame`, and export the garment there. Do not carry the cloth from one pose to the next: the
body jumps back to the A-pose at each `first_frame`. (Pose %u, for example: frames %u to %u.)

## What to send back

One mesh per pose in `results/`, named as `poses.json` says: `results/pose_000000.obj`,
`results/pose_000001.obj`, ... (OBJ, or .glb/.gltf/.fbx with the garment as the only mesh, or named
"garment"). One .glb/.gltf/.fbx holding every pose as a morph target / blend shape also works
(one target per pose in pose order, one per clip frame, or targets named pose_000012).

- Keep `garment.obj`'s vertices and their order if you can: those results are used exactly as they are.
- If your tool re-meshed the garment, also send `results/rest.obj`: your garment in the rest pose, in
  the same vertex order as your pose files. swish then binds its own garment to yours by closest
  point on the surface.
- A pose that failed in your tool: leave its file out. swish reports the missing poses and trains on
  the others.

Then, in the bake recipe, point part 1 at the results and bake as usual:

    "simulation": {"source": "external", "path": "<this folder>/results"}

(add `"space": "world", "units_per_metre": 100, "up_axis": "z"` if the meshes come back in
centimetres with Z up, and `"origin": [x, y, z]` if the character did not stand at the origin).
Re-export when the recipe's clips, sampling, thinning or limb clearance change: the pose list
changes with them, and swish refuses results made for another list.
)",
                list.simulated.size(), list.character->name.c_str(), clipFrames, double(clip.framesPerSecond),
                double(clip.transitionSeconds), double(clip.holdSeconds), simVertices, simTriangles,
                markers.empty() ? 0u : markers.back().poseId, markers.empty() ? 0u : markers.back().firstFrame,
                markers.empty() ? 0u : markers.back().targetFrame);
  return head;
}

}  // namespace

PoseExportResult exportPoses(const DatasetBuildSettings& s, const fs::path& dir,
                             const std::function<void(const std::string&)>& logFn) {
  auto log = [&](const std::string& line) {
    if (logFn) logFn(line);
  };
  DatasetBuildResult res;
  const DatasetPoseList list = listDatasetPoses(s, res, logFn);
  const Character& ch = *list.character;
  const SimulationMesh& sim = list.shapes->solver().mesh();
  const TransitionClipSettings clip = clipSettingsOf(s.simulation);
  std::vector<TransitionMarker> markers;
  const std::vector<Pose> frames = buildTransitionFrames(ch.skeleton, list.simulated, clip, markers);

  std::error_code ec;
  fs::create_directories(dir / "results", ec);
  if (ec) throw Error(dir.string() + ": cannot make the export folder (" + ec.message() + ")");
  PoseExportResult out;
  out.poses = list.simulated.size();
  out.clipFrames = frames.size();
  out.simulationVertices = sim.vertexCount();
  auto wrote = [&](const fs::path& f) {
    out.files.push_back(f);
    log("export: wrote " + f.string());
  };

  writeTextFileAtomic(dir / "poses.bvh", bvhText(ch.skeleton, frames, clip.framesPerSecond));
  wrote(dir / "poses.bvh");

  Mesh garment;
  garment.positions = sim.restPositions;
  garment.triangles = sim.triangles;
  garment.skin = sim.skin;
  io::GltfScene scene;
  scene.skeleton = &ch.skeleton;
  scene.generator = "swish bake --export-poses (character " + ch.name + ")";
  scene.materials.push_back({"skin", Vec4f(0.80f, 0.66f, 0.55f, 1.f), 0.7f, {}});
  scene.materials.push_back({"cloth", Vec4f(0.15f, 0.25f, 0.65f, 1.f), 0.9f, {}});
  scene.meshes.push_back({"body", &ch.body, true, 0, {}});
  scene.meshes.push_back({"garment", &garment, false, 1, {}});  // the rest pose: what the tool starts from
  scene.animation = io::GltfAnimation{"poses", clip.framesPerSecond, &frames};
  io::writeGlb(dir / "poses.glb", scene);
  wrote(dir / "poses.glb");

  nlohmann::json joints = nlohmann::json::array();
  for (const Joint& j : ch.skeleton.joints) joints.push_back(j.name);
  nlohmann::json poses = nlohmann::json::array();
  for (const TransitionMarker& m : markers) {
    const Pose& p = list.simulated[m.poseId];
    nlohmann::json rot = nlohmann::json::array();
    for (const Quatf& q : p.local) rot.push_back({q.x(), q.y(), q.z(), q.w()});
    poses.push_back({{"id", m.poseId},
                     {"first_frame", m.firstFrame},
                     {"target_frame", m.targetFrame},
                     {"target_seconds", double(m.targetFrame) / double(clip.framesPerSecond)},
                     {"result", exportedResultName(m.poseId)},
                     {"root_translation", {p.rootTranslation.x(), p.rootTranslation.y(), p.rootTranslation.z()}},
                     {"rotations", rot}});
  }
  const nlohmann::json sidecar = {
      {"format", "swish pose export"},
      {"version", 1},
      {"character", ch.name},
      {"space", "metres, Y up, the character at the origin"},
      {"clip",
       {{"bvh", "poses.bvh"},
        {"gltf", "poses.glb"},
        {"frames", frames.size()},
        {"frames_per_second", clip.framesPerSecond},
        {"transition_seconds", clip.transitionSeconds},
        {"hold_seconds", clip.holdSeconds}}},
      {"body", {{"file", "body.obj"}, {"vertices", ch.body.vertexCount()}}},
      {"garment", {{"file", "garment.obj"}, {"vertices", sim.vertexCount()}, {"triangles", sim.triangles.rows()}}},
      {"results", {{"folder", "results"}, {"rest", "results/rest.obj"}}},
      {"pose_list_digest", std::to_string(list.digest)},
      {"joints", joints},
      {"rotations",
       "per pose, each joint's local rotation as a quaternion [x, y, z, w] (glTF order); the clip holds the same"},
      {"poses", poses}};
  writeTextFileAtomic(dir / "poses.json", sidecar.dump(1) + "\n");
  wrote(dir / "poses.json");

  writeTextFileAtomic(dir / "body.obj", objText(ch.body.positions, ch.body.triangles,
                                                "swish: body '" + ch.name + "', rest pose, metres, Y up"));
  wrote(dir / "body.obj");
  writeTextFileAtomic(
      dir / "garment.obj",
      objText(sim.restPositions, sim.triangles,
              "swish: garment to simulate (simulation mesh), rest pose, metres, Y up; keep this vertex order"));
  wrote(dir / "garment.obj");
  writeTextFileAtomic(dir / "README.md",
                      readme(list, clip, frames.size(), markers, sim.vertexCount(), size_t(sim.triangles.rows())));
  wrote(dir / "README.md");
  char line[200];
  std::snprintf(line, sizeof line,
                "export: %zu poses, a %zu-frame clip (%.1f s at %g fps), garment of %zu vertices in %s", out.poses,
                out.clipFrames, double(out.clipFrames) / double(clip.framesPerSecond), double(clip.framesPerSecond),
                out.simulationVertices, dir.string().c_str());
  log(line);
  return out;
}

}  // namespace swish::bake
