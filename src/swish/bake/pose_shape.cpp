#include "swish/bake/pose_shape.hpp"

#include <algorithm>
#include <cmath>

#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"

namespace swish::bake {

namespace {

// A number at obj[key] (absent: `fallback`), finite and in [lo, hi].
double number(const nlohmann::json& obj, const std::string& where, const char* key, double lo, double hi,
              double fallback) {
  if (!obj.is_object() || !obj.contains(key)) return fallback;
  const nlohmann::json& v = obj.at(key);
  if (!v.is_number()) throw Error(where + "." + key + ": must be a number");
  const double d = v.get<double>();
  if (!(d >= lo && d <= hi))
    throw Error(where + "." + key + ": " + std::to_string(d) + " is outside " + std::to_string(lo) + ".." +
                std::to_string(hi));
  return d;
}

const nlohmann::json& section(const nlohmann::json& j, const char* key, const std::string& what) {
  static const nlohmann::json empty = nlohmann::json::object();
  if (!j.is_object()) throw Error(what + ": the dataset settings must be a JSON object");
  if (!j.contains(key)) return empty;
  if (!j.at(key).is_object()) throw Error(what + "." + key + ": must be a JSON object");
  return j.at(key);
}

std::optional<LimbClearance> makeClearance(const Character& c, const LimbClearanceSettings& s) {
  if (s.clearance > 0.f) return std::optional<LimbClearance>(std::in_place, c, s);
  return std::nullopt;
}

bool samePose(const Pose& a, const Pose& b) {
  return a.local.size() == b.local.size() &&
         std::equal(a.local.begin(), a.local.end(), b.local.begin(),
                    [](const Quatf& x, const Quatf& y) { return x.coeffs() == y.coeffs(); });
}

}  // namespace

Pose canonicalPose(const Skeleton& skeleton, Pose p) {
  p.local[0] = skeleton.joints[0].rest.rotation;
  p.rootTranslation = skeleton.joints[0].rest.translation;
  return p;
}

PoseShapeSettings poseShapeSettingsFromJson(const nlohmann::json& j, const std::string& what) {
  PoseShapeSettings s;
  const nlohmann::json& sim = section(j, "simulation", what);
  std::string w = what + ".simulation";
  ClothSimSettings& cs = s.simulation;
  if (sim.contains("preset")) {
    if (!sim.at("preset").is_string()) throw Error(w + ".preset: must be a string");
    try {
      cs.material = clothMaterialPreset(sim.at("preset").get<std::string>());
    } catch (const Error& e) {
      throw Error(w + ".preset: " + e.what());
    }
  }
  s.simulationVertices = size_t(number(sim, w, "vertices", 0, 2e6, double(s.simulationVertices)));
  cs.thickness = float(number(sim, w, "thickness", 0, 0.05, cs.thickness));
  cs.transitionSeconds = float(number(sim, w, "transition_seconds", 0.05, 10, cs.transitionSeconds));
  cs.settleSeconds = float(number(sim, w, "settle_seconds", 0, 10, cs.settleSeconds));
  cs.frameRate = float(number(sim, w, "frame_rate", 5, 1000, cs.frameRate));
  cs.substeps = int(number(sim, w, "substeps", 1, 1000, cs.substeps));
  cs.iterations = int(number(sim, w, "iterations", 1, 1000, cs.iterations));
  cs.gravity = Vec3f(0.f, -float(number(sim, w, "gravity", 0, 100, -cs.gravity.y())), 0.f);
  s.limbClearance.clearance = float(number(sim, w, "limb_clearance", 0, 0.1, s.limbClearance.clearance));
  try {
    cs.validate();
  } catch (const Error& e) {
    throw Error(w + ": " + e.what());
  }

  const nlohmann::json& tr = section(j, "transfer", what);
  w = what + ".transfer";
  LaplacianSmoothingSettings& ls = s.transfer.smoothing;
  ls.strength = float(number(tr, w, "smoothing_strength", 0, 1, ls.strength));
  ls.iterations = int(number(tr, w, "smoothing_iterations", 0, 1000, ls.iterations));
  if (tr.contains("smoothing_weights")) {
    const nlohmann::json& v = tr.at("smoothing_weights");
    const std::string name = v.is_string() ? v.get<std::string>() : "";
    if (name == "cotangent") ls.weights = LaplacianWeights::Cotangent;
    else if (name == "uniform") ls.weights = LaplacianWeights::Uniform;
    else throw Error(w + ".smoothing_weights: must be \"cotangent\" or \"uniform\"");
  }

  const nlohmann::json& nm = section(j, "normal_maps", what);
  w = what + ".normal_maps";
  NormalMapBakeSettings& nb = s.transfer.normalMap;
  nb.width = nb.height = uint32_t(number(nm, w, "size", 4, 4096, nb.width));
  nb.maxDistance = float(number(nm, w, "max_distance", 1e-4, 1, nb.maxDistance));
  nb.dilationRings = int(number(nm, w, "dilation_rings", 0, 256, nb.dilationRings));
  return s;
}

PoseShapeSimulator::PoseShapeSimulator(const Character& character, const PoseShapeSettings& settings)
    : character_(&character),
      settings_(settings),
      clearance_(makeClearance(character, settings.limbClearance)),
      solver_(character, buildSimulationMesh(character, settings.simulationVertices), settings.simulation),
      transfer_(character, solver_.mesh().restPositions, solver_.mesh().triangles, settings.transfer) {}

Pose PoseShapeSimulator::poseToSimulate(const Pose& recorded, std::vector<LimbCorrection>* corrections) const {
  Pose p = recorded;
  if (clearance_) {
    std::vector<LimbCorrection> c = clearance_->apply(p);
    if (corrections) corrections->insert(corrections->end(), c.begin(), c.end());
  }
  return p;
}

TransferredPose PoseShapeSimulator::gameMeshShape(const Pose& simulated, const Pose& recorded,
                                                  const Points3f& simulationPositions) const {
  TransferredPose tp = transfer_.transfer(simulated, simulationPositions);
  // A pose whose limbs were turned out of the trunk: the shape before skinning comes from the
  // corrected simulation; the world shape is that shape skinned as the run time will skin it with
  // the recorded pose. The model so learns its real inputs, and the sleeves of a hanging arm pass
  // into the torso with the arm, as the body does.
  if (!samePose(simulated, recorded))
    tp.gameMeshWorld = skinPositions(tp.gameMeshPreSkin, character_->garment.skin,
                                     character_->skeleton.skinningMatrices(recorded));
  return tp;
}

PoseShape PoseShapeSimulator::simulate(const Pose& recorded) const {
  PoseShape out;
  out.simulatedPose = poseToSimulate(recorded, &out.corrections);
  PoseSimulation sim = solver_.simulate(out.simulatedPose);
  out.residuals = sim.residuals;
  if (!sim.ok) {
    out.failure = "simulation: " + sim.failure;
    return out;
  }
  try {
    TransferredPose tp = gameMeshShape(out.simulatedPose, recorded, sim.positions);
    out.gameMeshWorld = std::move(tp.gameMeshWorld);
    out.gameMeshPreSkin = std::move(tp.gameMeshPreSkin);
    out.normalMap = std::move(tp.normalMap);
    out.ok = true;
  } catch (const Error& e) {
    out.failure = std::string("transfer: ") + e.what();
  }
  return out;
}

}  // namespace swish::bake
