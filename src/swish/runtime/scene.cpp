#include "swish/runtime/scene.hpp"

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
