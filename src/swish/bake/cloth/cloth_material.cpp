#include "swish/bake/cloth/cloth_material.hpp"

#include <cmath>

#include "swish/core/error.hpp"

namespace swish::bake {

const std::vector<ClothMaterial>& clothMaterialPresets() {
  // Orders of magnitude from fabric measurements (Kawabata-style tensile/bending tests): a knit
  // stretches a few percent under its own weight, a woven cotton about ten times less, and "stiff"
  // stands for canvas/denim-like cloth that is, for the solver, practically inextensible.
  static const std::vector<ClothMaterial> presets = {
      {"jersey", 0.15f, 60.f, 6.f, 10.f, 2e-5f, 0.4f, 4.f},
      {"cotton", 0.18f, 600.f, 30.f, 80.f, 1e-4f, 0.5f, 4.f},
      {"stiff", 0.30f, 1e6f, 1e4f, 1e4f, 1e-3f, 0.6f, 4.f},
  };
  return presets;
}

const ClothMaterial& clothMaterialPreset(std::string_view name) {
  std::string known;
  for (const ClothMaterial& m : clothMaterialPresets()) {
    if (m.name == name) return m;
    known += (known.empty() ? "" : ", ") + m.name;
  }
  throw Error("unknown cloth material preset '" + std::string(name) + "' (known: " + known + ")");
}

void validateClothMaterial(const ClothMaterial& m) {
  auto positive = [&](float v, const char* field) {
    if (!std::isfinite(v) || !(v > 0.f))
      throw Error("cloth material '" + m.name + "': " + field + " must be finite and positive, got " +
                  std::to_string(v));
  };
  positive(m.density, "density");
  positive(m.stretchModulus, "stretchModulus");
  positive(m.compressionModulus, "compressionModulus");
  positive(m.shearModulus, "shearModulus");
  positive(m.bendingStiffness, "bendingStiffness");
  if (!std::isfinite(m.friction) || m.friction < 0.f)
    throw Error("cloth material '" + m.name + "': friction must be finite and >= 0");
  if (!std::isfinite(m.damping) || m.damping < 0.f)
    throw Error("cloth material '" + m.name + "': damping must be finite and >= 0");
}

}  // namespace swish::bake
