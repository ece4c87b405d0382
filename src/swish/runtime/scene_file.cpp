#include "swish/runtime/scene_file.hpp"

#include <set>
#include <sstream>

#include "swish/core/error.hpp"
#include "swish/files/json_file.hpp"
#include "swish/files/json_reader.hpp"

namespace swish::runtime {

namespace {

using nlohmann::json;

std::filesystem::path resolve(const std::filesystem::path& base, const std::string& p) {
  const std::filesystem::path path(p);
  return path.is_absolute() ? path : (base / path).lexically_normal();
}

void requireFile(const JsonReader& r, const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    r.fail("file '" + file.string() + "' does not exist or is not a file");
}

SceneCharacter parseCharacter(const JsonReader& r, const std::filesystem::path& base, bool checkFiles) {
  r.requireObject({"name", "model", "animation", "poseStream", "placement", "visible", "level"});
  SceneCharacter c;
  c.name = r.required("name").string();
  const JsonReader model = r.required("model");
  c.model = model.string();
  if (c.model != kDefaultModelName) {
    c.model = resolve(base, c.model).string();
    if (checkFiles) requireFile(model, c.model);
  }
  if (r.has("animation") == r.has("poseStream")) r.fail("needs exactly one of \"animation\" and \"poseStream\"");
  if (r.has("animation")) {
    const JsonReader a = r.child("animation");
    a.requireObject({"file", "clip", "timeOffset", "speed", "jointMap"});
    SceneClip clip;
    const JsonReader file = a.required("file");
    clip.file = resolve(base, file.string());
    if (checkFiles) requireFile(file, clip.file);
    if (a.has("clip")) clip.clipName = a.child("clip").string();
    if (a.has("timeOffset")) clip.timeOffsetSeconds = a.child("timeOffset").number();
    if (a.has("speed")) {
      clip.speed = a.child("speed").number();
      if (!(clip.speed > 0.0 && clip.speed <= 100.0)) a.child("speed").fail("must be in (0, 100]");
    }
    if (a.has("jointMap")) {
      const JsonReader m = a.child("jointMap");
      if (m.value().is_string()) {
        clip.jointMapFile = resolve(base, m.string());
        if (checkFiles) {
          requireFile(m, clip.jointMapFile);
          clip.jointMap = readJsonFile(clip.jointMapFile, "joint map");
          if (!clip.jointMap.is_object()) m.fail(clip.jointMapFile.string() + ": the joint map must be a JSON object");
        }
      } else if (m.value().is_object()) {
        clip.jointMap = m.value();
      } else {
        m.fail("must be a joint map object {\"clip joint\": \"character joint\"} or a joint map file, is " +
               std::string(m.value().type_name()));
      }
    }
    c.clip = clip;
  } else {
    const JsonReader s = r.child("poseStream");
    c.poseStream = resolve(base, s.string());
    if (checkFiles) requireFile(s, *c.poseStream);
  }
  if (r.has("placement")) {
    const JsonReader p = r.child("placement");
    p.requireObject({"translation", "yawDegrees"});
    if (p.has("translation")) {
      c.placement.translation = p.child("translation").vec3();
      if (c.placement.translation.cwiseAbs().maxCoeff() > 1e7) p.child("translation").fail("is beyond 1e7 m");
    }
    if (p.has("yawDegrees")) c.placement.yawDegrees = p.child("yawDegrees").number();
  }
  if (r.has("visible")) c.visible = r.child("visible").boolean();
  if (r.has("level")) {
    const JsonReader l = r.child("level");
    if (l.value().is_number_integer())
      c.level = std::to_string(l.integer(0, 255));
    else
      c.level = l.string();
    if (c.level.empty()) l.fail("must name a level of the model's ladder, or its index");
  }
  return c;
}

}  // namespace

Scene parseScene(const json& j, const std::filesystem::path& source, bool checkFiles) {
  const JsonReader root(j, source.string(), "");
  root.requireObject({"name", "frames", "camera", "cullDistance", "levels", "body", "outputs", "characters"});
  const std::filesystem::path base = source.has_parent_path() ? source.parent_path() : std::filesystem::path(".");
  Scene s;
  s.source = source;
  s.name = root.has("name") ? root.child("name").string() : source.stem().string();

  const JsonReader frames = root.required("frames");
  frames.requireObject({"start", "count", "rate"});
  if (frames.has("start")) s.firstFrame = frames.child("start").integer(0, 100'000'000);
  s.frameCount = frames.required("count").integer(1, 10'000'000);
  if (frames.has("rate")) {
    s.framesPerSecond = frames.child("rate").number();
    if (!(s.framesPerSecond > 0.0 && s.framesPerSecond <= 1000.0)) frames.child("rate").fail("must be in (0, 1000]");
  }

  if (root.has("camera")) {
    const JsonReader cam = root.child("camera");
    cam.requireObject({"position", "target", "fovDegrees", "imageHeight"});
    s.camera = cam.required("position").vec3();
    if (cam.has("target")) s.cameraTarget = cam.child("target").vec3();
    if (cam.has("fovDegrees")) s.cameraFovDegrees = cam.child("fovDegrees").number();
    if (cam.has("imageHeight")) s.imageHeightPixels = cam.child("imageHeight").integer(16, 65536);
  }
  if (root.has("levels")) {
    const JsonReader lv = root.child("levels");
    lv.requireObject({"frameBudgetMs", "tolerancePixels", "holdSeconds"});
    if (lv.has("frameBudgetMs")) s.levels.frameBudgetMs = lv.child("frameBudgetMs").number();
    if (lv.has("tolerancePixels")) s.levels.tolerancePixels = lv.child("tolerancePixels").number();
    if (lv.has("holdSeconds")) s.levels.holdSeconds = lv.child("holdSeconds").number();
  }
  if (root.has("cullDistance")) {
    const double d = root.child("cullDistance").number();
    if (!(d > 0.0)) root.child("cullDistance").fail("must be a positive number of metres");
    s.cullDistance = d;
  }

  if (root.has("body")) {
    const JsonReader b = root.child("body");
    b.requireObject({"pushOut", "hideCovered"});
    if (b.has("pushOut")) s.body.pushOut = b.child("pushOut").boolean();
    if (b.has("hideCovered")) s.body.hideCovered = b.child("hideCovered").boolean();
  }

  if (root.has("outputs")) {
    const JsonReader o = root.child("outputs");
    o.requireObject({"directory", "report", "render", "meshes", "normalMaps", "gpuCheckEvery"});
    if (o.has("directory"))
      s.outputs.directory = resolve(base, o.child("directory").string());
    else
      s.outputs.directory = resolve(base, s.outputs.directory.string());
    if (o.has("report")) s.outputs.report = o.child("report").boolean();
    if (o.has("render")) s.outputs.render = o.child("render").boolean();
    if (o.has("meshes")) s.outputs.meshes = o.child("meshes").boolean();
    if (o.has("normalMaps")) s.outputs.normalMaps = o.child("normalMaps").boolean();
    if (o.has("gpuCheckEvery")) s.outputs.gpuCheckEvery = o.child("gpuCheckEvery").integer(1, 1'000'000);
  } else {
    s.outputs.directory = resolve(base, s.outputs.directory.string());
  }

  const JsonReader chars = root.required("characters");
  if (!chars.value().is_array()) chars.fail("must be an array, is " + std::string(chars.value().type_name()));
  if (chars.value().empty()) chars.fail("a scene needs at least one character");
  std::set<std::string> names;
  for (size_t i = 0; i < chars.value().size(); ++i) {
    s.characters.push_back(parseCharacter(chars.at(i), base, checkFiles));
    if (!names.insert(s.characters.back().name).second)
      chars.at(i).child("name").fail("'" + s.characters.back().name + "' is used by another character");
  }
  s.validate();
  return s;
}

Scene loadScene(const std::filesystem::path& file, bool checkFiles) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) throw Error(file.string() + ": scene file does not exist");
  return parseScene(readJsonFile(file, "scene file"), file, checkFiles);
}

