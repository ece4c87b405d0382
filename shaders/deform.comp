#version 460
// PCA reconstruction (pre-skinning space) + linear blend skinning for ALL instances of one model in one
// dispatch. One thread per vertex: it loads its 3K basis values and its skin influences ONCE, then
// loops over the instances, whose weights are staged in shared memory in chunks. The basis, the
// largest input (3N x K floats), is therefore read once per frame, not once per instance.
//
// Conforms to runtime/reference_pca.cpp (x = mean + sum_k basis_k * w_k, k ascending, starting at the
// mean) and runtime/reference_skinning.cpp (core/skinning.cpp: B = sum over influences with w != 0 of
// w * M, then B * x). `precise` forbids fused multiply-add contraction so that the sums round like
// the CPU reference (which is compiled without FMA); devices may still differ within the documented
// tolerance.
#extension GL_GOOGLE_include_directive : require
#include "swish_buffers.glsl"
#include "swish_layouts.h"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint K = 1;               // mesh PCA components
layout(constant_id = 2) const uint INFLUENCES = 4;      // skin influences per vertex
layout(constant_id = 3) const bool APPLY_SKINNING = true;  // false: write the pre-skinning shape

layout(push_constant) uniform Push { DeformParams p; };

shared float sWeights[SWISH_DEFORM_SHARED_WEIGHTS];

void main() {
  const uint v = gl_GlobalInvocationID.x;
  const bool inRange = v < p.vertexCount;
  const uint n3 = p.vertexCount * 3u;

  float basis[3 * K];
  vec3 mean = vec3(0.0);
  uint joints[INFLUENCES];
  float skinW[INFLUENCES];
  if (inRange) {
    FloatsIn meanBuf = FloatsIn(p.mean);
    FloatsIn basisBuf = FloatsIn(p.basis);
    mean = vec3(meanBuf.v[3u * v], meanBuf.v[3u * v + 1u], meanBuf.v[3u * v + 2u]);
    for (uint k = 0u; k < K; ++k)
      for (uint a = 0u; a < 3u; ++a) basis[3u * k + a] = basisBuf.v[k * n3 + 3u * v + a];
    UintsIn jointBuf = UintsIn(p.skinJoints);
    FloatsIn skinWeightBuf = FloatsIn(p.skinWeights);
    for (uint i = 0u; i < INFLUENCES; ++i) {
      joints[i] = jointBuf.v[v * INFLUENCES + i];
      skinW[i] = skinWeightBuf.v[v * INFLUENCES + i];
    }
  }

  FloatsIn weightBuf = FloatsIn(p.weights);
  Mat4sIn matrices = Mat4sIn(p.skinMatrices);
  FloatsOut outBuf = FloatsOut(p.positionsOut);
  const uint chunk = SWISH_DEFORM_SHARED_WEIGHTS / K;
  for (uint first = 0u; first < p.instanceCount; first += chunk) {
    const uint count = min(chunk, p.instanceCount - first);
    barrier();  // the previous chunk's weights are no longer read
    for (uint i = gl_LocalInvocationID.x; i < count * K; i += gl_WorkGroupSize.x)
      sWeights[i] = weightBuf.v[first * K + i];
    barrier();
    if (!inRange) continue;
    for (uint j = 0u; j < count; ++j) {
      precise vec3 x = mean;
      for (uint k = 0u; k < K; ++k) {
        const float w = sWeights[j * K + k];
        x = x + vec3(basis[3u * k], basis[3u * k + 1u], basis[3u * k + 2u]) * w;
      }
      precise vec3 y = x;
      if (APPLY_SKINNING) {
        const uint instance = first + j;
        precise mat4 b = mat4(0.0);
        for (uint i = 0u; i < INFLUENCES; ++i)
          if (skinW[i] != 0.0) b = b + skinW[i] * matrices.m[instance * p.jointCount + joints[i]];
        y = ((b[0].xyz * x.x + b[1].xyz * x.y) + b[2].xyz * x.z) + b[3].xyz;
      }
      const uint o = ((first + j) * p.vertexCount + v) * 3u;
      outBuf.v[o] = y.x;
      outBuf.v[o + 1u] = y.y;
      outBuf.v[o + 2u] = y.z;
    }
  }
}
