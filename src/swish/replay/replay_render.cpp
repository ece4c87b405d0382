#include "swish/replay/replay_render.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <optional>

#include <tbb/parallel_for.h>

#include "swish/bake/character/default_character.hpp"
#include "swish/core/error.hpp"
#include "swish/io/error_heat_map.hpp"
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
    motion.emplace(
        models.clip(
            ch.clip->file, ch.model, ch.clip->jointMap,
            ch.clip->jointMapFile.empty() ? where : ch.clip->jointMapFile.string(),
            ch.clip->jointMapFile.empty() ? "characters[" + std::to_string(o.character) + "].animation.jointMap" : ""),
        *ch.clip, skeleton, ch.name);
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
  popts.pushOut = o.pushOut;
  std::string why;
  popts.body = render::bodyFromCharacter(bake::makeDefaultCharacter(), model.info(), why);
  if (!popts.body) result.note = "no mannequin drawn: " + why;
  if (popts.body && o.hideCoveredBody) {
    try {
      const size_t hidden = model.info().coveredBodyTriangles.empty() ? 0 : popts.body->hideCovered(model.info());
      result.note = hidden ? "left out " + std::to_string(hidden) +
                                 " body triangles the garment covers in (nearly) every training pose (the scene's "
                                 "body.hideCovered or --hide-covered-body)"
                           : "body drawn whole: the model lists no covered triangles (baked before format 1.2)";
    } catch (const api::Error& e) {
      result.note = std::string("body drawn whole: ") + e.what();
    }
  }
  {
    // Frame the garment and the body around it from the hem up (arms, neck), not the legs and feet.
    render::Vec3 lo, hi;
    render::boundsOf(model.info().restPositions, lo, hi);
    const float hem = lo[1] - 0.08f;
    if (popts.body)
      for (size_t i = 0; i + 2 < popts.body->positions.size(); i += 3)
        if (popts.body->positions[i + 1] >= hem)
          for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], popts.body->positions[i + a]);
            hi[a] = std::max(hi[a], popts.body->positions[i + a]);
          }
    popts.camera = render::frameBox(lo, hi, float(o.width) / float(o.height), 0.04f);
  }
  render::PreviewRenderer preview(device, runtime, model, popts);
  // Skin the garment covers at rest, as drawn (without the triangles left out when they are).
  std::optional<BodyThroughGarmentMeter> meter;
  if (popts.body) {
    const render::BodyMesh& b = *popts.body;
    const Points3f restBody = Eigen::Map<const Points3f>(b.positions.data(), Eigen::Index(b.positions.size() / 3), 3);
    const Triangles bodyTriangles =
        Eigen::Map<const Triangles>(b.triangles.data(), Eigen::Index(b.triangles.size() / 3), 3);
    meter.emplace(restBody, bodyTriangles, entry.model.gameMesh.positions, entry.model.gameMesh.triangles);
    result.coveredTriangles = meter->coveredTriangles();
  }

  std::unique_ptr<ModelTruth> truth;
  if (o.truth.every > 0) {
    truth = std::make_unique<ModelTruth>(entry, o.truth);
    if (!truth->available()) {
      result.note += std::string(result.note.empty() ? "" : "; ") + "no heat maps: " + truth->note();
      truth.reset();
    }
  }
  struct HeatJob {
    uint32_t frame;
    size_t drawn;  // its index among the drawn frames
    Pose pose;
    Points3f model;
    Points3f body;  // as drawn (empty without a body), for the truth's body-through measure
    api::Mat4 viewProjection;
  };
  std::vector<HeatJob> heatJobs;

  const uint32_t frames = scene.frameCount;
  const uint32_t shown = std::max<uint32_t>(1, std::min(o.maxFrames, frames));
  std::vector<PoseIssue> issues;
  std::vector<render::PreviewImage> images, marked;  // marked: the frames with body through, marked
  std::vector<render::PreviewImage> truthMarked;     // the truth frames whose truth shows any, its pixels marked
  // A drawn frame again with the pixels that count painted magenta (where to look), written as PREFIX_NNNN.png
  // (its path appended to `paths`); returned for the sheet.
  auto writeMarked = [&](const render::PreviewImage& drawn, const std::vector<int32_t>& where, const char* prefix,
                         uint32_t frame, std::vector<fs::path>& paths) {
    render::PreviewImage image = drawn;
    for (size_t p = 0; p < where.size(); ++p)
      if (where[p] >= 0) {
        uint8_t* px = &image.rgba[p * 4];
        px[0] = 255, px[1] = 0, px[2] = 255, px[3] = 255;
      }
    char name[48];
    std::snprintf(name, sizeof name, "%s_%04u.png", prefix, frame);
    render::writePreviewPng((dir / name).string(), image, preview.options().background);
    paths.push_back(dir / name);
    return image;
  };
  std::vector<api::Quat> rotations(skeleton.size());
  for (uint32_t i = 0; i < shown; ++i) {
    uint32_t index = uint32_t(uint64_t(i) * frames / shown);
    if (truth) index -= index % o.truth.every;  // on the truth grid, as the replay's truth frames
    if (i > 0 && truth && !heatJobs.empty() && scene.firstFrame + index == heatJobs.back().frame) continue;
    const uint32_t f = scene.firstFrame + index;
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
    result.frameNumbers.push_back(f);
    Points3f drawnBody;
    if (meter) {
      const std::vector<float> body = preview.lastBody();
      const api::DeformedMesh jersey = preview.lastJersey();
      drawnBody = Eigen::Map<const Points3f>(body.data(), Eigen::Index(body.size() / 3), 3);
      std::vector<int32_t> where;
      result.bodyThrough.push_back(meter->measure(
          drawnBody, Eigen::Map<const Points3f>(jersey.positions.data(), Eigen::Index(jersey.positions.size() / 3), 3),
          preview.viewProjection(), o.width, o.height, &where));
      if (result.bodyThrough.back().pixels > 0) {
        marked.push_back(writeMarked(images.back(), where, "through", f, result.throughFrames));
      }
    }
    result.truthBodyThrough.emplace_back();
    if (truth) {
      HeatJob job{f, result.frames.size() - 1, pose, Points3f(), std::move(drawnBody), preview.viewProjection()};
      job.pose.rootTranslation = skeleton.restPose().rootTranslation;  // drawn in place, as the preview
      const api::DeformedMesh mesh = preview.lastJersey();
      job.model = Eigen::Map<const Points3f>(mesh.positions.data(), Eigen::Index(mesh.positions.size() / 3), 3);
      heatJobs.push_back(std::move(job));
    }
  }
  if (truth) {
    // The truth simulations (a couple of seconds each) in parallel; the figures in frame order.
    std::vector<TruthMeasurement> measured(heatJobs.size());
    tbb::parallel_for(size_t(0), heatJobs.size(),
                      [&](size_t k) { measured[k] = truth->measure(heatJobs[k].pose, heatJobs[k].model, nullptr); });
    std::vector<render::PreviewImage> figures;
    for (size_t k = 0; k < heatJobs.size(); ++k) {
      if (!measured[k].summary.ok) {
        result.note += std::string(result.note.empty() ? "" : "; ") + "frame " + std::to_string(heatJobs[k].frame) +
                       ": no heat map, the truth simulation failed (" + measured[k].summary.failure + ")";
        continue;
      }
      io::HeatMapFigure fig;
      char title[96];
      std::snprintf(title, sizeof title, "frame %u  mean %.1f mm  max %.1f mm", heatJobs[k].frame,
                    measured[k].summary.meanMm, measured[k].summary.maxMm);
      fig.title = title;
      fig.model = &heatJobs[k].model;
      fig.truth = &measured[k].truthPositions;
      fig.triangles = &entry.model.gameMesh.triangles;
      fig.scaleMm = 10.0;  // one scale for every frame, so that colours compare across the sheet
      if (meter) {
        std::vector<int32_t> where;
        const BodyThroughGarment through = meter->measure(heatJobs[k].body, measured[k].truthPositions,
                                                          heatJobs[k].viewProjection, o.width, o.height, &where);
        result.truthBodyThrough[heatJobs[k].drawn] = through;
        if (through.pixels > 0) {  // marked on the model's frame: where the truth's garment lets the body through
          truthMarked.push_back(writeMarked(images[heatJobs[k].drawn], where, "truth_through", heatJobs[k].frame,
                                            result.truthThroughFrames));
        }
      }
      const io::PngImage png = io::heatMapFigure(fig);
      char name[32];
      std::snprintf(name, sizeof name, "heat_%04u.png", heatJobs[k].frame);
      io::writePng(dir / name, png);
      result.heatMaps.push_back(dir / name);
      render::PreviewImage img;
      img.width = png.width, img.height = png.height;
      img.rgba.resize(size_t(png.width) * png.height * 4);
      for (size_t p = 0; p < size_t(png.width) * png.height; ++p) {
        for (int c = 0; c < 3; ++c) img.rgba[p * 4 + size_t(c)] = uint8_t(png.samples[p * 3 + size_t(c)]);
        img.rgba[p * 4 + 3] = 255;
      }
      figures.push_back(std::move(img));
    }
    if (!figures.empty()) {
      render::ContactSheetOptions so;
      so.columns = 2;
      so.thumbnailWidth = 600;
      result.heatSheet = dir / "heat_sheet.png";
      render::writeContactSheet(figures, result.heatSheet, so);
    }
  }
  result.contactSheet = dir / "contact_sheet.png";
  render::writeContactSheet(images, result.contactSheet);
  if (!marked.empty()) {
    result.throughSheet = dir / "through_sheet.png";
    render::writeContactSheet(marked, result.throughSheet);
  }
  if (!truthMarked.empty()) {
    result.truthThroughSheet = dir / "truth_through_sheet.png";
    render::writeContactSheet(truthMarked, result.truthThroughSheet);
  }
  return result;
}

}  // namespace

