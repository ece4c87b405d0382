#version 460
// The triangle pass of the two-pass tangent frames, storing 32-bit floats: the code and its
// description are in triangle_frames.glsl.
#extension GL_GOOGLE_include_directive : require
#include "triangle_frames.glsl"
