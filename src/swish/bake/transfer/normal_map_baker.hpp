#pragma once
// Baking the tangent-space normal map of the detail the smoothed game mesh lacks (paper 2.2: "generate
// normal map textures that represent the difference in detail between the two meshes").
//
// The game mesh's UV layout is rasterised once: each texel centre ((x + .5) / width, (y + .5) / height)
// that falls inside a UV triangle records that triangle and its barycentrics (overlapping UVs: the
// lowest triangle index wins). Per pose, for each such texel:
//   - surface point and tangent frame on the smoothed game mesh, interpolated from the per-vertex
//     frames of computeVertexFrames (THE frame definition, the one the runtime GPU pass computes):
//     N = normalize(lerp n), T = lerp t made orthonormal to N, B = sign * N x T;
//   - rays from the point along +N and -N (Embree) to the simulation mesh, nearest hit within
//     maxDistance; hits whose surface faces away from N (the far side of a sleeve or the inside of the
//     opposite panel) are skipped and the ray continues;
//   - the simulation mesh's interpolated (welded, area-weighted) vertex normal n there, written as
//     X = n . T, Y = n . B (Z = n . N is implied).
// Texels with no hit within maxDistance and texels outside every chart are then filled by ring
// dilation (uv_dilation.hpp). Deterministic: every texel is independent, so the parallel loop gives the
// same bits as a serial one.
#include <string>
#include <vector>

#include "swish/bake/dataset/dataset.hpp"
#include "swish/core/mesh_frames.hpp"

namespace swish::bake {

struct NormalMapBakeSettings {
  uint32_t width = 360, height = 360;
  float maxDistance = 0.03f;  // metres along +/- N to look for the simulation surface
  int dilationRings = 8;      // >= 0
};

struct NormalMapBakeStats {
  size_t chartTexels = 0;    // texels inside some UV triangle
  size_t hitTexels = 0;      // of those, found the simulation surface
  size_t missedTexels = 0;   // inside a chart but no valid hit within maxDistance (filled by dilation)
  size_t dilatedTexels = 0;  // filled from neighbours
  size_t flatTexels = 0;     // still empty after dilation, set to (0, 0)
  float meanHitDistance = 0.f, maxHitDistance = 0.f;
};

class NormalMapBaker {
 public:
  // The game mesh's UVs and triangles and its rest positions (for the frame topology: seams are welded
  // by rest position). Throws Error naming `what` for a mesh without UVs, bad indices or bad settings.
  NormalMapBaker(const Points2f& gameUvs, const Triangles& gameTriangles, const Points3f& gameRest,
                 const NormalMapBakeSettings& settings, const std::string& what = "normal-map bake");

  // One pose: the smoothed game mesh and the simulation mesh (its topology from buildFrameTopology on
  // its rest positions, for welded normals), both in the same (character) space.
  NormalMapImage bake(const Points3f& gamePositions, const Points3f& simPositions, const Triangles& simTriangles,
                      const MeshFrameTopology& simTopology, NormalMapBakeStats* stats = nullptr) const;

  const NormalMapBakeSettings& settings() const { return settings_; }
  size_t chartTexelCount() const { return texels_.size(); }

 private:
  struct ChartTexel {
    uint32_t index;     // y * width + x
    uint32_t triangle;  // game triangle
    float b1, b2;       // barycentrics of corners 1 and 2
  };
  Points2f uvs_;
  Triangles triangles_;
  MeshFrameTopology topology_;
  NormalMapBakeSettings settings_;
  std::string what_;
  std::vector<ChartTexel> texels_;  // ascending index
};

}  // namespace swish::bake
