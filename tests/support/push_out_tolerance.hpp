#pragma once
// The conformance tolerance of positions after the deform kernel's push-out (shaders/deform.glsl,
// runtime::referencePushOut), shared by the push-out and whole-frame tests.
//
// The kernel's skinned vertex y and skinned ball centre c each carry the skinning's own tolerance
// (test_deform.cpp: 2 um + 1e-5 relative, FMA-contracting devices included; the kernel also sums an
// anchor's influences in its joint table's order, not the reference's rank order, which that bound
// holds too). The push x = c + e r / |e| (e = y - c) projects y radially onto the sphere of radius r:
// an error of e along e is removed, one across it is scaled by r / |e| (> 1 inside the ball), and c's
// error adds once more; the factor r / |e| itself (a sqrt and a division that Vulkan lets a device
// compute to a few ulps) errs by about 1e-5 relative, times r. So
//   |dx| <= |dc| + (r / |e|) (|dy| + |dc|) + 1e-5 r.
// A vertex near the sphere (|e| ~ r) may be pushed on one side and not on the other; the push there is
// r - |e|, within the same bound: the step is continuous. With two or three anchor sets each push starts
// from the one before's output, so its |dy| is that one's bound.
#include <span>
#include <vector>

#include "swish/core/types.hpp"
#include "swish/model/model.hpp"

namespace swish::test {

// Per coordinate (3 per vertex) of one instance: `skinned` its positions before the push-out,
// `matrices` its skinning matrices, `sets` the anchor sets applied (0: the skinning's tolerance alone).
std::vector<double> pushOutTolerance(const BodyAnchors& anchors, uint32_t sets, std::span<const Mat4f> matrices,
                                     const Points3f& skinned);

}  // namespace swish::test