json sceneToJson(const Scene& s) {
  json j;
  j["name"] = s.name;
  j["frames"] = {{"start", s.firstFrame}, {"count", s.frameCount}, {"rate", s.framesPerSecond}};
  j["camera"] = {{"position", {s.camera.x(), s.camera.y(), s.camera.z()}},
                 {"fovDegrees", s.cameraFovDegrees},
                 {"imageHeight", s.imageHeightPixels}};
  if (s.cameraTarget) j["camera"]["target"] = {s.cameraTarget->x(), s.cameraTarget->y(), s.cameraTarget->z()};
  j["levels"] = {{"holdSeconds", s.levels.holdSeconds}};
  if (s.levels.frameBudgetMs) j["levels"]["frameBudgetMs"] = *s.levels.frameBudgetMs;
  if (s.levels.tolerancePixels) j["levels"]["tolerancePixels"] = *s.levels.tolerancePixels;
  if (s.cullDistance) j["cullDistance"] = *s.cullDistance;
  j["body"] = {{"pushOut", s.body.pushOut}, {"hideCovered", s.body.hideCovered}};
  j["outputs"] = {{"directory", s.outputs.directory.string()},
                  {"report", s.outputs.report},
                  {"render", s.outputs.render},
                  {"meshes", s.outputs.meshes},
                  {"normalMaps", s.outputs.normalMaps},
                  {"gpuCheckEvery", s.outputs.gpuCheckEvery}};
  j["characters"] = json::array();
  for (const SceneCharacter& c : s.characters) {
    json cj{{"name", c.name}, {"model", c.model}, {"visible", c.visible}};
    if (c.clip)
      cj["animation"] = {{"file", c.clip->file.string()},
                         {"clip", c.clip->clipName},
                         {"timeOffset", c.clip->timeOffsetSeconds},
                         {"speed", c.clip->speed}};
    if (c.clip && !c.clip->jointMapFile.empty())
      cj["animation"]["jointMap"] = c.clip->jointMapFile.string();
    else if (c.clip && !c.clip->jointMap.is_null())
      cj["animation"]["jointMap"] = c.clip->jointMap;
    if (c.poseStream) cj["poseStream"] = c.poseStream->string();
    if (!c.level.empty()) cj["level"] = c.level;
    const auto& t = c.placement.translation;
    cj["placement"] = {{"translation", {t.x(), t.y(), t.z()}}, {"yawDegrees", c.placement.yawDegrees}};
    j["characters"].push_back(cj);
  }
  return j;
}

}  // namespace swish::runtime
