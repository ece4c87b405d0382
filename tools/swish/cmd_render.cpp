// swish render MODEL --pose JOINT=RX,RY,RZ ... [--character auto|default|FILE|none] [--out FILE]
// Draws one pose of a model with the headless preview renderer (a host of swish's public API on its
// own Vulkan device): the jersey with swish's normal map (left) and without it (right), side by side
// from the same deformation, so that a person sees what the maps add. The body drawn is, by default, the
// one the model was baked on (named by its metadata: the embedded default character, a recipe, or a
// glTF/FBX file); --character picks another or none. The output line names the body it drew.
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "swish/bake/pipeline/baked_character.hpp"
#include "swish/command.hpp"
#include "swish/core/error.hpp"
#include "swish/model/model_file.hpp"
#include "swish/render/body_from_character.hpp"
#include "swish/render/preview_renderer.hpp"
#include "swish/swish.hpp"

namespace swish::cli {

namespace {

struct RenderOptions {
  std::string model;
  std::vector<std::string> pose;
  std::string character = "auto";
  std::string out = "render.png";
  std::string device;
  uint32_t width = 480, height = 640;
  bool validation = false, hideCoveredBody = false;
};

api::Quat multiply(const api::Quat& a, const api::Quat& b) {
  return {a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}

api::Quat axisAngle(float x, float y, float z, float degrees) {
  const float h = degrees * 3.14159265f / 360.f, s = std::sin(h);
  return {x * s, y * s, z * s, std::cos(h)};
}

// "JOINT=RX,RY,RZ": degrees about the joint's local X, then Y, then Z, on top of its rest rotation.
void applyPoseSpec(const std::string& spec, const api::ModelInfo& info, std::vector<api::Quat>& rotations) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos) throw Error("--pose '" + spec + "': expected JOINT=RX,RY,RZ (degrees)");
  const std::string joint = spec.substr(0, eq);
  size_t j = 0;
  while (j < info.jointNames.size() && info.jointNames[j] != joint) ++j;
  if (j == info.jointNames.size())
    throw Error("--pose '" + spec + "': the model's skeleton has no joint '" + joint + "'");
  std::istringstream in(spec.substr(eq + 1));
  float r[3];
  char comma;
  if (!(in >> r[0] >> comma >> r[1] >> comma >> r[2]) || !std::isfinite(r[0] + r[1] + r[2]))
    throw Error("--pose '" + spec + "': expected three finite angles in degrees, like Spine=10,0,-5");
  const api::Quat q = multiply(multiply(axisAngle(0, 0, 1, r[2]), axisAngle(0, 1, 0, r[1])), axisAngle(1, 0, 0, r[0]));
  rotations[j] = multiply(rotations[j], q);
}

// The body to draw and the words that name it. 'auto' draws the body the model was baked on (its metadata
// names the character), and refuses when that character's file is not at hand rather than drawing the
// garment on another body at the wrong place.
std::optional<render::BodyMesh> loadBody(const RenderOptions& o, const api::ModelInfo& info, std::string& label,
                                         std::string& why) {
  if (o.character == "none") {
    why = "--character none";
    return std::nullopt;
  }
  const Character c = bake::characterToDraw(
      o.character, o.character == "auto" ? loadModel(o.model).metadata : std::string(), o.model, label);
  return render::bodyFromCharacter(c, info, why);
}

int run(const RenderOptions& o) {
  render::HostDeviceOptions dopts;
  dopts.validation = o.validation;
  dopts.device = o.device;
  render::HostDevice device(dopts);
  api::Runtime runtime = api::Runtime::adopt(device.handles());
  api::Model model = runtime.loadModel(o.model);
  const api::ModelInfo& info = model.info();

  render::PreviewOptions popts;
  popts.width = o.width;
  popts.height = o.height;
  std::string why, bodyLabel;
  popts.body = loadBody(o, info, bodyLabel, why);
  if (!popts.body) std::printf("swish render: drawing the jersey only: %s\n", why.c_str());
  std::string hidden = "body drawn whole";
  if (popts.body && o.hideCoveredBody) {
    if (info.coveredBodyTriangles.empty())
      hidden = "body drawn whole: the model lists no covered triangles (baked before format 1.2, or without a body)";
    else
      hidden = "left out " + std::to_string(popts.body->hideCovered(info)) +
               " body triangles the garment covers in (nearly) every training pose";
  }
  if (!info.hasNormalMaps) std::printf("swish render: the model has no normal maps; both halves will look the same\n");

  std::vector<api::Quat> rotations = info.restRotations;
  for (const auto& spec : o.pose) applyPoseSpec(spec, info, rotations);
  api::CharacterPose pose;
  pose.localRotations = rotations;

  render::PreviewRenderer preview(device, runtime, model, popts);
  const render::PreviewImage img = preview.render(pose, {{true, true}, {false, true}});
  for (const auto& w : preview.lastReport().warnings) std::printf("swish render: warning: %s\n", w.c_str());
  render::writePreviewPng(o.out, img, popts.background);
  std::printf("%s: %ux%u, left: with swish's normal map, right: without (%s, %s; %s), on %s\n", o.out.c_str(),
              img.width, img.height, info.name.c_str(), popts.body ? ("on " + bodyLabel).c_str() : "garment only",
              hidden.c_str(), device.deviceName().c_str());
  if (o.validation)
    for (const auto& m : device.validationMessages()) std::fprintf(stderr, "validation: %s\n", m.c_str());
  return o.validation && !device.validationMessages().empty() ? 1 : 0;
}

}  // namespace

static CommandRegistration registration{
    "render", "Draw one pose of a model headlessly (with and without the normal map) into a PNG", [](CLI::App& app) {
      auto o = std::make_shared<RenderOptions>();
      app.add_option("model", o->model, "the .swish model")->required();
      app.add_option("--pose", o->pose,
                     "JOINT=RX,RY,RZ: degrees on top of the rest rotation (repeatable); none: the rest pose");
      app.add_option("--character", o->character,
                     "body to draw: 'auto' (the body the model was baked on, from its metadata; an error when that "
                     "file is not at hand), 'default' (the embedded mannequin), a glTF/FBX file, or 'none'");
      app.add_flag(
          "--hide-covered-body", o->hideCoveredBody,
          "leave out the body triangles the garment covers in (nearly) every training pose (the model's list; as "
          "games do under tight clothing). Off by default: the whole body shows where the garment fails");
      app.add_option("--out,-o", o->out, "output PNG");
      app.add_option("--width", o->width, "width of each half, pixels")->check(CLI::Range(16, 4096));
      app.add_option("--height", o->height, "height, pixels")->check(CLI::Range(16, 4096));
      app.add_option("--device", o->device,
                     "Vulkan device index or name substring (default: SWISH_DEVICE or automatic)");
      app.add_flag("--validation", o->validation, "enable the Vulkan validation layer; any message fails the command");
      return [o] {
        try {
          return run(*o);
        } catch (const api::Error& e) {
          throw Error(e.what());  // main prints it as "swish render: error: ..."
        }
      };
    }};

}  // namespace swish::cli
