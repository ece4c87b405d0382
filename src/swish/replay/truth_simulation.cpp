#include "swish/replay/truth_simulation.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>

#include <nlohmann/json.hpp>

#include "swish/bake/pipeline/bake_config.hpp"
#include "swish/bake/pipeline/baked_character.hpp"
#include "swish/bake/pipeline/part1_dataset.hpp"
#include "swish/bake/report/bake_evaluation.hpp"
#include "swish/bake/report/penetration.hpp"
#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"
#include "swish/model/model_file.hpp"

namespace swish::replay {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Rest data written by code and read back from a float32 file: equal, but allow float noise.
constexpr float kSameTolerance = 1e-5f;

double threadCpuSeconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

std::string fmtNum(const char* f, double v) {
  char s[64];
  std::snprintf(s, sizeof s, f, v);
  return s;
}

template <class A, class B>
bool near(const A& a, const B& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         (a.size() == 0 || (a - b).cwiseAbs().maxCoeff() <= kSameTolerance);
}

}  // namespace

std::string characterDifference(const Model& model, const Character& ch) {
  const Skeleton& a = model.skeleton;
  const Skeleton& b = ch.skeleton;
  if (a.size() != b.size())
    return "the skeleton has " + std::to_string(b.size()) + " joints, the model's " + std::to_string(a.size());
  for (size_t j = 0; j < a.size(); ++j) {
    const Joint& x = a.joints[j];
    const Joint& y = b.joints[j];
    if (x.name != y.name || x.parent != y.parent)
      return "joint " + std::to_string(j) + " is '" + y.name + "', the model's '" + x.name + "'";
    const bool sameRotation =
        (x.rest.rotation.coeffs() - y.rest.rotation.coeffs()).cwiseAbs().maxCoeff() <= kSameTolerance ||
        (x.rest.rotation.coeffs() + y.rest.rotation.coeffs()).cwiseAbs().maxCoeff() <= kSameTolerance;
    if (!near(x.rest.translation, y.rest.translation) || !sameRotation)
      return "joint '" + x.name + "' has another rest transform";
  }
  const Mesh& m = model.gameMesh;
  const Mesh& g = ch.garment;
  if (m.vertexCount() != g.vertexCount() || m.triangleCount() != g.triangleCount())
    return "the game mesh has " + std::to_string(g.vertexCount()) + " vertices and " +
           std::to_string(g.triangleCount()) + " triangles, the model's " + std::to_string(m.vertexCount()) + " and " +
           std::to_string(m.triangleCount());
  if (m.triangles != g.triangles) return "the game mesh's triangles differ";
  if (!near(m.positions, g.positions)) return "the game mesh's rest positions differ";
  if (!near(m.uvs, g.uvs)) return "the game mesh's UVs differ";
  if (m.skin.influences != g.skin.influences || m.skin.joints != g.skin.joints ||
      m.skin.weights.size() != g.skin.weights.size())
    return "the game mesh's skin weights differ";
  for (size_t i = 0; i < m.skin.weights.size(); ++i)
    if (std::abs(m.skin.weights[i] - g.skin.weights[i]) > kSameTolerance) return "the game mesh's skin weights differ";
  return {};
}

ModelTruth::ModelTruth(const ModelEntry& entry, const TruthOptions& options) : model_(&entry.model) {
  try {
    prepare(entry, options);
  } catch (const std::exception& e) {  // a metadata shape nobody foresaw: still no truth rather than no replay
    note_ = std::string("the bake's source simulation cannot be rebuilt: ") + e.what();
    simulator_.reset();
    character_.reset();
  }
}

