#version 460
// The gather pass of the two-pass tangent frames, storing 32-bit floats: the code and its description
// are in vertex_frames_gather.glsl.
#extension GL_GOOGLE_include_directive : require
#include "vertex_frames_gather.glsl"
