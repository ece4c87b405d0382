#include "swish/runtime/reference_skinning.hpp"

#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"

namespace swish::runtime {

Points3f referenceSkin(const Points3f& preSkin, const SkinWeights& skin, const std::vector<Mat4f>& m) {
  if (skin.vertexCount() != size_t(preSkin.rows()))
    throw Error("skinning: " + std::to_string(skin.vertexCount()) + " skinned vertices for " +
                std::to_string(preSkin.rows()) + " positions");
  for (const uint16_t j : skin.joints)
    if (j >= m.size())
      throw Error("skinning: joint " + std::to_string(j) + " has no matrix (" + std::to_string(m.size()) + " given)");
  return skinPositions(preSkin, skin, m);
}

}  // namespace swish::runtime
