#version 460
// Benchmark baseline: a plain vec4 copy, the memory bandwidth the deform kernel is measured against.
#extension GL_GOOGLE_include_directive : require
#include "swish_buffers.glsl"
#include "swish_layouts.h"

layout(local_size_x_id = 0) in;
layout(push_constant) uniform Push { CopyVec4Params p; };
layout(buffer_reference, std430, buffer_reference_align = 16) readonly buffer Vec4In { vec4 v[]; };
layout(buffer_reference, std430, buffer_reference_align = 16) writeonly buffer Vec4Out { vec4 v[]; };

void main() {
  const uint i = gl_GlobalInvocationID.x;
  if (i < p.count) Vec4Out(p.dst).v[i] = Vec4In(p.src).v[i];
}
