#version 460
#extension GL_GOOGLE_include_directive : require
#include "preview_common.glsl"
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 0) out vec4 outColor;
void main() { outColor = vec4(shade(normalize(inNormal), inPosition, pc.baseColor.rgb), 1.0); }
