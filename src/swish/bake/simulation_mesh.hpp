#pragma once
// The high-resolution cloth the source simulation runs on: the game mesh welded by position (seam-split
// copies become one cloth vertex, so the cloth does not tear along UV seams) and subdivided until it
// has about the requested number of vertices; or the character's own simulation mesh when it has one.
#include <cstddef>
#include <vector>

#include "swish/core/character.hpp"

namespace swish::bake {

struct SimulationMesh {
  Points3f restPositions;              // character space, rest (A-)pose
  Triangles triangles;                 // welded: neighbours share vertex indices
  SkinWeights skin;                    // per simulation vertex
  std::vector<uint32_t> gameToSim;     // game-mesh vertex -> simulation vertex at its rest position
  int subdivisionLevels = 0;           // midpoint levels applied to the welded game mesh
  bool fromCharacterSimulationMesh = false;

  size_t vertexCount() const { return size_t(restPositions.rows()); }
};

constexpr size_t kDefaultSimulationVertices = 12000;

// Builds the simulation mesh of `character` (validated first: skin weights present, indices in range,
// every edge shared by at most two triangles). With character.simulationMesh, that mesh is welded and
// used as is, and each game vertex maps to the nearest simulation vertex. Otherwise the welded game
// mesh is midpoint-subdivided the number of times that brings its vertex count closest to
// `targetVertices` (0: no subdivision). Throws Error naming the mesh and the problem.
SimulationMesh buildSimulationMesh(const Character& character,
                                   size_t targetVertices = kDefaultSimulationVertices);

// One level of midpoint (1 -> 4) subdivision. New vertices sit at edge midpoints (the rest shape is
// kept exactly, so a garment that clears the body keeps clearing it up to the chord sag), with the
// two end points' skin weights averaged, cut back to the mesh's influence count and renormalised.
// gameToSim is unchanged (old vertices keep their indices).
SimulationMesh subdivideMidpoint(const SimulationMesh& mesh);

// Welds by exact position and drops unused vertices. Returns, per input vertex, its welded index.
// Used for the game mesh and a character's own simulation mesh alike.
SimulationMesh weldedSimulationMesh(const Mesh& mesh, std::vector<uint32_t>& inputToWelded);

}  // namespace swish::bake
