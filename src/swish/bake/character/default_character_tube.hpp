#pragma once
// A swept-ellipse body part of the default mannequin: a smooth (Catmull-Rom) axis through the recipe's
// stations, with an elliptical cross-section whose half-axes are interpolated the same way. The frame
// of a cross-section: tangent t, e1 = normalize(t x Z) (the "width" axis; X for a vertical torso),
// e2 = t x e1. Used three ways: meshed as a closed tube (body), densely sampled for inside tests and
// for pushing cloth out of the body, and sampled at a height for the jersey's torso profile.
#include <algorithm>
#include <vector>

#include "swish/core/types.hpp"

namespace swish::bake {

struct TubeStation {
  Vec3f center;
  float halfWidth, halfDepth;
  int joint;  // skeleton index
};

struct TubeSection {
  Vec3f center, tangent, e1, e2;
  float halfWidth, halfDepth;
  float param;  // in [0, stations - 1]
};

class SweptEllipseTube {
 public:
  explicit SweptEllipseTube(std::vector<TubeStation> stations, int denseSamplesPerSpan = 24);

  TubeSection section(float param) const;  // param in [0, stations - 1]
  size_t stationCount() const { return stations_.size(); }
  const TubeStation& station(size_t i) const { return stations_[i]; }

  // Normalised elliptical radius of p about the nearest dense section (< 1 inside), and that section.
  // Beyond either end the cap counts: a half-ellipsoid reaching capLength() past the end section.
  float normalisedRadius(const Vec3f& p, TubeSection* nearest = nullptr) const;
  // Moves p radially (in its nearest cross-section) so that it is at least `clearance` metres outside
  // the ellipse; returns whether it moved.
  bool pushOut(Vec3f& p, float clearance) const;
  // Cross-section whose centre has height y (linear between dense samples; the axis must be monotonic
  // in y over the sampled range, as a torso's is).
  TubeSection sectionAtHeight(float y) const;
  // How far the rounded cap reaches past an end section (the mesh's cap pole sits there too).
  static float capLength(const TubeSection& s) { return 0.5f * std::min(s.halfWidth, s.halfDepth); }

 private:
  std::vector<TubeStation> stations_;
  std::vector<TubeSection> dense_;
};

}  // namespace swish::bake
