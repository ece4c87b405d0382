#pragma once
// Triangle meshes with skin weights. Vertices may be split at UV seams (one UV per vertex, as glTF
// requires); split copies share position and weights.
#include <string>

#include "swish/core/types.hpp"

namespace swish {

constexpr int kMaxInfluences = 8;

struct SkinWeights {
  int influences = 4;            // per vertex, 1..kMaxInfluences
  std::vector<uint16_t> joints;  // vertexCount * influences, joint indices into the skeleton
  std::vector<float> weights;    // vertexCount * influences, non-negative, summing to 1 per vertex

  size_t vertexCount() const { return influences > 0 ? weights.size() / size_t(influences) : 0; }
  // The joint with the largest weight on `vertex` (the first of equal ones): where a vertex "is" in
  // messages, and how vertices are grouped by body part.
  uint16_t strongestJoint(size_t vertex) const {
    const size_t base = vertex * size_t(influences);
    size_t best = base;
    for (size_t k = base + 1; k < base + size_t(influences); ++k)
      if (weights[k] > weights[best]) best = k;
    return joints[best];
  }
};

struct Mesh {
  Points3f positions;   // N x 3
  Points3f normals;     // N x 3 (may be empty)
  Points4f tangents;    // N x 4: xyz tangent, w = bitangent sign (may be empty)
  Points2f uvs;         // N x 2 (may be empty)
  Triangles triangles;  // T x 3
  SkinWeights skin;     // may be empty (influences * N == 0)

  size_t vertexCount() const { return size_t(positions.rows()); }
  size_t triangleCount() const { return size_t(triangles.rows()); }
  // Throws Error naming `what` for out-of-range indices, size mismatches, non-finite data,
  // degenerate skin weights, or joints >= jointCount (when jointCount > 0).
  void validate(const std::string& what, size_t jointCount = 0) const;
};

// Weld map: for each vertex, the smallest index of a vertex at exactly the same position. Used to
// treat seam-split copies as one surface point (normals, simulation).
std::vector<uint32_t> weldByPosition(const Points3f& positions);

// The triangles with every corner replaced by its weldByPosition representative: the surface with its
// seam copies joined (closed where only UV seams split it), over the same vertex array.
Triangles trianglesWeldedByPosition(const Points3f& positions, const Triangles& triangles);

// The edges (lower index first, ascending) that exactly one triangle uses: a surface's openings. Weld first
// (trianglesWeldedByPosition) for a mesh whose UV seams split it, or every seam is an opening too.
std::vector<std::pair<uint32_t, uint32_t>> openEdges(const Triangles& triangles);

// Vertex -> incident triangles, in compressed sparse rows. Gathered (never scattered), so that the
// GPU pass needs no float atomics and the CPU reference sums in the same order.
struct VertexTriangleAdjacency {
  std::vector<uint32_t> offsets;    // vertexCount + 1
  std::vector<uint32_t> triangles;  // incident triangle indices, ascending per vertex
};
// `weld` (optional, from weldByPosition) makes seam copies share each other's triangles.
VertexTriangleAdjacency buildVertexTriangleAdjacency(const Triangles& tris, size_t vertexCount,
                                                     const std::vector<uint32_t>* weld = nullptr);

// Vertex -> the vertices it shares a triangle edge with, ascending, without repeats. With `weld` (from
// weldByPosition) both ends of every edge are mapped to their representatives first: the lists of the
// representatives hold representatives, and every other vertex's list is empty.
std::vector<std::vector<uint32_t>> buildVertexNeighbours(const Triangles& tris, size_t vertexCount,
                                                         const std::vector<uint32_t>* weld = nullptr);
// Every edge of those lists once, lower index first, ascending.
std::vector<std::pair<uint32_t, uint32_t>> uniqueEdges(const std::vector<std::vector<uint32_t>>& neighbours);
// The length of each of those edges in `positions`.
std::vector<float> edgeLengths(const Points3f& positions, const std::vector<std::pair<uint32_t, uint32_t>>& edges);

// Connected parts by shared vertex indices: per vertex, the smallest vertex index of its part (a
// vertex in no triangle is a part of its own).
std::vector<uint32_t> connectedParts(const Triangles& tris, size_t vertexCount);

}  // namespace swish
