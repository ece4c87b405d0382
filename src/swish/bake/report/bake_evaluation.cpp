#include "swish/bake/report/bake_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "swish/bake/compression/normal_map_pca.hpp"
#include "swish/bake/compression/vq_codebook.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/nearest_code.hpp"
#include "swish/runtime/novelty_guard.hpp"
#include "swish/runtime/reference_pca.hpp"
#include "swish/runtime/reference_push_out.hpp"
#include "swish/runtime/reference_skinning.hpp"
#include "swish/runtime/theta.hpp"

namespace swish::bake {

nlohmann::json toJson(const DistanceStats& s) { return {{"mean_mm", s.mean}, {"p95_mm", s.p95}, {"max_mm", s.max}}; }
nlohmann::json toJson(const AngularErrorStats& s) {
  return {{"mean_deg", s.meanDegrees}, {"p95_deg", s.p95Degrees}, {"max_deg", s.maxDegrees}};
}

nlohmann::json toJson(const PenetrationPool& p) {
  return {{"poses", p.frames},
          {"poses_with_inside", p.framesInside},
          {"poses_visible", p.framesVisible},
          {"vertices_inside", p.inside},
          {"vertices_visible", p.visible},
          {"share_inside", p.share()},
          {"deepest_mm", p.deepestMm},
          {"deepest_p95_mm", p.deepestPercentileMm(0.95)}};
}

nlohmann::json penetrationJson(const BakeEvaluation& ev) {
  if (!ev.penetrationMeasured) return nullptr;
  nlohmann::json j{{"visible_depth_mm", kVisiblePenetrationMm},
                   {"truth", toJson(ev.truthPenetration)},
                   {"model", toJson(ev.modelPenetration)}};
  if (ev.pushOut) {
    j["pushed"] = toJson(ev.pushedPenetration);
    j["vertex_total_pushed"] = toJson(ev.totalPushedMm);
  }
  return j;
}

DistanceStats distanceStats(std::vector<double> v) {
  DistanceStats s;
  if (v.empty()) return s;
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / double(v.size());
  const size_t k = std::min(v.size() - 1, size_t(std::ceil(0.95 * double(v.size()))) - 1);
  std::nth_element(v.begin(), v.begin() + long(k), v.end());
  s.p95 = v[k];
  s.max = *std::max_element(v.begin(), v.end());
  return s;
}

Points3f predictPreSkin(const Model& model, const Pose& pose) {
  const runtime::MlpEvaluator mlp(model);
  const runtime::NoveltyGuardEvaluator guard(model);
  std::vector<float> lambda(size_t(mlp.outputSize()));
  const std::vector<float> theta = runtime::computeTheta(model.inputJoints, model.rootGravity, pose.local);
  mlp.evaluate(theta, lambda);
  guard.apply(guard.measureOne(theta), std::span<float>(lambda.data(), size_t(model.meshComponents())));
  return runtime::referencePcaReconstruct(model.meshPca,
                                          std::span<const float>(lambda.data(), size_t(model.meshComponents())));
}

Points3f predictPositions(const Model& model, const Pose& pose, bool pushOut) {
  const auto mats = model.skeleton.skinningMatrices(pose);
  Points3f p = runtime::referenceSkin(predictPreSkin(model, pose), model.gameMesh.skin, mats);
  if (pushOut && !model.bodyAnchors.empty()) runtime::referencePushOut(p, model.bodyAnchors, mats);
  return p;
}

BakeEvaluation evaluateModel(const Model& model, const std::vector<const DatasetPose*>& heldOut,
                             const std::vector<const NormalMapImage*>& uncompressed, const PcaResult* normalPca,
                             const Mesh* body) {
  BakeEvaluation ev;
  std::optional<BodyCollider> collider;
  if (body && body->triangleCount() > 0) {
    collider.emplace(*body, kPenetrationCellSize, "bake evaluation: body");
    ev.penetrationMeasured = true;
  }
  ev.pushOut = !model.bodyAnchors.empty();
  std::vector<double> totalPushed;
  ev.poses = heldOut.size();
  const size_t n = model.gameMesh.vertexCount();
  const int K = model.meshComponents();
  const runtime::MlpEvaluator mlp(model);
  const runtime::NoveltyGuardEvaluator guard(model);  // as the run time applies it (on by default)
  ev.hasNormalMaps = !model.normalMaps.empty();
  std::unique_ptr<runtime::NearestCodeSearch> search;
  std::vector<NormalMapImage> decoded;
  if (ev.hasNormalMaps) {
    if (uncompressed.size() != model.normalMaps.mapCount() || !normalPca)
      throw Error("bake evaluation: " + std::to_string(uncompressed.size()) + " uncompressed maps for a database of " +
                  std::to_string(model.normalMaps.mapCount()) + " (and the normal-map PCA is required)");
    search = std::make_unique<runtime::NearestCodeSearch>(model.normalMaps.keys);
    for (uint32_t m = 0; m < model.normalMaps.mapCount(); ++m) decoded.push_back(decodeVqMap(model.normalMaps, m));
  }
  // The PCA basis as a PcaResult-like projector for the truncation error.
  const MatXf& basis = model.meshPca.basis;
  std::vector<double> total, trunc, regr, restSkinned, meanSkinned;
  Points3f meanShape(Eigen::Index(n), 3);
  for (size_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k) meanShape(Eigen::Index(v), k) = model.meshPca.mean[Eigen::Index(3 * v + size_t(k))];
  total.reserve(n * heldOut.size());
  trunc.reserve(n * heldOut.size());
  regr.reserve(n * heldOut.size());
  AngularErrorAccumulator dbAcc, selAcc, totAcc, vqAcc;
  size_t agree = 0;
  std::vector<float> lambda(size_t(mlp.outputSize()));
  for (const DatasetPose* p : heldOut) {
    if (size_t(p->gameMeshWorld.rows()) != n || size_t(p->gameMeshPreSkin.rows()) != n)
      throw Error("bake evaluation: pose " + std::to_string(p->id) + " has a game mesh of another size");
    const std::vector<float> theta = runtime::computeTheta(model.inputJoints, model.rootGravity, p->pose.local);
    mlp.evaluate(theta, lambda);
    guard.apply(guard.measureOne(theta), std::span<float>(lambda.data(), size_t(K)));
    const auto mats = model.skeleton.skinningMatrices(p->pose);
    const Points3f predicted = runtime::referenceSkin(
        runtime::referencePcaReconstruct(model.meshPca, std::span<const float>(lambda.data(), size_t(K))),
        model.gameMesh.skin, mats);
    const VecXf truthPre = Eigen::Map<const VecXf>(p->gameMeshPreSkin.data(), Eigen::Index(3 * n));
    const VecXf projected = basis.transpose() * (truthPre - model.meshPca.mean);
    const Points3f truncated = runtime::referenceSkin(
        runtime::referencePcaReconstruct(model.meshPca, std::span<const float>(projected.data(), size_t(K))),
        model.gameMesh.skin, mats);
    const Points3f restBaseline = runtime::referenceSkin(model.gameMesh.positions, model.gameMesh.skin, mats);
    const Points3f meanBaseline = runtime::referenceSkin(meanShape, model.gameMesh.skin, mats);
    PoseEvaluation pe;
    pe.poseId = p->id;
    for (size_t v = 0; v < n; ++v) {
      const double e = 1000.0 * double((predicted.row(Eigen::Index(v)) - p->gameMeshWorld.row(Eigen::Index(v))).norm());
      const double t = 1000.0 * double((truncated.row(Eigen::Index(v)) - p->gameMeshWorld.row(Eigen::Index(v))).norm());
      total.push_back(e);
      trunc.push_back(t);
      regr.push_back(1000.0 * double((predicted.row(Eigen::Index(v)) - truncated.row(Eigen::Index(v))).norm()));
      pe.meanMm += e / double(n);
      pe.truncationMeanMm += t / double(n);
      pe.maxMm = std::max(pe.maxMm, e);
      const double r =
          1000.0 * double((restBaseline.row(Eigen::Index(v)) - p->gameMeshWorld.row(Eigen::Index(v))).norm());
      const double m =
          1000.0 * double((meanBaseline.row(Eigen::Index(v)) - p->gameMeshWorld.row(Eigen::Index(v))).norm());
      restSkinned.push_back(r);
      meanSkinned.push_back(m);
      pe.restSkinnedMeanMm += r / double(n);
      pe.meanSkinnedMeanMm += m / double(n);
    }
    std::optional<Points3f> pushed;
    if (ev.pushOut) {
      pushed = predicted;
      runtime::referencePushOut(*pushed, model.bodyAnchors, mats);
      for (size_t v = 0; v < n; ++v)
        totalPushed.push_back(1000.0 *
                              double((pushed->row(Eigen::Index(v)) - p->gameMeshWorld.row(Eigen::Index(v))).norm()));
    }
    if (collider) {
      collider->pose(mats);
      pe.truthPenetration = measurePenetration(*collider, p->gameMeshWorld);
      pe.modelPenetration = measurePenetration(*collider, predicted);
      ev.truthPenetration.add(pe.truthPenetration);
      ev.modelPenetration.add(pe.modelPenetration);
      if (pushed) {
        pe.pushedPenetration = measurePenetration(*collider, *pushed);
        ev.pushedPenetration.add(pe.pushedPenetration);
      }
    }
    if (ev.hasNormalMaps) {
      const VecXf trueCode = normalMapCode(*normalPca, p->normalMap);
      const std::span<const float> predCode(lambda.data() + K, size_t(model.normalCodeDims()));
      pe.selectedMap = search->find(predCode).index;
      pe.idealMap = search->find(std::span<const float>(trueCode.data(), size_t(trueCode.size()))).index;
      agree += pe.selectedMap == pe.idealMap;
      dbAcc.addMaps(p->normalMap, *uncompressed[pe.idealMap]);
      selAcc.addMaps(p->normalMap, *uncompressed[pe.selectedMap]);
      AngularErrorAccumulator mine;
      mine.addMaps(p->normalMap, decoded[pe.selectedMap]);
      pe.normalTotalDegrees = mine.stats().meanDegrees;
      totAcc.merge(mine);
      vqAcc.addMaps(*uncompressed[pe.selectedMap], decoded[pe.selectedMap]);
    }
    ev.perPose.push_back(pe);
  }
  ev.totalMm = distanceStats(std::move(total));
  ev.truncationMm = distanceStats(std::move(trunc));
  ev.regressionMm = distanceStats(std::move(regr));
  ev.restSkinnedMm = distanceStats(std::move(restSkinned));
  ev.meanSkinnedMm = distanceStats(std::move(meanSkinned));
  ev.totalPushedMm = distanceStats(std::move(totalPushed));
  ev.normalDatabase = dbAcc.stats();
  ev.normalSelection = selAcc.stats();
  ev.normalTotal = totAcc.stats();
  ev.normalVqAdded = vqAcc.stats();
  ev.selectionAgreement = heldOut.empty() ? 0.0 : double(agree) / double(heldOut.size());
  return ev;
}

}  // namespace swish::bake
