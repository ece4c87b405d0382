#include "swish/replay/replay_render.hpp"

#include <cstdio>

#include "swish/bake/character/default_character.hpp"
#include "swish/core/error.hpp"
#include "swish/model/model_file.hpp"
#include "swish/render/body_from_character.hpp"
#include "swish/render/contact_sheet.hpp"
#include "swish/replay/character_motion.hpp"
#include "swish/replay/pose_stream.hpp"
#include "swish/swish.hpp"

namespace swish::replay {

namespace fs = std::filesystem;

namespace {

ReplayRenderResult renderInto(const runtime::Scene& scene, ModelLibrary& models, const fs::path& dir,
                              const ReplayRenderOptions& o) {
  const std::string where = scene.source.string();
  if (o.character >= scene.characters.size())
    throw Error(where + ": --render character " + std::to_string(o.character) + " but the scene has " +
                std::to_string(scene.characters.size()) + " characters");
  const runtime::SceneCharacter& ch = scene.characters[o.character];
  const ModelEntry& entry = models.at(ch.model);
  const Skeleton& skeleton = entry.model.skeleton;

  std::optional<CharacterMotion> motion;
  if (ch.clip)
    motion.emplace(models.clip(ch.clip->file, ch.model), *ch.clip, skeleton, ch.name);
  else if (ch.poseStream)
    motion.emplace(std::make_shared<PoseStream>(readPoseStream(*ch.poseStream)), skeleton, ch.name);
  else
    throw Error(where + ": characters[" + std::to_string(o.character) + "] has neither a clip nor a pose stream");

  render::HostDeviceOptions dopts;
  dopts.validation = o.validation;
  dopts.device = o.device;
  render::HostDevice device(dopts);
  api::Runtime runtime = api::Runtime::adopt(device.handles());
  const std::vector<uint8_t> bytes = serializeModel(entry.model);
  api::Model model = runtime.loadModelFromMemory(bytes, entry.key);

  ReplayRenderResult result;
  render::PreviewOptions popts;
  popts.width = o.width;
  popts.height = o.height;
  std::string why;
  popts.body = render::bodyFromCharacter(bake::makeDefaultCharacter(), model.info(), why);
  if (!popts.body) result.note = "no mannequin drawn: " + why;
  render::PreviewRenderer preview(device, runtime, model, popts);

  const uint32_t frames = scene.frameCount;
  const uint32_t shown = std::max<uint32_t>(1, std::min(o.maxFrames, frames));
  std::vector<PoseIssue> issues;
  std::vector<render::PreviewImage> images;
  std::vector<api::Quat> rotations(skeleton.size());
  for (uint32_t i = 0; i < shown; ++i) {
    const uint32_t f = scene.firstFrame + uint32_t(uint64_t(i) * frames / shown);
    const Pose pose = motion->poseAt(scene.timeOfFrame(f), f, issues);
    for (size_t j = 0; j < skeleton.size(); ++j)
      rotations[j] = {pose.local[j].x(), pose.local[j].y(), pose.local[j].z(), pose.local[j].w()};
    api::CharacterPose cp;
    cp.localRotations = rotations;  // root translation left at rest: drawn in place
    cp.dtSeconds = float(double(frames) / shown / scene.framesPerSecond);
    char name[32];
    std::snprintf(name, sizeof name, "frame_%04u.png", f);
    images.push_back(render::renderFramePng(preview, cp, dir / name));
    result.frames.push_back(dir / name);
  }
  result.contactSheet = dir / "contact_sheet.png";
  render::writeContactSheet(images, result.contactSheet);
  return result;
}

}  // namespace

ReplayRenderResult renderReplayFrames(const runtime::Scene& scene, ModelLibrary& models, const fs::path& dir,
                                      const ReplayRenderOptions& o) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error(dir.string() + ": cannot create the render folder: " + ec.message());
  try {
    return renderInto(scene, models, dir, o);
  } catch (...) {
    fs::remove_all(dir, ec);  // no partial frame sets left behind
    throw;
  }
}

}  // namespace swish::replay
