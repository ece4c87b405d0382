#version 460
// The gather pass of the two-pass tangent frames, storing 64-bit words (devices with shaderInt64):
// vertex_frames_gather.glsl.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_shader_explicit_arithmetic_types_int64 : require
#define SWISH_TF_STORE64 1
#include "vertex_frames_gather.glsl"
