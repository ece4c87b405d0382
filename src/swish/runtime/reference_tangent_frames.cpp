#include "swish/runtime/reference_tangent_frames.hpp"

#include "swish/core/error.hpp"

namespace swish::runtime {

ReferenceTangentFrames referenceTangentFrames(const Points3f& deformed, const Mesh& rest,
                                              const MeshFrameTopology& topo) {
  if (deformed.rows() != rest.positions.rows())
    throw Error("tangent frames: " + std::to_string(deformed.rows()) + " deformed vertices for a mesh of " +
                std::to_string(rest.positions.rows()));
  ReferenceTangentFrames f;
  computeVertexFrames(deformed, rest.uvs, rest.triangles, topo, f.normals, f.tangents);
  return f;
}

}  // namespace swish::runtime
