#pragma once
// "Body through the garment", measured on the picture: the pixels where the camera sees skin that the
// garment covers. Vertex counts of penetration (bake/report/penetration.hpp) say how much cloth is inside
// the body; this says what a player sees of it (the grey shoulder patches of the contact sheet).
//
// Which skin the garment covers is decided once, in the rest pose: a body triangle is covered when the
// line along its outward normal through its centroid meets the rest garment between 1.5 cm under the skin
// and `reach` above it, at least `edgeMargin` from the garment's openings (hem, collar, sleeve ends); or
// when it is buried inside another part of the body at rest (the top of an arm tube inside the trunk's
// shoulder, which a hanging arm brings out) with the garment over it within 8 cm. The forearms, the neck above the
// collar and the legs are not covered; the shoulders, chest and back are.
//
// Per picture, each pixel's ray (the camera's view-projection inverted, through the pixel centre) is
// cast against the posed body and the deformed garment. A pixel counts when the first thing its ray
// meets is a covered body triangle AND the garment is within `reach` of that skin point, away from its
// openings: the cloth is right there, sunk beneath the skin or just behind it, and the body is drawn
// where the garment should have been. Skin that a moved garment edge uncovers (a hem riding up as the
// arms rise, a sleeve sliding) does not count: nothing went through the cloth there. Nothing is drawn
// from it; it is on the CPU (Embree), deterministic, and independent of the GPU that drew the picture.
#include <cstdint>
#include <vector>

#include "swish/api_types.hpp"
#include "swish/core/types.hpp"

namespace swish::replay {

struct BodyThroughGarment {
  uint32_t pixels = 0;         // pixels where covered skin is drawn: the body through the garment
  uint32_t garmentPixels = 0;  // pixels where the garment is drawn
  // Of the pixels where the garment is drawn or should be, those that show the body instead.
  double share() const { return pixels ? double(pixels) / double(garmentPixels + pixels) : 0.0; }
};

class BodyThroughGarmentMeter {
 public:
  // Rest positions of the body and the garment in one space (the character's), triangles winding
  // outwards. `reach` (m): how far above a body triangle the garment may be and still cover it;
  // `edgeMargin` (m): how far from the garment's openings. Throws Error for indices out of range,
  // non-finite positions or a reach that is not a positive number.
  BodyThroughGarmentMeter(const Points3f& restBody, const Triangles& bodyTriangles, const Points3f& restGarment,
                          const Triangles& garmentTriangles, float reach = 0.03f, float edgeMargin = 0.03f);

  size_t coveredTriangles() const;
  const std::vector<char>& covered() const { return covered_; }  // per body triangle

  // One picture of `width` x `height` pixels seen through `viewProjection` (world -> Vulkan clip,
  // column-major as render::viewProjection), with the body and the garment posed in that world (same
  // vertex counts as at rest). Throws Error for a singular view-projection, other vertex counts or
  // non-finite positions.
  // `where` (optional): resized to width * height (row-major, y down) and set, per pixel that counts, to
  // the body triangle the camera sees there; -1 elsewhere.
  BodyThroughGarment measure(const Points3f& body, const Points3f& garment, const api::Mat4& viewProjection,
                             uint32_t width, uint32_t height, std::vector<int32_t>* where = nullptr) const;

 private:
  Triangles bodyTriangles_, garmentTriangles_;
  Eigen::Index bodyVertices_ = 0, garmentVertices_ = 0;
  float reach_ = 0.f;
  std::vector<char> covered_;
  std::vector<char> nearOpening_;  // per garment triangle: within edgeMargin of an opening at rest
};

}  // namespace swish::replay
