#version 460
// The normal-map blend, storing 64-bit words (devices with shaderInt64): normal_map_blend.glsl.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#define SWISH_BLEND_STORE64 1
#include "normal_map_blend.glsl"
