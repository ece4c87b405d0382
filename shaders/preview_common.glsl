// Shared by the preview renderer's shaders (src/swish/render/preview_pipelines.cpp mirrors the layout
// as PreviewPushConstants, 120 bytes, within the 128 every device allows).
layout(push_constant) uniform PreviewPush {
  mat4 viewProj;       // world -> clip
  vec4 cameraPos;      // xyz, world
  vec4 lightDir;       // xyz: unit direction towards the key light
  vec4 baseColor;      // rgb albedo
  uint layer;          // normal-map layer of the character
  uint useNormalMap;   // 0: shade with the interpolated vertex normal only
} pc;

// A key light, a cool fill from the other side and a sky/ground ambient term, plus a little
// Blinn-Phong: enough for folds and wrinkles to read in a still image. Gamma 2.2 on output.
vec3 shade(vec3 n, vec3 worldPos, vec3 albedo) {
  const vec3 v = normalize(pc.cameraPos.xyz - worldPos);
  if (dot(n, v) < 0.0) n = -n;  // back faces of an open garment (collar, sleeves) seen from inside
  const vec3 l = normalize(pc.lightDir.xyz);
  const vec3 fill = normalize(vec3(-l.x, 0.3, l.z));
  const float key = max(dot(n, l), 0.0);
  const float back = max(dot(n, fill), 0.0) * 0.25;
  const float sky = 0.5 + 0.5 * n.y;
  const vec3 h = normalize(l + v);
  const float spec = pow(max(dot(n, h), 0.0), 32.0) * 0.15 * step(0.0, dot(n, l));
  const vec3 lit = albedo * (0.85 * key + back + 0.18 * mix(0.6, 1.0, sky)) + vec3(spec);
  return pow(clamp(lit, 0.0, 1.0), vec3(1.0 / 2.2));
}
