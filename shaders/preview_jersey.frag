#version 460
// The jersey, lit, with swish's per-character tangent-space normal map (X, Y stored; Z rebuilt).
#extension GL_GOOGLE_include_directive : require
#include "preview_common.glsl"
layout(set = 0, binding = 0) uniform sampler2DArray normalMaps;
layout(location = 0) in vec3 inPosition;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec4 inTangent;
layout(location = 3) in vec2 inUv;
layout(location = 0) out vec4 outColor;
void main() {
  vec3 n = normalize(inNormal);
  if (pc.useNormalMap != 0u) {
    const vec3 t = normalize(inTangent.xyz - n * dot(n, inTangent.xyz));
    const vec3 b = cross(n, t) * (inTangent.w < 0.0 ? -1.0 : 1.0);  // MikkTSpace bitangent
    const vec2 xy = texture(normalMaps, vec3(inUv, float(pc.layer))).xy;
    const float z = sqrt(max(0.0, 1.0 - dot(xy, xy)));
    n = normalize(t * xy.x + b * xy.y + n * z);
  }
  outColor = vec4(shade(n, inPosition, pc.baseColor.rgb), 1.0);
}