std::unique_ptr<Character> rebuildBakeCharacter(const ModelEntry& entry, std::string& note, std::string* how) {
  if (entry.procedural) {
    note = "the procedural stand-in model was not baked from a simulation: no bake character to rebuild";
    return nullptr;
  }
  bake::BakedCharacter baked = bake::findBakedCharacter(entry.model.metadata, entry.file);
  if (baked.kind == bake::BakedCharacter::Kind::Unknown) {
    note =
        "the model's metadata has no bake settings (\"dataset_settings\", written by swish bake): the character and "
        "cloth settings of its source simulation are unknown";
    return nullptr;
  }
  if (!baked.problem.empty()) {
    note = baked.problem;
    return nullptr;
  }
  bake::DatasetBuildSettings& s = baked.settings;
  const std::string built =
      baked.kind == bake::BakedCharacter::Kind::File ? "imported from " + baked.description : baked.description;
  if (s.inputJoints.empty())
    for (uint32_t j : entry.model.inputJoints) s.inputJoints.push_back(entry.model.skeleton.joints[j].name);
  std::unique_ptr<Character> character;
  try {
    character = std::make_unique<Character>(bake::loadDatasetCharacter(s));
  } catch (const Error& e) {
    note = std::string("the bake's character cannot be rebuilt: ") + e.what();
    return nullptr;
  }
  if (const std::string diff = characterDifference(entry.model, *character); !diff.empty()) {
    note = "the rebuilt character '" + character->name + "' (" + built + ") is not the model's: " + diff;
    return nullptr;
  }
  if (how) *how = built;
  return character;
}

void ModelTruth::prepare(const ModelEntry& entry, const TruthOptions& options) {
  const json meta = json::parse(entry.model.metadata, nullptr, false);
  const json ds = meta.is_object() && meta.contains("dataset_settings") && meta["dataset_settings"].is_object()
                      ? meta["dataset_settings"]
                      : json::object();
  if (ds.contains("simulation") && ds["simulation"].is_object() && ds["simulation"].value("source", "") == "external") {
    note_ = "the model was baked from an external cloth tool's shapes (" +
            ds["simulation"].value("path", std::string()) +
            "): swish's own solver is not its source simulation, so there is no truth to run";
    return;
  }
  std::string how;
  character_ = rebuildBakeCharacter(entry, note_, &how);  // says why not when the metadata names no bake
  if (!character_) return;
  bake::PoseShapeSettings ps;
  try {
    ps = bake::poseShapeSettingsFromJson(ds, "model metadata dataset_settings");
  } catch (const Error& e) {
    note_ = e.what();
    return;
  }
  std::string overridden;
  if (options.simulationVertices) {
    ps.simulationVertices = *options.simulationVertices;
    overridden += " simulation vertices";
  }
  if (options.substeps) {
    ps.simulation.substeps = *options.substeps;
    overridden += " substeps";
  }
  if (options.coverBodyMm) {  // the cover as bakes run it today: in the simulated pose and the recorded one
    ps.transfer.cover.margin = 0.001f * *options.coverBodyMm;
    overridden += " cover_body_mm " + fmtNum("%g", *options.coverBodyMm);
    if (!ps.transfer.cover.recordedPose && ps.transfer.cover.enabled()) overridden += " (in the recorded pose too)";
    ps.transfer.cover.recordedPose = true;
  }
  if (options.limbClearanceMm) {
    ps.limbClearance.clearance = 0.001f * *options.limbClearanceMm;
    overridden += " limb clearance " + fmtNum("%g", *options.limbClearanceMm) + " mm";
  }
  try {
    simulator_ = std::make_unique<bake::PoseShapeSimulator>(*character_, ps);
  } catch (const Error& e) {
    note_ = std::string("the source simulation cannot be set up: ") + e.what();
    return;
  }
  if (character_->body.triangleCount() > 0)
    body_ = std::make_unique<const bake::BodyCollider>(character_->body, bake::kPenetrationCellSize, "truth body");
  std::string mapNote;
  normalMaps_ = options.normalMaps && !entry.model.normalMaps.empty();
  if (normalMaps_ && (ps.transfer.normalMap.width != entry.model.normalMaps.width ||
                      ps.transfer.normalMap.height != entry.model.normalMaps.height)) {
    normalMaps_ = false;
    mapNote = "; normal maps not measured: the bake's are " + std::to_string(ps.transfer.normalMap.width) +
              " px, the model's " + std::to_string(entry.model.normalMaps.width);
  }
  const bake::ClothSimSettings& cs = ps.simulation;
  std::string retriedBy;  // the retries' carries, when not the skinning one alone
  for (size_t k = 0; !cs.skinningRetriesOnly() && k < cs.retryCarries.size(); ++k)
    retriedBy += std::string(k == 0 ? " (retries: " : ", then ") + bake::clothCarryName(cs.retryCarries[k]) +
                 (k + 1 == cs.retryCarries.size() ? ")" : "");
  note_ = "the bake's source simulation of character '" + character_->name + "' (" + how +
          "): " + std::to_string(simulator_->solver().mesh().vertexCount()) + " simulation vertices, preset '" +
          cs.material.name + "', " + std::to_string(cs.substeps) + " substeps x " + std::to_string(cs.iterations) +
          " iterations at " + fmtNum("%g", cs.frameRate) + " fps, " + fmtNum("%g", cs.transitionSeconds) +
          " s transition + " + fmtNum("%g", cs.settleSeconds) + " s settle, carried by " +
          bake::clothCarryName(cs.carry) + retriedBy + ", limb clearance " +
          fmtNum("%g", 1000.0 * ps.limbClearance.clearance) + " mm (trunk within " +
          fmtNum("%g", 1000.0 * ps.limbClearance.garmentReach) + " mm of the garment; 0: all), neck range " +
          fmtNum("%g", ps.limbClearance.neckRangeDegrees) + " deg (0: as recorded), smoothing " +
          std::to_string(ps.transfer.smoothing.iterations) + " x " + fmtNum("%g", ps.transfer.smoothing.strength) +
          (overridden.empty() ? std::string() : "; overridden for this run (not the bake's):" + overridden) + mapNote;
}