std::string renderReportSection(const ReplayRenderResult& r, const ReplayRenderOptions& o, const fs::path& reportDir) {
  auto rel = [&](const fs::path& p) { return p.lexically_relative(reportDir).generic_string(); };
  std::string s = "\n## Pictures\n\nCharacter " + std::to_string(o.character) + ", " + std::to_string(r.frames.size()) +
                  " frames drawn in place by the preview renderer: the run time's push-out was " +
                  (o.pushOut ? "ON" : "OFF") + "; the body was " +
                  (o.hideCoveredBody ? "drawn without the triangles the garment covers in (nearly) every training pose "
                                       "(as games leave out the skin under tight clothing)"
                                     : "drawn whole (a body showing through the garment is visible)") +
                  ".";
  if (!r.note.empty()) {
    std::string note = r.note;
    note[0] = char(std::toupper(static_cast<unsigned char>(note[0])));
    s += " " + note + ".";
  }
  if (!r.bodyThrough.empty()) {
    size_t showing = 0, most = 0;  // frames with any; the frame with the most
    for (size_t i = 0; i < r.bodyThrough.size(); ++i) {
      if (r.bodyThrough[i].pixels > 0) ++showing;
      if (r.bodyThrough[i].pixels > r.bodyThrough[most].pixels) most = i;
    }
    char line[320];
    std::snprintf(line, sizeof line,
                  "\n\nBody through the garment (skin that the garment covers at rest, %zu body triangles, drawn where "
                  "the garment should be; measured by casting each pixel's ray): **%zu of %zu frames**",
                  r.coveredTriangles, showing, r.bodyThrough.size());
    s += line;
    if (showing > 0) {
      std::snprintf(line, sizeof line, ", at most %u pixels (frame %u, %.2f %% of the garment's)",
                    r.bodyThrough[most].pixels, r.frameNumbers[most], 100.0 * r.bodyThrough[most].share());
      s += line;
    }
    s += ".";
    // The truth's garment in the same pictures (frames with truth only): is the body through the model's doing?
    size_t truthFrames = 0, truthShowing = 0;
    uint32_t truthMost = 0;
    for (const auto& t : r.truthBodyThrough)
      if (t) {
        ++truthFrames;
        if (t->pixels > 0) ++truthShowing;
        truthMost = std::max(truthMost, t->pixels);
      }
    if (truthFrames > 0) {
      std::snprintf(line, sizeof line,
                    " The truth (the source simulation's garment, skinned as the run time skins it, posed and seen "
                    "as the model's) shows it in **%zu of %zu frames**, at most %u pixels.",
                    truthShowing, truthFrames, truthMost);
      s += line;
    }
    s += truthFrames > 0 ? "\n\n| frame | pixels | share of the garment's | truth pixels |\n|---|---|---|---|\n"
                         : "\n\n| frame | pixels | share of the garment's |\n|---|---|---|\n";
    for (size_t i = 0; i < r.bodyThrough.size(); ++i) {
      std::snprintf(line, sizeof line, "| %u | %u | %.2f %% |", r.frameNumbers[i], r.bodyThrough[i].pixels,
                    100.0 * r.bodyThrough[i].share());
      s += line;
      if (truthFrames > 0) {
        const auto& t = i < r.truthBodyThrough.size() ? r.truthBodyThrough[i] : std::nullopt;
        if (t) std::snprintf(line, sizeof line, " %u |", t->pixels);
        s += t ? line : " - |";
      }
      s += "\n";
    }
  }
  s += "\n\n![contact sheet](" + rel(r.contactSheet) + ")\n";
  if (!r.throughSheet.empty())
    s += "\nThe frames that show the body through the garment, the pixels counted painted magenta:\n\n![body through "
         "the garment](" +
         rel(r.throughSheet) + ")\n";
  if (!r.truthThroughSheet.empty())
    s += "\nThe truth's body-through pixels in the same frames, painted magenta over the model's picture (where the "
         "source simulation's garment, as the run time skins it, lets the body through):\n\n![the truth's body "
         "through the garment](" +
         rel(r.truthThroughSheet) + ")\n";
  if (!r.heatSheet.empty())
    s += "\nModel | truth | per-vertex error (mm, one scale for all frames):\n\n![error heat maps](" +
         rel(r.heatSheet) + ")\n";
  return s;
}

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
