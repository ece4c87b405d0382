#pragma once
// The training dataset: what part 1 of the bake (poses -> simulation -> transfer -> normal maps)
// hands to part 2 (PCA, database, VQ, MLP). In memory here; the on-disk layout (a folder with a
// manifest.json, one file per pose, PNG normal maps) is written and read by dataset_io.hpp.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/core/character.hpp"

namespace swish::bake {

// How a pose's source simulation ended.
struct SimResiduals {
  float maxConstraintViolation = 0.f;  // relative stretch of the worst distance constraint
  float maxPenetration = 0.f;          // metres inside the body (thickness included), worst vertex
  bool converged = false;
  int iterations = 0;
  double seconds = 0.0;
  // The solver's end condition (cloth_solver.hpp; not stored in dataset pose files): the
  // mass-weighted RMS motion of the vertices over the last frame relative to gravity's free fall in
  // a frame (the unbalanced share of gravity's load; -1: not measured), the worst vertex's, and the
  // frames the equilibrium phase took.
  float equilibriumResidual = -1.f;
  float equilibriumResidualMax = -1.f;
  int equilibriumFrames = 0;
  int staticIterations = 0;    // Newton steps of the static solve (0: not run)
  float projectedDepth = 0.f;  // m: the deepest vertex the final projection moved out of the body
};

// A tangent-space normal map, X and Y only (Z = sqrt(1 - X^2 - Y^2)), in [-1, 1].
// Texel (x, y) is stored at xy[2 * (y * width + x) + {0, 1}] and covers UV ((x + .5) / width,
// (y + .5) / height): row 0 is v = 0, glTF's top of the image.
struct NormalMapImage {
  uint32_t width = 0, height = 0;
  std::vector<float> xy;
};

struct DatasetPose {
  uint32_t id = 0;           // index in the thinned pose list (stable across re-runs)
  Pose pose;                 // local rotations on the character's skeleton
  Points3f gameMeshWorld;    // transferred + smoothed game mesh, character space, posed
  Points3f gameMeshPreSkin;  // the same shape un-skinned to pre-skinning space
  NormalMapImage normalMap;  // detail of the simulation mesh the game mesh lacks
  SimResiduals residuals;
};

struct Dataset {
  Character character;                // skeleton, body, game mesh (rest pose)
  std::vector<uint32_t> inputJoints;  // Theta joints, skeleton indices
  std::vector<DatasetPose> poses;     // only poses whose simulation succeeded
  nlohmann::json settings;            // the bake settings that made it
};

}  // namespace swish::bake
