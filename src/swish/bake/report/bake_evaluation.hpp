#pragma once
// The bake report's measurements, taken on held-out poses through the real run-time path:
// Theta (runtime/theta) -> MLP (runtime::MlpEvaluator) -> PCA reconstruction (runtime reference) ->
// skinning (runtime reference), and nearest-code lookup (runtime::NearestCodeSearch) -> VQ decode
// (runtime reference).
//
// Vertex error (mm) against the transferred, smoothed game mesh of the dataset:
//   truncation = skin(PCA projection of the true pre-skin shape) vs truth  (what K components can hold)
//   regression = skin(prediction) vs skin(PCA projection)                  (what the MLP gets wrong)
//   total      = skin(prediction) vs truth
// Normal-map angular error (degrees) against the baked map of the pose:
//   database   = the uncompressed database map nearest the pose's TRUE code    (what 128 maps can hold)
//   selection  = the uncompressed database map nearest the PREDICTED code
//   total      = the VQ-decoded map nearest the predicted code (what the runtime shows, before the
//                temporal filter), and vqAdded = selection map uncompressed vs VQ-decoded.
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/dataset/dataset.hpp"
#include "swish/bake/compression/normal_map_metrics.hpp"
#include "swish/bake/compression/pca.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct DistanceStats {
  double mean = 0.0, p95 = 0.0, max = 0.0;
};
DistanceStats distanceStats(std::vector<double> values);

// The report's and the model metadata's form of the figures: {mean,p95,max}_mm and {mean,p95,max}_deg.
nlohmann::json toJson(const DistanceStats& s);
nlohmann::json toJson(const AngularErrorStats& s);

struct PoseEvaluation {
  uint32_t poseId = 0;
  double meanMm = 0.0, maxMm = 0.0;
  double truncationMeanMm = 0.0;
  double normalTotalDegrees = 0.0;  // mean over texels (NaN-free; 0 without normal maps)
  uint32_t selectedMap = 0, idealMap = 0;
};

struct BakeEvaluation {
  size_t poses = 0;
  DistanceStats totalMm, truncationMm, regressionMm;
  bool hasNormalMaps = false;
  AngularErrorStats normalDatabase, normalSelection, normalTotal, normalVqAdded;
  double selectionAgreement = 0.0;  // share of poses whose predicted map is the ideal one
  std::vector<PoseEvaluation> perPose;
};

// uncompressedMaps: the database maps before VQ, in database order (may be empty if the model has none);
// normalPca: the PCA that made the keys (to code each held-out map). Throws Error on size mismatches.
BakeEvaluation evaluateModel(const Model& model, const std::vector<const DatasetPose*>& heldOut,
                             const std::vector<const NormalMapImage*>& uncompressedMaps, const PcaResult* normalPca);

}  // namespace swish::bake