ModelTruth::~ModelTruth() = default;

bake::PoseShape ModelTruth::simulate(const Pose& pose) const {
  bake::PoseShape shape = simulator_->simulate(bake::canonicalPose(character_->skeleton, pose));
  if (!shape.ok) return shape;
  // Skinned as the run time skins the prediction: the model's skeleton and weights, the whole pose.
  shape.gameMeshWorld =
      skinPositions(shape.gameMeshPreSkin, model_->gameMesh.skin, model_->skeleton.skinningMatrices(pose));
  if (!normalMaps_) shape.normalMap = bake::NormalMapImage{};
  return shape;
}

TruthMeasurement ModelTruth::measure(const Pose& pose, const Points3f& positions,
                                     const runtime::BlendedNormalMap* normalMap, const Points3f* without) const {
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = threadCpuSeconds();
  TruthMeasurement m;
  const bake::PoseShape shape = simulate(pose);
  m.summary.limbCorrections = uint32_t(shape.corrections.size());
  if (!shape.ok) {
    m.summary.failure = shape.failure;
  } else if (positions.rows() != shape.gameMeshPreSkin.rows()) {
    m.summary.failure = "the run time output has " + std::to_string(positions.rows()) + " vertices, the truth " +
                        std::to_string(shape.gameMeshPreSkin.rows());
  } else {
    const Points3f& truth = shape.gameMeshWorld;
    auto distances = [&](const Points3f& p) {
      std::vector<double> mm(size_t(truth.rows()));
      for (Eigen::Index v = 0; v < truth.rows(); ++v) {
        const double d = (p.row(v).cast<double>() - truth.row(v).cast<double>()).norm() * 1000.0;
        mm[size_t(v)] = std::isfinite(d) ? d : 1e30;  // a non-finite output must not hide
      }
      return mm;
    };
    m.vertexMm = distances(positions);
    m.truthPositions = truth;
    const bake::DistanceStats st = bake::distanceStats(m.vertexMm);
    m.summary.ok = true;
    m.summary.meanMm = st.mean, m.summary.p95Mm = st.p95, m.summary.maxMm = st.max;
    if (without && without->rows() == truth.rows()) {
      m.vertexMmWithout = distances(*without);
      const bake::DistanceStats w = bake::distanceStats(m.vertexMmWithout);
      m.summary.comparedWithout = true;
      m.summary.meanMmWithout = w.mean, m.summary.p95MmWithout = w.p95, m.summary.maxMmWithout = w.max;
      // Where the truth itself lies inside the body (the bake's body, posed as the run time posed it).
      if (body_) {
        bake::BodyCollider body = *body_;
        body.pose(model_->skeleton.skinningMatrices(pose));
        m.truthInside.resize(size_t(truth.rows()));
        for (Eigen::Index v = 0; v < truth.rows(); ++v)
          m.truthInside[size_t(v)] = bake::penetrationDepth(body, truth.row(v).transpose()) > 0.f ? 1 : 0;
      }
    }
    if (normalMaps_ && normalMap && normalMap->width == shape.normalMap.width &&
        normalMap->height == shape.normalMap.height) {
      const bake::NormalMapImage shown{normalMap->width, normalMap->height, runtime::xyAsFloat(*normalMap)};
      m.angles = std::make_unique<bake::AngularErrorAccumulator>();
      m.angles->addMaps(shape.normalMap, shown);
      const bake::AngularErrorStats a = m.angles->stats();
      m.summary.normalMap = true;
      m.summary.meanDeg = a.meanDegrees, m.summary.p95Deg = a.p95Degrees, m.summary.maxDeg = a.maxDegrees;
    }
  }
  m.summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  m.summary.cpuSeconds = threadCpuSeconds() - cpu0;
  return m;
}

