#version 460
// The deform pass reading the PCA basis through its buffer address: the code and its description are
// in deform.glsl.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "deform.glsl"
