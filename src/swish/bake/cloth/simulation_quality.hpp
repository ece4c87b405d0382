#pragma once
// How far to trust the source simulation: the figures every part-1 report carries (and `swish bake
// --check-simulation` measures on any garment without building a dataset).
//
//   - convergence: on a seeded sample of poses, the shape at the bake's settings against the shape at
//     twice the substeps and half the equilibrium tolerance (mean / p95 per-vertex distance, mm). A
//     converged solver answers with a property of the pose, not of its settings.
//   - noise: on the same sample, every non-root joint turned by +-a degrees about one random axis per
//     pose; the second difference x(+a) - 2 x(0) + x(-a) cancels the smooth (linear) response and
//     leaves the simulation's own noise, sqrt(6) times one simulation's if that noise is independent
//     per simulation, so the figure is |second difference| / sqrt(6) per vertex (mean / p95, mm). The
//     measure of docs/baking.md ("the truth's noise floor"), here on the simulation mesh.
//   - path sensitivity: on the same sample, the shape with the transition one frame longer (same
//     substeps) against the shape at the solver's settings (mean / p95, mm). The path picks which
//     equilibrium the cloth settles in; this is how much a path that differs by nothing the pose
//     decides moves it, so the part of the convergence figure that more substeps cannot remove.
//   - edge strain: the mean signed strain of the garment's edges at the solver's settings and at the
//     reference's. Where the two differ the stretch is the solver's (its sweeps and substeps), not
//     the material's: XPBD with few sweeps on a light, long garment (docs/baking.md, "the stiff regime").
//   - failures per reason with their share, the poses that needed a retry, the equilibrium residuals
//     and the seconds each pose's solve took on its core.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/cloth/cloth_solver.hpp"

namespace swish::bake {

struct SimulationQualitySettings {
  size_t poses = 6;  // sampled poses for convergence and noise; 0: not measured
  uint64_t seed = 1;
  float noiseTurnDegrees = 2.f;
  int threads = 0;  // 0: TBB's default
};

struct SimulationQuality {
  size_t convergencePoses = 0;  // sampled poses whose reference solve succeeded
  double convergenceMeanMm = 0, convergenceP95Mm = 0, convergenceMaxMm = 0;
  size_t noisePoses = 0;  // sampled poses whose two turned solves succeeded
  double noiseMeanMm = 0, noiseP95Mm = 0;
  float noiseTurnDegrees = 0.f;
  size_t pathPoses = 0;  // sampled poses whose longer-path solve succeeded
  double pathMeanMm = 0, pathP95Mm = 0;
  // Mean signed edge strain (%) of the sampled shapes at the solver's settings and of the reference's.
  double edgeStrainPercent = 0, referenceEdgeStrainPercent = 0;
  std::vector<std::string> referenceFailures;  // reference or turned solves that failed: "pose 12 (+2 deg): why"
  double seconds = 0;                          // wall time of the measurement
  nlohmann::json toJson() const;
};

// The path sensitivity and edge strain figures of a measurement (SimulationQuality::toJson's form) as
// one line for a log; says so when the measurement predates them.
std::string simulationQualityDetail(const nlohmann::json& quality);

// One pose's simulation outcome as the report needs it.
struct SimulatedPoseSummary {
  uint32_t id = 0;
  bool ok = false;
  std::string failure;  // when !ok
  int attempts = 1;
  std::string firstFailure;  // when attempts > 1
  SimResiduals residuals;
};

// "explosion", "penetration", "non-finite", "bad input", "transfer" or "other": the reason a
// failure message names (the last attempt's, for a retried pose).
std::string failureCategory(const std::string& failure);

// Failures per reason (count and share of all poses), the retried poses, seconds per pose per core
// (the mean solve time: each pose is solved on one core), equilibrium residuals and the final
// projection's deepest move, as JSON for part1.json. `extraFailures`: poses lost after the
// simulation (transfer), id and reason.
nlohmann::json simulationRunJson(const std::vector<SimulatedPoseSummary>& poses, const ClothSimSettings& settings,
                                 const std::vector<std::pair<uint32_t, std::string>>& extraFailures = {});

// The seeded sample of `count` ids among `candidates` (ascending).
std::vector<uint32_t> sampleQualityPoses(const std::vector<uint32_t>& candidates, size_t count, uint64_t seed);

// Convergence and noise on the poses `ids` of `poses`, whose shapes at the solver's settings are
// `shapes[k]` (simulation-mesh positions, for ids[k]). `character` is the solver's. `log` gets one
// line per finished solve.
SimulationQuality measureSimulationQuality(const Character& character, const ClothSolver& solver,
                                           const std::vector<Pose>& poses, const std::vector<uint32_t>& ids,
                                           const std::vector<Points3f>& shapes,
                                           const SimulationQualitySettings& settings,
                                           const std::function<void(const std::string&)>& log = {});

// The fingerprint of a measurement (solver, sampled poses, settings): a cached result is reused only
// when it matches.
uint64_t simulationQualityFingerprint(const ClothSolver& solver, const std::vector<Pose>& poses,
                                      const std::vector<uint32_t>& ids, const SimulationQualitySettings& settings);

}  // namespace swish::bake
