#pragma once
// CPU reference of shaders/tangent_frames.comp: normals and tangents of a deformed mesh, exactly
// core/mesh_frames.hpp's computeVertexFrames over buildFrameTopology(triangles, REST positions)
// (the adjacency is fixed by the rest mesh, so seams stay welded however the mesh deforms).
#include "swish/core/mesh_frames.hpp"

namespace swish::runtime {

struct ReferenceTangentFrames {
  Points3f normals;   // N x 3
  Points4f tangents;  // N x 4 (w = bitangent sign)
};

ReferenceTangentFrames referenceTangentFrames(const Points3f& deformed, const Mesh& restMesh,
                                              const MeshFrameTopology& topology);

}  // namespace swish::runtime
