#version 460
// The deform pass reading the PCA basis as R32 texels (binding 2): deform.glsl.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define SWISH_DEFORM_BASIS_TEXELS 1
#include "deform.glsl"
