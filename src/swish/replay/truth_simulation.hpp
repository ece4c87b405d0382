#pragma once
// Ground truth for `swish replay --truth-every N`: on every Nth frame each on-screen character's pose is
// simulated as the model's bake simulated its training poses (bake/pipeline/pose_shape.hpp: limb clearance,
// cloth solve from the A-pose, transfer + Laplacian smoothing, normal-map bake), and the run time's
// GPU output of that frame is measured against it: per-vertex distance (mm) and per-texel normal-map
// angle (degrees, every texel, as the bake's evaluation measures its held-out poses).
//
// What is simulated is what the bake simulates: the pose with the root joint at its rest rotation and
// translation (the shape is a function of the other joints alone, bake/pipeline/part1_dataset.hpp). The
// truth's pre-skin shape is then skinned with the frame's whole pose and the model's skin weights,
// exactly as the run time skins the model's prediction, so the error is that of the predicted shape.
// Both sides are in CHARACTER space: the placement, however far from the origin, never enters it.
//
// Rebuilding the simulator needs the bake's character and settings. The settings are the model's
// metadata "dataset_settings" (written by `swish bake`); the character is rebuilt as the bake built it
// (the embedded default by code, a recipe file or a character file when that file is at hand) and
// must match the model (skeleton, game mesh, UVs, skin weights). Otherwise (the procedural stand-in,
// a model without bake metadata, a character file not at hand, another character) there is no truth
// and ModelTruth::note() says why.
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "swish/bake/cloth/body_collider.hpp"
#include "swish/bake/compression/normal_map_metrics.hpp"
#include "swish/bake/pipeline/pose_shape.hpp"
#include "swish/replay/model_library.hpp"
#include "swish/runtime/reference_normal_blend.hpp"

namespace swish::replay {

struct TruthOptions {
  uint32_t every = 0;                        // 0: none; N: frames whose index in the scene is a multiple of N
  std::optional<size_t> simulationVertices;  // instead of the bake's (tests and quick looks: coarser, faster)
  std::optional<int> substeps;               // instead of the bake's
  // part1.transfer.cover_body_mm instead of the bake's (0: off): what keeping the game mesh over the body does
  // to the truth, measured on a model baked without it (or the reverse).
  std::optional<float> coverBodyMm;
  // part1.simulation.limb_clearance (mm here) instead of the bake's (0: poses simulated as recorded): what turning
  // limbs out of the trunk before simulating does to the truth.
  std::optional<float> limbClearanceMm;
  bool normalMaps = true;  // also bake the truth normal map and measure the run time's
};

// One character on one truth frame.
struct CharacterTruth {
  uint32_t character = 0;                   // scene character index
  bool ok = false;                          // a truth shape was simulated and measured
  std::string failure;                      // why not (the simulation failed: the bake leaves such poses out too)
  double meanMm = 0, p95Mm = 0, maxMm = 0;  // per-vertex distance to the truth
  // The same for the positions without the push-out (the CPU reference), when it ran.
  bool comparedWithout = false;
  double meanMmWithout = 0, p95MmWithout = 0, maxMmWithout = 0;
  bool normalMap = false;                      // the normal map was measured
  double meanDeg = 0, p95Deg = 0, maxDeg = 0;  // per-texel angle to the truth map
  uint32_t limbCorrections = 0;                // limbs limb clearance turned out of the trunk before simulating
  double seconds = 0;     // this pose's clearance + simulation + transfer + bake: wall time on its thread
  double cpuSeconds = 0;  // the same in CPU time of that thread (what a shared machine does not inflate)
};

// A measurement with what pooling needs: every vertex distance and the texel-angle histogram.
struct TruthMeasurement {
  CharacterTruth summary;
  std::vector<double> vertexMm;
  Points3f truthPositions;              // the truth's game mesh, skinned as the run time skins (when ok)
  std::vector<double> vertexMmWithout;  // empty unless compared without the push-out
  // With vertexMmWithout and a body: per vertex 1 where the truth itself lies inside the posed body (the
  // source simulation's cloth inside the arm or trunk, which no push-out can match), else 0.
  std::vector<uint8_t> truthInside;
  std::unique_ptr<bake::AngularErrorAccumulator> angles;  // null without a normal map
};

// Pooled over (frame, character) pairs: one character's truth frames, or all of them.
struct TruthSummary {
  uint32_t samples = 0;                     // measured pairs
  uint32_t failed = 0;                      // pairs whose truth simulation failed (not measured)
  double meanMm = 0, p95Mm = 0, maxMm = 0;  // over every vertex of every measured pair
  bool comparedWithout = false;             // every measured pair also measured without the push-out
  double meanMmWithout = 0, p95MmWithout = 0, maxMmWithout = 0;
  // The push-out's change split by where the truth lies (every measured pair has truthInside): does it
  // take the garment away from a truth that is outside the body (a fault of the push-out), or only from
  // one inside it (a fault of the truth)? Mean vertex error with and without the push-out, each side.
  bool splitByTruth = false;
  double truthInsideShare = 0;  // of the vertices measured
  double meanMmTruthOutside = 0, meanMmWithoutTruthOutside = 0;
  double meanMmTruthInside = 0, meanMmWithoutTruthInside = 0;
  bool normalMaps = false;
  double meanDeg = 0, p95Deg = 0, maxDeg = 0;  // over every texel of every measured map
  double seconds = 0, cpuSeconds = 0;          // summed per-pose seconds (CharacterTruth), failed poses too
};

class TruthPool {
 public:
  void add(const TruthMeasurement& m);
  TruthSummary summary() const;

