#pragma once
// The high-resolution cloth the source simulation runs on: the game mesh welded by position (seam-split
// copies become one cloth vertex, so the cloth does not tear along UV seams) and refined by longest-edge
// bisection until it has about the requested number of vertices with edges of about one length; or the
// character's own simulation mesh when it has one.
//
// Why even edges and not uniform midpoint subdivision: a game mesh mixes 4 mm and 6 cm edges, and two
// midpoint levels turn its short ones into 1 mm edges whose stiff constraints a few Gauss-Seidel sweeps
// cannot reconcile with the long ones (the shared T-shirt exploded at frame 2 that way).
#include <cstddef>
#include <vector>

#include "swish/core/character.hpp"

namespace swish::bake {

struct SimulationMesh {
  Points3f restPositions;  // character space, rest (A-)pose
  Triangles triangles;     // welded: neighbours share vertex indices
  SkinWeights skin;        // per simulation vertex
  // Game-mesh vertex -> simulation vertex at its rest position (within a quarter of the refined edge
  // length of it where collapseShortEdges merged it into a neighbour).
  std::vector<uint32_t> gameToSim;
  float refinedEdgeLength = 0.f;  // m: longest edge allowed by refineToEdgeLength (0: not refined)

  size_t vertexCount() const { return size_t(restPositions.rows()); }
};

constexpr size_t kDefaultSimulationVertices = 12000;

// Builds the simulation mesh of `character` (validated first: skin weights present, indices in range,
// every edge shared by at most two triangles). With character.simulationMesh, that mesh is welded and
// used as is, and each game vertex maps to the nearest simulation vertex. Otherwise the welded game
// mesh is refined to even edges (refineToEdgeLength, then collapseShortEdges at a quarter of that
// length) with a vertex count within about 10% of `targetVertices`; a game mesh that already has
// that many keeps its vertices except edges under a quarter of its median edge, which collapse
// (0: the welded mesh as is). Throws Error naming the mesh and the problem.
SimulationMesh buildSimulationMesh(const Character& character, size_t targetVertices = kDefaultSimulationVertices);

// Longest-edge bisection (Rivara): splits, longest first, every edge longer than `maxEdge` at its
// midpoint, together with the one or two triangles on it, until none is left. New vertices sit at
// edge midpoints (the rest shape is kept exactly) with the two end points' skin weights averaged, cut
// back to the mesh's influence count and renormalised. Old vertices keep their indices (gameToSim is
// unchanged). Deterministic.
SimulationMesh refineToEdgeLength(const SimulationMesh& mesh, float maxEdge);

// Removes edges shorter than `minEdge` by collapsing them, where that keeps the surface manifold
// (link condition) and flips or squashes no triangle: two interior vertices merge at their midpoint
// (skin weights averaged as in refineToEdgeLength), an edge with a boundary end point collapses onto
// that end point, which keeps its position (hems keep their shape). Game mesh corners closer than a
// fraction of a millimetre (armhole seams) would otherwise be cloth edges whose 400% "strain" under a
// 2 mm contact push dominates every residual. gameToSim follows the merged vertices.
SimulationMesh collapseShortEdges(const SimulationMesh& mesh, float minEdge);

// Welds by exact position and drops unused vertices. Returns, per input vertex, its welded index.
// Used for the game mesh and a character's own simulation mesh alike.
SimulationMesh weldedSimulationMesh(const Mesh& mesh, std::vector<uint32_t>& inputToWelded);

}  // namespace swish::bake
