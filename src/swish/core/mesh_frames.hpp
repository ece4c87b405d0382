#pragma once
// Per-vertex tangent frames (normal + tangent with bitangent sign) of a deformed mesh. This is the ONE
// definition of the frames: the bake uses it to express baked normal maps in tangent space, the
// runtime CPU reference uses it as the specification of the GPU normals/tangents pass. If the two
// disagreed, every baked normal map would be rendered in the wrong frame.
//
// Normal: area-weighted sum of face normals over the triangles around the vertex, with seam-split
// copies welded (so a UV seam is invisible in shading). Tangent: sum of per-triangle UV-gradient
// tangents over the vertex's OWN triangles (tangents legitimately differ across UV seams), then
// Gram-Schmidt against the normal; w = sign of the bitangent, +1 or -1.
#include "swish/core/mesh.hpp"

namespace swish {

struct MeshFrameTopology {
  VertexTriangleAdjacency normalAdjacency;   // welded by rest position
  VertexTriangleAdjacency tangentAdjacency;  // own triangles only
};

MeshFrameTopology buildFrameTopology(const Triangles& tris, const Points3f& restPositions);

// Fallbacks, so the output is always finite for finite input: a vertex with no area around it gets
// normal (0,0,1); a tangent that vanishes after Gram-Schmidt is replaced by a fixed perpendicular.
void computeVertexFrames(const Points3f& positions, const Points2f& uvs, const Triangles& tris,
                         const MeshFrameTopology& topo, Points3f& normals, Points4f& tangents);

// The fallback perpendicular used above: normalize(cross(n, e)) for the axis e least aligned with n.
Vec3f anyPerpendicular(const Vec3f& n);

}  // namespace swish
