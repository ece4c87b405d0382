#include "swish/render/body_from_character.hpp"

#include <unordered_map>

namespace swish::render {

std::optional<BodyMesh> bodyFromCharacter(const Character& c, const api::ModelInfo& model, std::string& why) {
  const Mesh& b = c.body;
  if (b.vertexCount() == 0 || b.triangleCount() == 0) {
    why = "character '" + c.name + "' has no body mesh";
    return std::nullopt;
  }
  if (b.skin.influences < 1 || b.skin.vertexCount() != b.vertexCount()) {
    why = "the body of character '" + c.name + "' is not skinned";
    return std::nullopt;
  }
  std::unordered_map<std::string, uint16_t> modelJoint;
  for (size_t j = 0; j < model.jointNames.size(); ++j) modelJoint[model.jointNames[j]] = uint16_t(j);
  BodyMesh out;
  out.positions.assign(b.positions.data(), b.positions.data() + b.positions.size());
  if (size_t(b.normals.rows()) == b.vertexCount())
    out.normals.assign(b.normals.data(), b.normals.data() + b.normals.size());
  out.triangles.assign(b.triangles.data(), b.triangles.data() + b.triangles.size());
  out.influences = uint32_t(b.skin.influences);
  out.weights = b.skin.weights;
  out.joints.resize(b.skin.joints.size());
  for (size_t i = 0; i < b.skin.joints.size(); ++i) {
    const uint16_t j = b.skin.joints[i];
    if (j >= c.skeleton.size()) {
      why = "the body of '" + c.name + "' names joint " + std::to_string(j) + ", beyond its skeleton";
      return std::nullopt;
    }
    const auto it = modelJoint.find(c.skeleton.joints[j].name);
    if (it == modelJoint.end()) {
      if (b.skin.weights[i] == 0.f) {
        out.joints[i] = 0;  // an unused influence slot
        continue;
      }
      why = "joint '" + c.skeleton.joints[j].name + "' skins the body of '" + c.name +
            "' but is not in the model's skeleton";
      return std::nullopt;
    }
    out.joints[i] = it->second;
  }
  return out;
}

}  // namespace swish::render
