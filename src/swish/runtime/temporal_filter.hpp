#pragma once
// The temporal filter that hides normal-map pops (paper section 2.2): each frame the newly selected
// database map is blended into the character's normal map,
//     out = mix(previous_out, decoded(selected), alpha),  alpha = 1 - exp(-dt / timeConstant),
// an exponential moving average whose memory is the time constant in seconds, whatever the frame rate.
// The GPU blend pass applies the BlendStep this class returns; BlendedMapWeights (blended_map_weights.hpp)
// is the CPU model of what that produces.
//
// Edge cases, all defined:
//   - first frame (or after reset): alpha = 1, since there is no history to blend with;
//   - dt = 0: alpha = 0, the map does not change (a paused game or a second update in one frame);
//   - huge dt (or +inf): alpha = 1;
//   - time constant 0: alpha = 1 (filtering off: the selection shows at once);
//   - negative or NaN dt: treated as 0 (nothing changes; time cannot run backwards) and reported in
//     BlendStep::invalidDt so the caller can say so. The previous output is kept.
// alpha is computed as -expm1(-dt / timeConstant), accurate for tiny dt / timeConstant too.
#include <cstdint>

namespace swish::runtime {

struct BlendStep {
  uint32_t selectedMap = 0;  // the map to blend in
  float alpha = 1.f;         // its weight this frame, in [0, 1]
  bool firstFrame = false;   // no history: alpha is 1 and the output is the selected map
  bool invalidDt = false;    // dt was negative or NaN and was treated as 0
};

class TemporalFilter {
 public:
  // Throws Error unless timeConstantSeconds is finite and >= 0.
  explicit TemporalFilter(float timeConstantSeconds);

  float timeConstantSeconds() const { return timeConstant_; }
  bool hasHistory() const { return hasHistory_; }

  // One frame: dt seconds since the previous step, and the map the lookup selected.
  BlendStep step(float dtSeconds, uint32_t selectedMap);
  // Forget the history (a character that teleports or respawns): the next step has alpha = 1.
  void reset() { hasHistory_ = false; }

  // The blend factor for dt, without state: 1 - exp(-dt / timeConstant) with the edge cases above
  // (first frame excluded). Sets *invalidDt when dt was negative or NaN.
  static float alphaFor(float dtSeconds, float timeConstantSeconds, bool* invalidDt = nullptr);

 private:
  float timeConstant_ = 0.f;
  bool hasHistory_ = false;
};

}  // namespace swish::runtime
