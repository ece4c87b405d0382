#pragma once
// Topology checks for garment meshes before simulation. Positions are welded first (seam-split copies
// are one surface point), then:
//  - every edge is shared by at most two triangles (else: non-manifold);
//  - two triangles sharing an edge traverse it in opposite directions (else: flipped winding);
//  - no degenerate triangle (repeated welded vertex, zero area);
//  - the surface faces outwards: its signed volume about its own centroid is positive (an inward-facing
//    tube or shell has a negative one), and where the file has normals, most face normals agree with them.
#include <string>

#include "swish/core/mesh.hpp"

namespace swish::io {

struct TopologyReport {
  size_t nonManifoldEdges = 0;
  size_t inconsistentEdges = 0;  // shared edges traversed the same way by both triangles
  size_t degenerateTriangles = 0;
  size_t boundaryEdges = 0;
  double signedVolume = 0.0;     // about the centroid of the welded vertices
  double normalAgreement = 1.0;  // fraction of triangles whose normal agrees with the stored normals
};

TopologyReport analyseTopology(const Mesh& mesh);

// Throws Error starting with `what` describing the first problem found.
void checkGarmentTopology(const Mesh& mesh, const std::string& what);

}  // namespace swish::io
