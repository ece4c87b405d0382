#pragma once
// The preview's mannequin from a Character (the embedded default, or one imported from glTF/FBX):
// its body mesh with skin joints renamed onto the MODEL's skeleton by joint name. This is the one
// place the preview touches swish's internal types; a host would do the same with its own meshes.
#include <optional>
#include <string>

#include "swish/api_types.hpp"
#include "swish/core/character.hpp"
#include "swish/render/preview_renderer.hpp"

namespace swish::render {

// nullopt with `why` filled when the character has no body, or a joint that skins the body is not in
// the model's skeleton.
std::optional<BodyMesh> bodyFromCharacter(const Character& character, const api::ModelInfo& model, std::string& why);

}  // namespace swish::render