 private:
  uint32_t samples_ = 0, failed_ = 0;
  double seconds_ = 0, cpuSeconds_ = 0;
  std::vector<double> vertexMm_, vertexMmWithout_;
  std::vector<uint8_t> truthInside_;
  bool allWithout_ = true, allSplit_ = true;
  std::unique_ptr<bake::AngularErrorAccumulator> angles_;
};

// The truth simulator of one model, or why there is none.
class ModelTruth {
 public:
  // Never throws: whatever stops the truth (no bake metadata, character not at hand or different,
  // a solver that cannot be set up) becomes note() with available() false.
  ModelTruth(const ModelEntry& entry, const TruthOptions& options);
  ~ModelTruth();

  bool available() const { return simulator_ != nullptr; }
  // Why there is no truth, or what the truth simulates (character, vertices, substeps, overrides).
  const std::string& note() const { return note_; }
  bool normalMaps() const { return normalMaps_; }

  // The truth of `pose` (on the model's skeleton, as the run time posed the character): the bake's
  // PoseShape of it, with gameMeshWorld the truth's game mesh skinned as the run time skins (the model's
  // weights, the whole pose) and normalMap empty unless normalMaps(). Thread-safe; only when available().
  bake::PoseShape simulate(const Pose& pose) const;
  // Simulates `pose` (on the model's skeleton, as the run time posed the character) and measures the
  // run time's output of it: `positions` (character space) and `normalMap` (null: not measured);
  // `withoutPushOut` (optional): the same frame's positions without the push-out, measured beside them.
  // Thread-safe and deterministic. Only when available().
  TruthMeasurement measure(const Pose& pose, const Points3f& positions, const runtime::BlendedNormalMap* normalMap,
                           const Points3f* withoutPushOut = nullptr) const;

 private:
  void prepare(const ModelEntry& entry, const TruthOptions& options);

  const Model* model_;
  std::string note_;
  bool normalMaps_ = false;
  std::unique_ptr<Character> character_;
  std::unique_ptr<bake::PoseShapeSimulator> simulator_;
  // The character's body at rest, built once; each measurement poses a copy (where the truth lies inside it).
  std::unique_ptr<const bake::BodyCollider> body_;
};

// The character a model was baked on, rebuilt as its bake built it (the embedded default by code, a
// recipe or character file named in the metadata, looked for as written and beside the model file) and
// checked against the model; null with `note` saying why there is none. `how` (optional): how it was
// built, in words.
std::unique_ptr<Character> rebuildBakeCharacter(const ModelEntry& entry, std::string& note, std::string* how = nullptr);

// For the tools that add to a model after its bake (swish body-proxy, swish body-coverage): the model
// file loaded as an entry, and the body it was baked on. Throws Error naming the file, `purpose` and
// why when that body cannot be rebuilt or has no mesh.
struct ModelWithBakeBody {
  ModelEntry entry;
  std::unique_ptr<Character> character;
  std::string how;  // how the character was rebuilt, in words
};
ModelEntry loadModelEntry(const std::string& path);
ModelWithBakeBody loadModelWithBakeBody(const std::string& path, const std::string& purpose);

// Where the rebuilt `character` differs from `model` (skeleton, game mesh, UVs, skin weights), in
// words; empty when it matches.
std::string characterDifference(const Model& model, const Character& character);

}  // namespace swish::replay
