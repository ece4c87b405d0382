#include "swish/replay/replay_job.hpp"

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>

#include <unistd.h>

#include <cstdio>

#include "swish/core/error.hpp"
#include "swish/io/png.hpp"
#include "swish/replay/gltf_frame_writer.hpp"
#include "swish/replay/progress_bar.hpp"
#include "swish/replay/report_writer.hpp"

namespace swish::replay {

namespace {

namespace fs = std::filesystem;

// Removes the staging folder unless released.
struct StagingFolder {
  fs::path path;
  bool keep = false;
  ~StagingFolder() {
    std::error_code ec;
    if (!keep && !path.empty()) fs::remove_all(path, ec);
  }
};

void writeNormalMap(const fs::path& file, const runtime::BlendedNormalMap& map) {
  io::writePng(file, io::encodeNormalMap(map.width, map.height, runtime::xyAsFloat(map), 16));
}

// The names a replay writes into its output folder (and the marker it leaves there).
constexpr const char* kMarker = ".swish-replay";
bool writtenByReplay(const std::string& name) {
  for (const char* n : {kMarker, "report.json", "report.md", "plots", "render", "meshes", "normal_maps"})
    if (name == n) return true;
  return false;
}

// The replay replaces its output folder whole; one that holds anything a replay does not write (a user's
// files, a home folder given as --out) is refused before any work, never deleted.
void checkOutputFolder(const fs::path& dir) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(dir, ec);
  if (ec || !fs::exists(st)) return;
  if (!fs::is_directory(st))
    throw Error(dir.string() + ": the replay's output folder is a file; choose a new or empty folder (--out)");
  if (fs::exists(dir / kMarker)) return;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (!writtenByReplay(name))
      throw Error(dir.string() + ": the replay's output folder holds '" + name +
                  "', which no replay wrote; the replay replaces its whole output folder, so it refuses one that is "
                  "not a replay's output: choose a new or empty folder (--out)");
  }
  if (ec) throw Error(dir.string() + ": cannot read the replay's output folder: " + ec.message());
}

}  // namespace

ReplayJobResult runReplayJob(const runtime::Scene& scene, const ReplayJobOptions& options) {
  const runtime::SceneOutputs& out = scene.outputs;
  std::optional<ModelLibrary> ownModels;
  ModelLibrary& models = options.models ? *options.models : ownModels.emplace(scene);
  ReplayOptions eo = options.engine;
  const bool writes = out.report || out.normalMaps || out.meshes;
  StagingFolder staging;
  if (writes) {
    checkOutputFolder(out.directory);
    staging.path = out.directory.string() + ".partial-" + std::to_string(::getpid());
    fs::remove_all(staging.path);
    fs::create_directories(staging.path);
    std::ofstream(staging.path / kMarker) << "written by swish replay: the next replay into this folder replaces it\n";
  }
  // Meshes of the frame being read back, written as one glTF when the next frame starts (and at the end).
  struct PendingMesh {
    uint32_t character;
    Points3f positions, normals;
  };
  std::vector<PendingMesh> pending;
  uint32_t pendingFrame = 0;
  auto flushMeshes = [&] {
    if (pending.empty()) return;
    std::vector<GltfCharacterMesh> meshes;
    for (const auto& p : pending) {
      const Mesh& g = models.at(scene.characters[p.character].model).model.gameMesh;
      meshes.push_back({scene.characters[p.character].name, scene.characters[p.character].placement, &p.positions,
                        p.normals.rows() ? &p.normals : nullptr, &g.uvs, &g.triangles});
    }
    char name[64];
    std::snprintf(name, sizeof name, "frame_%06u.gltf", pendingFrame);
    writeGltfFrame(staging.path / "meshes" / name, meshes);
    pending.clear();
  };
  if (out.meshes) fs::create_directories(staging.path / "meshes");
  if (out.normalMaps) fs::create_directories(staging.path / "normal_maps");
  if (out.normalMaps || out.meshes) {
    eo.onCharacterOutput = [&, user = options.engine.onCharacterOutput](
                               uint32_t frame, uint32_t c, const runtime::ReferenceFrameOutputs& o, uint32_t i) {
      if (out.meshes) {
        if (frame != pendingFrame) flushMeshes();
        pendingFrame = frame;
        pending.push_back({c, o.positions[i], i < o.normals.size() ? o.normals[i] : Points3f()});
      }
      if (out.normalMaps && i < o.normalMaps.size()) {
        char name[64];
        std::snprintf(name, sizeof name, "_%06u.png", frame);
        writeNormalMap(staging.path / "normal_maps" / (scene.characters[c].name + name), o.normalMaps[i]);
      }
      if (user) user(frame, c, o, i);
    };
  }
  ProgressBar bar("swish replay", options.quiet);
  eo.progress = [&, user = options.engine.progress](uint32_t d, uint32_t t) {
    bar.update(d, t);
    if (user) user(d, t);
  };
  eo.truthProgress = [&, user = options.engine.truthProgress](uint32_t d, uint32_t t) {
    bar.truth(d, t);
    if (user) user(d, t);
  };
  ReplayEngine engine(scene, models, eo);
  ReplayJobResult r;
  r.result = engine.run();
  flushMeshes();
  bar.finish();
  if (out.report) writeReport(staging.path, scene, models, r.result);
  if (writes) {
    std::error_code ec;
    fs::remove_all(out.directory, ec);
    fs::rename(staging.path, out.directory, ec);
    if (ec) throw Error(out.directory.string() + ": cannot move the outputs into place: " + ec.message());
    staging.keep = true;
    r.directory = out.directory;
  }
  return r;
}

}  // namespace swish::replay
