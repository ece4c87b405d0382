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
  Mat4sIn matrices = Mat4sIn(p.skinMatrices);
  FloatsOut outBuf = FloatsOut(p.positionsOut);
  for (uint instance = 0u; instance < p.instanceCount; ++instance) {
    precise vec3 x = mean;
    [[unroll]] for (uint k = 0u; k < K; ++k) {
      const float w = weightBuf.v[instance * K + k];  // the same address in every thread: a broadcast load
      x = x + vec3(basis[3u * k], basis[3u * k + 1u], basis[3u * k + 2u]) * w;
    }
    precise vec3 y = x;
    if (APPLY_SKINNING) {
      precise mat4 b = mat4(0.0);
      [[unroll]] for (uint i = 0u; i < INFLUENCES; ++i)
        if (skinW[i] != 0.0) b = b + skinW[i] * matrices.m[instance * p.jointCount + joints[i]];
      y = ((b[0].xyz * x.x + b[1].xyz * x.y) + b[2].xyz * x.z) + b[3].xyz;
    }
    const uint o = (instance * p.vertexCount + v) * 3u;
    outBuf.v[o] = y.x;
    outBuf.v[o + 1u] = y.y;
    outBuf.v[o + 2u] = y.z;
  }
}
