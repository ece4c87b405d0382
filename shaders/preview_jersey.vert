#version 460
// The jersey straight from swish's deformed vertex streams (world space).
#extension GL_GOOGLE_include_directive : require
#include "preview_common.glsl"
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv;
layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec3 outNormal;
layout(location = 2) out vec4 outTangent;
layout(location = 3) out vec2 outUv;
void main() {
  outPosition = inPosition;
  outNormal = inNormal;
  outTangent = inTangent;
  outUv = inUv;
  gl_Position = pc.viewProj * vec4(inPosition, 1.0);
}
