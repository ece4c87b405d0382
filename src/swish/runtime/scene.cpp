#include "swish/runtime/scene.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "swish/core/error.hpp"

namespace swish::runtime {

Eigen::Matrix3d ScenePlacement::rotation() const {
  return Eigen::AngleAxisd(yawDegrees * M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
}

Eigen::Vector3d ScenePlacement::apply(const Vec3f& p) const { return rotation() * p.cast<double>() + translation; }

bool Scene::onScreen(size_t c) const {
  const SceneCharacter& ch = characters.at(c);
  if (!ch.visible) return false;
  if (cullDistance && (ch.placement.translation - camera).norm() > *cullDistance) return false;
  return true;
}

LevelCamera Scene::levelCamera() const {
  LevelCamera c;
  c.position = camera;
  c.verticalFovDegrees = cameraFovDegrees;
  c.imageHeightPixels = imageHeightPixels;
  if (cameraTarget) {
    c.target = *cameraTarget;
  } else {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const SceneCharacter& ch : characters) mean += ch.placement.translation;
    c.target = mean / double(std::max<size_t>(characters.size(), 1)) + Eigen::Vector3d(0, 1, 0);
  }
  return c;
}

LevelPlannerSettings Scene::levelPlannerSettings(std::optional<double> frameBudgetMs,
                                                 std::optional<double> tolerancePixels) const {
  LevelPlannerSettings s;
  s.camera = levelCamera();
  s.frameBudgetMs = frameBudgetMs ? frameBudgetMs : levels.frameBudgetMs;
  s.tolerancePixels = tolerancePixels ? tolerancePixels : levels.tolerancePixels;
  s.holdFrames = uint32_t(std::lround(levels.holdSeconds * framesPerSecond));
  return s;
}

void Scene::validate() const {
  const std::string where = source.empty() ? std::string("scene") : source.string();
  auto fail = [&](const std::string& path, const std::string& problem) {
    throw Error(where + ": " + path + ": " + problem);
  };
  if (frameCount < 1 || frameCount > 10'000'000)
    fail("frames.count", "must be 1 to 10000000, is " + std::to_string(frameCount));
  if (!(framesPerSecond > 0.0 && framesPerSecond <= 1000.0))
    fail("frames.rate", "must be in (0, 1000] frames per second");
  if (!camera.allFinite()) fail("camera.position", "must be finite");
  if (cameraTarget && !cameraTarget->allFinite()) fail("camera.target", "must be finite");
  if (cameraTarget && (*cameraTarget - camera).norm() < 1e-6) fail("camera.target", "must differ from the position");
  if (!(cameraFovDegrees >= 1.0 && cameraFovDegrees <= 170.0)) fail("camera.fovDegrees", "must be in [1, 170]");
  if (!(imageHeightPixels >= 16.0 && imageHeightPixels <= 65536.0))
    fail("camera.imageHeight", "must be 16 to 65536 pixels");
  if (levels.frameBudgetMs && !(*levels.frameBudgetMs > 0.0 && *levels.frameBudgetMs < 1e6))
    fail("levels.frameBudgetMs", "must be a positive number of milliseconds");
  if (levels.tolerancePixels && !(*levels.tolerancePixels > 0.0 && *levels.tolerancePixels < 1e6))
    fail("levels.tolerancePixels", "must be a positive number of pixels");
  if (!(levels.holdSeconds >= 0.0 && levels.holdSeconds <= 3600.0))
    fail("levels.holdSeconds", "must be 0 to 3600 seconds");
  if (cullDistance && !(*cullDistance > 0.0 && std::isfinite(*cullDistance)))
    fail("cullDistance", "must be a positive number of metres");
  if (outputs.gpuCheckEvery < 1) fail("outputs.gpuCheckEvery", "must be at least 1");
  if (characters.empty()) fail("characters", "a scene needs at least one character");
  std::set<std::string> names;
  for (size_t i = 0; i < characters.size(); ++i) {
    const SceneCharacter& c = characters[i];
    const std::string at = "characters[" + std::to_string(i) + "]";
    if (c.name.empty()) fail(at + ".name", "must not be empty");
    if (!names.insert(c.name).second) fail(at + ".name", "'" + c.name + "' is used by another character");
    if (c.model.empty()) fail(at + ".model", "must name a .swish file or \"default\"");
    if (c.clip.has_value() == c.poseStream.has_value())
      fail(at, "needs exactly one of \"animation\" and \"poseStream\"");
    if (c.clip) {
      if (!std::isfinite(c.clip->timeOffsetSeconds)) fail(at + ".animation.timeOffset", "must be finite");
      if (!(c.clip->speed > 0.0 && c.clip->speed <= 100.0)) fail(at + ".animation.speed", "must be in (0, 100]");
    }
    if (!c.placement.translation.allFinite()) fail(at + ".placement.translation", "must be finite");
    if (c.placement.translation.cwiseAbs().maxCoeff() > 1e7) fail(at + ".placement.translation", "beyond 1e7 m");
    if (!std::isfinite(c.placement.yawDegrees)) fail(at + ".placement.yawDegrees", "must be finite");
  }
}

}  // namespace swish::runtime
