#pragma once
// Which body triangles the garment covers in every training pose (issue: "hide what games hide"). A
// game does not draw the skin under a tight garment; the preview renderer and a host can do the same
// with this list (Model::bodyCoverage, api::ModelInfo::coveredBodyTriangles), so that a body the
// garment sits on can never show through it.
//
// A body triangle is covered in a pose when the ray from its centroid along its outward normal meets
// the garment (either side) within maxGap; it is listed when it is covered in every pose given. The body
// is skinned per pose with the character's own skeleton, the garment is the pose's simulated game
// mesh (DatasetPose::gameMeshWorld, the shape the network learns).
#include <cstdint>
#include <vector>

#include "swish/bake/dataset/dataset.hpp"
#include "swish/core/character.hpp"

namespace swish::bake {

struct BodyCoverageOptions {
  float maxGap = 0.04f;  // m between the body and the garment above it
  size_t maxPoses = 400;  // evenly spaced over the poses given, for the cost (a few ms per pose)
};

struct BodyCoverageResult {
  uint32_t bodyTriangles = 0;     // the body's triangle count (the list's indices refer to it)
  std::vector<uint32_t> covered;  // ascending
  size_t poses = 0;               // poses tested
  size_t coveredAtRest = 0;       // triangles covered in the first pose alone, for the report
};

BodyCoverageResult coveredBodyTriangles(const Character& character, const std::vector<const DatasetPose*>& poses,
                                        const BodyCoverageOptions& options = {});

}  // namespace swish::bake
