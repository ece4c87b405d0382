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
// and two baselines on the same poses, so a reader sees whether the network helps at all:
//   rest skinned = skin(the garment's rest shape) vs truth        (linear skinning, no correctives)
//   mean skinned = skin(the PCA mean shape) vs truth               (the average corrective, no network)
// Normal-map angular error (degrees) against the baked map of the pose:
//   database   = the uncompressed database map nearest the pose's TRUE code    (what 128 maps can hold)
//   selection  = the uncompressed database map nearest the PREDICTED code
//   total      = the VQ-decoded map nearest the predicted code (what the runtime shows, before the
//                temporal filter), and vqAdded = selection map uncompressed vs VQ-decoded.
// Penetration into the body (when the body is given, bake/report/penetration.hpp), per held-out pose, side by
// side: the truth (the dataset's game mesh), the model's prediction, and the prediction after the
// run-time push-out to the model's body anchors (when it has them; then also its vertex error).
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/compression/normal_map_metrics.hpp"
#include "swish/bake/compression/pca.hpp"
#include "swish/bake/dataset/dataset.hpp"
#include "swish/bake/report/penetration.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct DistanceStats {
  double mean = 0.0, p95 = 0.0, max = 0.0;
};
DistanceStats distanceStats(std::vector<double> values);

// The report's and the model metadata's form of the figures: {mean,p95,max}_mm and {mean,p95,max}_deg.
nlohmann::json toJson(const DistanceStats& s);
nlohmann::json toJson(const AngularErrorStats& s);

nlohmann::json toJson(const PenetrationPool& p);

struct PoseEvaluation {
  uint32_t poseId = 0;
  double meanMm = 0.0, maxMm = 0.0;
  double truncationMeanMm = 0.0;
  double restSkinnedMeanMm = 0.0, meanSkinnedMeanMm = 0.0;  // the baselines' mean on this pose
  double normalTotalDegrees = 0.0;                          // mean over texels (NaN-free; 0 without normal maps)
  uint32_t selectedMap = 0, idealMap = 0;
  PenetrationStats truthPenetration, modelPenetration, pushedPenetration;  // when measured
};

struct BakeEvaluation {
  size_t poses = 0;
  DistanceStats totalMm, truncationMm, regressionMm;
  DistanceStats restSkinnedMm, meanSkinnedMm;  // the baselines
  bool hasNormalMaps = false;
  AngularErrorStats normalDatabase, normalSelection, normalTotal, normalVqAdded;
  double selectionAgreement = 0.0;  // share of poses whose predicted map is the ideal one
  std::vector<PoseEvaluation> perPose;
  bool penetrationMeasured = false;
  PenetrationPool truthPenetration, modelPenetration;
  bool pushOut = false;  // the model has body anchors: the pushed figures below are measured
  PenetrationPool pushedPenetration;
  DistanceStats totalPushedMm;
};

// uncompressedMaps: the database maps before VQ, in database order (may be empty if the model has none);
// normalPca: the PCA that made the keys (to code each held-out map). Throws Error on size mismatches.
// The penetration figures of an evaluation (null when not measured), for the report and the metadata:
// truth / model / pushed pools, and the vertex error after the push-out.
nlohmann::json penetrationJson(const BakeEvaluation& ev);

// The model's skinned garment for a pose through the runtime path (Theta -> MLP -> PCA -> skinning, then
// the push-out when asked and the model has body anchors).
Points3f predictPositions(const Model& model, const Pose& pose, bool pushOut);
// The same garment before skinning (pre-skinning space, as DatasetPose::gameMeshPreSkin): the PCA
// reconstruction of the network's (guarded) mesh weights.
Points3f predictPreSkin(const Model& model, const Pose& pose);

// body (optional): the character's body, skinned to the model's skeleton: penetration is measured.
BakeEvaluation evaluateModel(const Model& model, const std::vector<const DatasetPose*>& heldOut,
                             const std::vector<const NormalMapImage*>& uncompressedMaps, const PcaResult* normalPca,
                             const Mesh* body = nullptr);

}  // namespace swish::bake
