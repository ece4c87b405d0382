#pragma once
// The embedded default character, made by code from its recipe (default_character_recipe.hpp),
// deterministic bit for bit: a 31-joint CMU-named skeleton in an A-pose (identity rest rotations,
// like ../shared/assets/tshirt_lo.glb), a mannequin body of swept-ellipse parts (torso, head and
// neck, arms, legs, feet; each a closed tube, overlapping where parts meet) skinned to the skeleton,
// and a fitted short-sleeved jersey (default_character_jersey.hpp) whose skin weights are transferred
// from the nearest visible body vertices. Metres, Y up, faces +Z, feet at y = 0.
#include "swish/bake/character/default_character_recipe.hpp"
#include "swish/core/character.hpp"

namespace swish::bake {

Character makeDefaultCharacter(const DefaultCharacterRecipe& recipe = embeddedDefaultRecipe());

}  // namespace swish::bake
