#pragma once
// CPU reference of the linear blend skinning in shaders/deform.comp: core/skinning.cpp's
// skinPositions, the one definition shared with the bake (which inverts it). Per vertex:
//   B = sum over influences i with w_i != 0 of w_i * M[joint_i]   (influence order, elementwise)
//   y = ((B.col0 * x.x + B.col1 * x.y) + B.col2 * x.z) + B.col3   (xyz rows)
// Zero weights are skipped, so an Inf/NaN matrix only reaches the vertices that really use its joint.
#include <vector>

#include "swish/core/mesh.hpp"

namespace swish::runtime {

Points3f referenceSkin(const Points3f& preSkin, const SkinWeights& skin, const std::vector<Mat4f>& skinMatrices);

}  // namespace swish::runtime
