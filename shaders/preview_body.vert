#version 460
// The body as a plain mannequin: positions and normals skinned on the CPU by the preview renderer.
#extension GL_GOOGLE_include_directive : require
#include "preview_common.glsl"
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 0) out vec3 outPosition;
layout(location = 1) out vec3 outNormal;
void main() {
  outPosition = inPosition;
  outNormal = inNormal;
  gl_Position = pc.viewProj * vec4(inPosition, 1.0);
}
