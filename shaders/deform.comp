#version 460
// PCA reconstruction (pre-skinning space) + linear blend skinning for ALL instances of one model in one
// dispatch. One thread per vertex: it loads its 3K basis values and its skin influences ONCE into
// registers, then loops over the instances. The basis, the largest input (3N x K floats), is
// therefore read once per frame, not once per instance. The instances' weights are read at addresses
// uniform across the workgroup (broadcast loads, served by the scalar/constant path of GPUs and by
// lavapipe's uniform-load path); staging them in shared memory measured 2x slower on lavapipe, whose
// shared-memory loads and barriers are costly.
//
// Conforms to runtime/reference_pca.cpp (x = mean + sum_k basis_k * w_k, k ascending, starting at the
// mean) and runtime/reference_skinning.cpp (core/skinning.cpp: B = sum over influences with w != 0 of
// w * M, then B * x). `precise` forbids fused multiply-add contraction so that the sums round like
// the CPU reference (which is compiled without FMA); devices may still differ within the documented
// tolerance.
//
// Loops over K and the influences are unrolled ([[unroll]]; both are specialisation constants), so
// that the per-thread basis and skin arrays stay in registers instead of indexed scratch memory.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "swish_buffers.glsl"
#include "swish_layouts.h"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint K = 1;               // mesh PCA components
layout(constant_id = 2) const uint INFLUENCES = 4;      // skin influences per vertex
layout(constant_id = 3) const bool APPLY_SKINNING = true;  // false: write the pre-skinning shape

layout(push_constant) uniform Push { DeformParams p; };

void main() {
  const uint v = gl_GlobalInvocationID.x;
  if (v >= p.vertexCount) return;
  const uint n3 = p.vertexCount * 3u;

  float basis[3 * K];
  uint joints[INFLUENCES];
  float skinW[INFLUENCES];
  FloatsIn meanBuf = FloatsIn(p.mean);
  FloatsIn basisBuf = FloatsIn(p.basis);
  const vec3 mean = vec3(meanBuf.v[3u * v], meanBuf.v[3u * v + 1u], meanBuf.v[3u * v + 2u]);
  [[unroll]] for (uint k = 0u; k < K; ++k)
    [[unroll]] for (uint a = 0u; a < 3u; ++a) basis[3u * k + a] = basisBuf.v[k * n3 + 3u * v + a];
  UintsIn jointBuf = UintsIn(p.skinJoints);
  FloatsIn skinWeightBuf = FloatsIn(p.skinWeights);
  [[unroll]] for (uint i = 0u; i < INFLUENCES; ++i) {
    joints[i] = jointBuf.v[v * INFLUENCES + i];
    skinW[i] = skinWeightBuf.v[v * INFLUENCES + i];
  }

  FloatsIn weightBuf = FloatsIn(p.weights);
  FloatsIn matrices = FloatsIn(p.skinMatrices);
  FloatsOut outBuf = FloatsOut(p.positionsOut);
  for (uint instance = 0u; instance < p.instanceCount; ++instance) {
    precise vec3 x = mean;
    [[unroll]] for (uint k = 0u; k < K; ++k) {
      const float w = weightBuf.v[instance * K + k];  // the same address in every thread: a broadcast load
      x = x + vec3(basis[3u * k], basis[3u * k + 1u], basis[3u * k + 2u]) * w;
    }
    precise vec3 y = x;
    if (APPLY_SKINNING) {
      // Only the top three rows of each (affine, column-major) matrix are read: 12 loads, not 16.
      // The zero-weight skip is a select, not a branch: every lane runs the same loads (lavapipe
      // gathers per lane, masked branches do not save that), and a skipped matrix still cannot
      // bring its NaN/Inf in.
      precise vec3 b0 = vec3(0.0), b1 = vec3(0.0), b2 = vec3(0.0), b3 = vec3(0.0);
      [[unroll]] for (uint i = 0u; i < INFLUENCES; ++i) {
        const uint m = (instance * p.jointCount + joints[i]) * 16u;
        const float w = skinW[i];
        const vec3 c0 = vec3(matrices.v[m], matrices.v[m + 1u], matrices.v[m + 2u]);
        const vec3 c1 = vec3(matrices.v[m + 4u], matrices.v[m + 5u], matrices.v[m + 6u]);
        const vec3 c2 = vec3(matrices.v[m + 8u], matrices.v[m + 9u], matrices.v[m + 10u]);
        const vec3 c3 = vec3(matrices.v[m + 12u], matrices.v[m + 13u], matrices.v[m + 14u]);
        const bool use = w != 0.0;
        b0 = use ? b0 + w * c0 : b0;
        b1 = use ? b1 + w * c1 : b1;
        b2 = use ? b2 + w * c2 : b2;
        b3 = use ? b3 + w * c3 : b3;
      }
      y = ((b0 * x.x + b1 * x.y) + b2 * x.z) + b3;
    }
    const uint o = (instance * p.vertexCount + v) * 3u;
    outBuf.v[o] = y.x;
    outBuf.v[o + 1u] = y.y;
    outBuf.v[o + 2u] = y.z;
  }
}
