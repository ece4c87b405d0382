#pragma once
// The default character's jersey (the game mesh): a torso tube around the body's torso profile, offset
// outwards, with an armhole on each side, and a short sleeve grown from each armhole around the arm.
//
// Layout: the torso is a grid of `columns` x `rows` quads in (theta around the vertical axis, height);
// theta = 0 at the front (+Z), +pi/2 at the character's left (+X). The armhole is a block of quads
// removed from the grid; the sleeve's first ring is that block's boundary loop (so torso and sleeve
// share positions and the surface stays manifold), later rings follow the arm tube outwards.
// UVs (1 UV unit ~ 1 m, so texel density is even): the torso chart is the unrolled tube, seam at the
// back (theta = +-pi), in v in [0.01, 0.01 + height]; each sleeve is its own chart above it, seam under
// the arm. Vertices are split along seams (glTF: one UV per vertex). Every vertex is finally pushed at
// least `clearance` outside every body part.
#include <vector>

#include "swish/bake/character/default_character_recipe.hpp"
#include "swish/bake/character/default_character_tube.hpp"
#include "swish/core/mesh.hpp"

namespace swish::bake {

struct JerseyArm {
  const SweptEllipseTube* tube;  // the arm's body part
  float side;                    // +1 left (+X), -1 right
};

// Positions, UVs and triangles (outward winding); no skin, normals or tangents yet.
Mesh buildJersey(const RecipeJersey& recipe, const SweptEllipseTube& torso, const std::vector<JerseyArm>& arms,
                 const std::vector<const SweptEllipseTube*>& bodyParts);

}  // namespace swish::bake