void TruthPool::add(const TruthMeasurement& m) {
  seconds_ += m.summary.seconds;
  cpuSeconds_ += m.summary.cpuSeconds;
  if (!m.summary.ok) {
    ++failed_;
    return;
  }
  ++samples_;
  vertexMm_.insert(vertexMm_.end(), m.vertexMm.begin(), m.vertexMm.end());
  if (m.vertexMmWithout.empty()) allWithout_ = false;
  vertexMmWithout_.insert(vertexMmWithout_.end(), m.vertexMmWithout.begin(), m.vertexMmWithout.end());
  if (m.truthInside.size() != m.vertexMm.size()) allSplit_ = false;
  truthInside_.insert(truthInside_.end(), m.truthInside.begin(), m.truthInside.end());
  if (m.angles) {
    if (!angles_) angles_ = std::make_unique<bake::AngularErrorAccumulator>();
    angles_->merge(*m.angles);
  }
}

TruthSummary TruthPool::summary() const {
  TruthSummary s;
  s.samples = samples_, s.failed = failed_, s.seconds = seconds_, s.cpuSeconds = cpuSeconds_;
  if (!vertexMm_.empty()) {
    const bake::DistanceStats d = bake::distanceStats(vertexMm_);
    s.meanMm = d.mean, s.p95Mm = d.p95, s.maxMm = d.max;
    if (allWithout_ && vertexMmWithout_.size() == vertexMm_.size()) {
      const bake::DistanceStats w = bake::distanceStats(vertexMmWithout_);
      s.comparedWithout = true;
      s.meanMmWithout = w.mean, s.p95MmWithout = w.p95, s.maxMmWithout = w.max;
      if (allSplit_ && truthInside_.size() == vertexMm_.size()) {
        double with[2] = {0, 0}, without[2] = {0, 0};
        size_t count[2] = {0, 0};
        for (size_t e = 0; e < vertexMm_.size(); ++e) {
          const int side = truthInside_[e] ? 1 : 0;
          with[side] += vertexMm_[e], without[side] += vertexMmWithout_[e], ++count[side];
        }
        auto mean = [&](const double* sum, int side) { return count[side] ? sum[side] / double(count[side]) : 0.0; };
        s.splitByTruth = true;
        s.truthInsideShare = double(count[1]) / double(vertexMm_.size());
        s.meanMmTruthOutside = mean(with, 0), s.meanMmWithoutTruthOutside = mean(without, 0);
        s.meanMmTruthInside = mean(with, 1), s.meanMmWithoutTruthInside = mean(without, 1);
      }
    }
  }
  if (angles_) {
    const bake::AngularErrorStats a = angles_->stats();
    s.normalMaps = true;
    s.meanDeg = a.meanDegrees, s.p95Deg = a.p95Degrees, s.maxDeg = a.maxDegrees;
  }
  return s;
}

ModelEntry loadModelEntry(const std::string& path) {
  ModelEntry entry;
  entry.key = path;
  entry.file = std::filesystem::absolute(path);
  entry.label = path;
  entry.model = loadModel(entry.file);
  return entry;
}

ModelWithBakeBody loadModelWithBakeBody(const std::string& path, const std::string& purpose) {
  ModelWithBakeBody m;
  m.entry = loadModelEntry(path);
  std::string note;
  m.character = rebuildBakeCharacter(m.entry, note, &m.how);
  if (!m.character) throw Error(path + ": no body " + purpose + ": " + note);
  if (m.character->body.triangleCount() == 0)
    throw Error(path + ": the bake's character '" + m.character->name + "' has no body mesh");
  return m;
}

}  // namespace swish::replay
