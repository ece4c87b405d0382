#pragma once
// Quality levels (levels of detail) of one model: a small ladder from full quality down to the PCA mean
// shape skinned. Each level is a valid, cheaper reconstruction of the same model, because PCA components
// are ordered by variance: the first k mesh weights the network predicts give the best k-component
// shape. Per level:
//   meshComponents  k: the deform reads the first k weights (the rest count as 0); 0 reads none and the
//                   network is not run (the mean shape skinned: plain skinning of the average garment)
//   normalMaps      whether the character gets the lookup, the VQ decode and the temporal blend; a level
//                   without them leaves the character's normal map out (the renderer draws the mesh's own
//                   normals)
// The bake measures every level on its held-out poses (bake/report/quality_ladder.hpp) and stores the
// ladder in the model's metadata (key "quality_levels"); the replay's level planner (level_planner.hpp)
// picks a level per character per frame from its size on screen and the frame budget.
//
// Plain data and JSON; no Vulkan, no I/O.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/model/model.hpp"

namespace swish::runtime {

struct QualityLevel {
  std::string name;             // "full", "k64", "k32-flat", "skinned", ...
  uint32_t meshComponents = 0;  // leading PCA components read, 0..K
  bool normalMaps = false;      // lookup + decode + blend for this character

  // Measured by the bake (NaN where not measured).
  double vertexMeanMm = std::numeric_limits<double>::quiet_NaN();
  double vertexP95Mm = std::numeric_limits<double>::quiet_NaN();
  double vertexMaxMm = std::numeric_limits<double>::quiet_NaN();
  // Angle between the normal the renderer shades with at this level (its map, or the mesh's own normal
  // without one) and the truth's, degrees, mean over the map's texels.
  double normalMeanDeg = std::numeric_limits<double>::quiet_NaN();
  double cpuUsPerCharacter = std::numeric_limits<double>::quiet_NaN();  // network + guard + lookup
  double gpuUsPerCharacter = std::numeric_limits<double>::quiet_NaN();  // deform + frames + maps, marginal

  // Whether the network must run for a character at this level (mesh weights or normal code needed).
  bool needsNetwork() const { return meshComponents > 0 || normalMaps; }
};

struct QualityLadder {
  std::vector<QualityLevel> levels;  // level 0 is full quality; cost and quality fall with the index
  std::string measuredOn;            // what the errors were measured on ("held-out poses: 140", ...)
  uint32_t poses = 0;                // poses the errors were measured on (0: not measured)
  std::string timedOn;               // the device / machine the times come from

  bool empty() const { return levels.empty(); }
  size_t size() const { return levels.size(); }
  bool measured() const { return poses > 0; }
  const QualityLevel& operator[](size_t i) const { return levels.at(i); }
};

// The metadata key of the ladder.
inline constexpr const char* kQualityLevelsKey = "quality_levels";

// The ladder a model offers when its metadata holds none (models before the ladder): full (K, maps),
// half the components with maps, a quarter without, an eighth without, and the mean shape skinned.
// Levels that would repeat another (small K, no database) are left out. Errors and times are NaN.
QualityLadder defaultLadder(const Model& model);

// The model's ladder: the metadata's "quality_levels" when present (checked against the model: throws
// Error naming the level when a level asks for more components than K or for maps the model lacks),
// else defaultLadder(model).
QualityLadder ladderOf(const Model& model);
// The same as run with the normal maps left out (normalMaps false: a plan or batch that uploads no
// database): every level keeps its components and draws without maps.
QualityLadder ladderOf(const Model& model, bool normalMaps);

nlohmann::json toJson(const QualityLadder& ladder);
// Throws Error naming `what` and the field on a malformed ladder (missing keys, wrong types, k > K,
// maps on a model without a database, not ordered from full to cheapest).
QualityLadder ladderFromJson(const nlohmann::json& j, const Model& model, const std::string& what);

// The model with its metadata's "quality_levels" replaced by `ladder` (the rest of the metadata kept).
void storeLadder(Model& model, const QualityLadder& ladder);

}  // namespace swish::runtime
