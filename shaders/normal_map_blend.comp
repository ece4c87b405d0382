#version 460
// The normal-map blend, storing 32-bit words: the code and its description are in normal_map_blend.glsl.
#extension GL_GOOGLE_include_directive : require
#include "normal_map_blend.glsl"
