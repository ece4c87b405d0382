#pragma once
// Seeded random models for tests and benchmarks: valid by construction (Model::validate passes), with
// the shapes asked for. Not meant to look like cloth; meant to exercise every code path.
#include <cstdint>

#include "swish/core/rng.hpp"
#include "swish/model/model.hpp"

namespace swish::test {

struct RandomModelSpec {
  uint32_t joints = 8;          // skeleton size (a chain with a few branches)
  uint32_t inputJoints = 4;     // Theta joints
  bool rootGravity = false;     // Theta ends with the gravity values (Model::rootGravity)
  uint32_t vertices = 100;      // game-mesh vertices (a strip of triangles over a UV-mapped grid)
  uint32_t influences = 4;      // skin influences per vertex, 1..8
  uint32_t meshComponents = 6;  // K
  uint32_t hiddenLayers = 2;
  uint32_t hiddenWidth = 16;
  uint32_t normalMaps = 4;  // 0: model without a normal-map database
  uint32_t codeDims = 3;
  uint32_t mapSize = 16;  // width = height, multiple of 4
  uint32_t codebookSize = 32;
  bool bodyAnchors = false;     // one body anchor per vertex (every 7th without), drawn after the MLP
  uint32_t noveltyCentres = 0;  // novelty guard centres (drawn after the anchors), with clamp and blend
  bool secondAnchors = false;   // with bodyAnchors: second anchors too (every 5th without), drawn last
  bool thirdAnchors = false;    // with secondAnchors: third anchors too (every 3rd from 2 without), drawn after them
};

Model makeRandomModel(Rng& rng, const RandomModelSpec& spec = {});

// A random pose for the model's skeleton: rotations of up to maxAngle radians per joint.
Pose makeRandomPose(Rng& rng, const Skeleton& skeleton, float maxAngle = 0.8f);

// The seed a test uses: SWISH_TEST_SEED from the environment if set, else `fallback`.
uint64_t testSeed(uint64_t fallback);
// testSeed(fallback), printed so that a failing run can be replayed (support/seeded_test.hpp also adds
// it to the failure messages).
uint64_t announcedTestSeed(uint64_t fallback);

}  // namespace swish::test
