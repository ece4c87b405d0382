#pragma once
// Cloth material presets of the source simulation. Moduli are per unit area of cloth (N/m), so a
// preset means the same fabric at every mesh resolution: the solver turns them into XPBD compliances
// with the area each constraint stands for.
#include <string>
#include <string_view>
#include <vector>

namespace swish::bake {

struct ClothMaterial {
  std::string name;
  float density = 0.15f;           // kg/m^2 (a jersey knit weighs about 150 g/m^2)
  float stretchModulus = 60.f;     // N/m: tension along an edge, per unit strain
  float compressionModulus = 6.f;  // N/m: cloth buckles far more easily than it stretches
  float shearModulus = 10.f;       // N/m: in-plane shear against the grain (warp = garment's up)
  float bendingStiffness = 2e-5f;  // N*m: resistance to folding across an edge
  float friction = 0.4f;           // Coulomb coefficient against the body
  float damping = 4.f;             // 1/s: velocity damping, high because the bake wants rest shapes
};

// The preset table. Names are stable (used in bake settings): "jersey", "cotton", "stiff".
const std::vector<ClothMaterial>& clothMaterialPresets();
// The preset with this name; throws Error listing the known names when there is none.
const ClothMaterial& clothMaterialPreset(std::string_view name);
// Throws Error naming the material and the offending field (non-finite, non-positive, friction < 0).
void validateClothMaterial(const ClothMaterial& m);

}  // namespace swish::bake
