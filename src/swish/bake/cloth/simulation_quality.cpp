#include "swish/bake/cloth/simulation_quality.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "swish/core/hash.hpp"
#include "swish/core/rng.hpp"

namespace swish::bake {
namespace {

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const size_t k = std::min(v.size() - 1, size_t(q * double(v.size())));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(k), v.end());
  return v[k];
}

// The mean signed strain of the garment's edges (stretch constraints) at `x`, in percent.
double meanEdgeStrainPercent(const ClothConstraints& cc, const Points3f& x) {
  double sum = 0.0;
  for (const DistanceConstraint& c : cc.stretch) sum += double(((x.row(c.i) - x.row(c.j)).norm() - c.rest) / c.rest);
  return cc.stretch.empty() ? 0.0 : 100.0 * sum / double(cc.stretch.size());
}

double mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / double(v.size());
}

// Every non-root joint of `p` turned by `radians` about `axis` (in each joint's own frame).
Pose turned(const Pose& p, const Vec3f& axis, float radians) {
  Pose out = p;
  const Quatf q(Eigen::AngleAxisf(radians, axis));
  for (size_t j = 1; j < out.local.size(); ++j) out.local[j] = (out.local[j] * q).normalized();
  return out;
}

}  // namespace

nlohmann::json SimulationQuality::toJson() const {
  return {{"convergence_reference", "twice the substeps, half the equilibrium tolerance"},
          {"convergence_poses", convergencePoses},
          {"convergence_mean_mm", convergenceMeanMm},
          {"convergence_p95_mm", convergenceP95Mm},
          {"convergence_max_mm", convergenceMaxMm},
          {"noise_measure", "second differences over turns of every non-root joint, |x(+a) - 2x(0) + x(-a)| / sqrt(6)"},
          {"noise_turn_degrees", noiseTurnDegrees},
          {"noise_poses", noisePoses},
          {"noise_mean_mm", noiseMeanMm},
          {"noise_p95_mm", noiseP95Mm},
          {"path_sensitivity_reference", "the transition one frame longer, the same substeps"},
          {"path_sensitivity_poses", pathPoses},
          {"path_sensitivity_mean_mm", pathMeanMm},
          {"path_sensitivity_p95_mm", pathP95Mm},
          {"edge_strain_mean_percent", edgeStrainPercent},
          {"reference_edge_strain_mean_percent", referenceEdgeStrainPercent},
          {"reference_failures", referenceFailures},
          {"seconds", seconds}};
}

std::string simulationQualityDetail(const nlohmann::json& quality) {
  if (!quality.contains("path_sensitivity_mean_mm")) return "path sensitivity and edge strain: not measured";
  char line[320];
  std::snprintf(line, sizeof line,
                "path sensitivity (the transition one frame longer; %zu poses) %.2f mm mean, %.2f mm p95; mean "
                "edge strain %.2f %% (%.2f %% at 2x substeps)",
                size_t(quality.value("path_sensitivity_poses", 0)), quality.value("path_sensitivity_mean_mm", 0.0),
                quality.value("path_sensitivity_p95_mm", 0.0), quality.value("edge_strain_mean_percent", 0.0),
                quality.value("reference_edge_strain_mean_percent", 0.0));
  return line;
}

std::string failureCategory(const std::string& failure) {
  // A retried pose's message ends with "; first attempt: ..."; the category is the last attempt's.
  const std::string last = failure.substr(0, failure.find("; first attempt:"));
  if (last.rfind("transfer", 0) == 0) return "transfer";
  if (last.find("exploded") != std::string::npos) return "explosion";
  if (last.find("inside the body") != std::string::npos) return "penetration";
  if (last.find("non-finite positions") != std::string::npos) return "non-finite";
  if (last.find("joint rotations") != std::string::npos || last.find("rotation") != std::string::npos)
    return "bad input";
  return "other";
}

nlohmann::json simulationRunJson(const std::vector<SimulatedPoseSummary>& poses, const ClothSimSettings& settings,
                                 const std::vector<std::pair<uint32_t, std::string>>& extraFailures) {
  std::map<std::string, size_t> byReason;
  nlohmann::json retried = nlohmann::json::array();
  std::vector<double> seconds, residual, staticSteps;
  // The residual's tolerance: the static solve's where it ends the pose, else the equilibrium phase's.
  const float tolerance = settings.staticSolve ? settings.staticTolerance : settings.equilibriumTolerance;
  double projected = 0.0;
  size_t notAtEquilibrium = 0, ok = 0;
  for (const SimulatedPoseSummary& p : poses) {
    seconds.push_back(p.residuals.seconds);
    if (!p.ok) ++byReason[failureCategory(p.failure)];
    if (p.attempts > 1)
      retried.push_back({{"pose", p.id}, {"attempts", p.attempts}, {"kept", p.ok}, {"first_failure", p.firstFailure}});
    if (!p.ok) continue;
    ++ok;
    projected = std::max(projected, double(p.residuals.projectedDepth));
    if (p.residuals.equilibriumResidual >= 0.f) {
      residual.push_back(p.residuals.equilibriumResidual);
      notAtEquilibrium += p.residuals.equilibriumResidual > tolerance;
    }
    // (Newton steps are not stored with a pose: the poses simulated in this run.)
    if (settings.staticSolve && p.residuals.staticIterations > 0) staticSteps.push_back(p.residuals.staticIterations);
  }
  for (const auto& f : extraFailures) ++byReason[failureCategory(f.second)];
  const double n = std::max<double>(1.0, double(poses.size()));
  nlohmann::json reasons = nlohmann::json::object();
  size_t failed = 0;
  for (const auto& [why, count] : byReason) {
    reasons[why] = {{"count", count}, {"share", double(count) / n}};
    failed += count;
  }
  nlohmann::json out = {
      {"poses", poses.size()},
      {"failed", failed},
      {"failed_share", double(failed) / n},
      {"failures_by_reason", reasons},
      {"retried_poses", retried.size()},
      {"retried", retried},
      {"seconds_per_pose_per_core", mean(seconds)},
      {"equilibrium_tolerance", tolerance},
      {"equilibrium_residual_mean", mean(residual)},
      {"equilibrium_residual_p95", percentile(residual, 0.95)},
      {"equilibrium_residual_max", residual.empty() ? 0.0 : *std::max_element(residual.begin(), residual.end())},
      {"poses_not_at_equilibrium", notAtEquilibrium},
      {"final_projection_max_mm", 1000.0 * projected},
      {"kept", ok}};
  if (settings.staticSolve) {
    out["static_solve"] = true;
    out["static_iterations_mean"] = mean(staticSteps);
    out["static_iterations_max"] =
        staticSteps.empty() ? 0.0 : *std::max_element(staticSteps.begin(), staticSteps.end());
  }
  return out;
}

std::vector<uint32_t> sampleQualityPoses(const std::vector<uint32_t>& candidates, size_t count, uint64_t seed) {
  std::vector<uint32_t> pool = candidates;
  Rng rng(seed ^ 0x51A7'C0DEull);
  count = std::min(count, pool.size());
  for (size_t i = 0; i < count; ++i) std::swap(pool[i], pool[i + size_t(rng.below(pool.size() - i))]);
  pool.resize(count);
  std::sort(pool.begin(), pool.end());
  return pool;
}

uint64_t simulationQualityFingerprint(const ClothSolver& solver, const std::vector<Pose>& poses,
                                      const std::vector<uint32_t>& ids, const SimulationQualitySettings& settings) {
  Fnv1a f(solver.fingerprint() ^ 0x0DD5'11A7ull);
  f.value(uint32_t(2));  // this measure's revision (2: path sensitivity and edge strain)
  for (uint32_t id : ids) {
    f.value(id);
    for (const Quatf& q : poses[id].local) f.matrix(q.coeffs());
  }
  f.value(settings.noiseTurnDegrees);
  f.value(settings.seed);
  return f.h;
}

SimulationQuality measureSimulationQuality(const Character& character, const ClothSolver& solver,
                                           const std::vector<Pose>& poses, const std::vector<uint32_t>& ids,
                                           const std::vector<Points3f>& shapes, const SimulationQualitySettings& qs,
                                           const std::function<void(const std::string&)>& log) {
  const auto start = std::chrono::steady_clock::now();
  SimulationQuality q;
  q.noiseTurnDegrees = qs.noiseTurnDegrees;
  if (ids.empty()) return q;
  ClothSimSettings fine = solver.settings();
  fine.substeps *= 2;
  fine.equilibriumSubsteps *= 2;  // (0, the path's substeps, stays 0: doubled with them)
  fine.equilibriumTolerance *= 0.5f;
  fine.staticTolerance *= 0.5f;
  const ClothSolver reference(character, solver.mesh(), fine);
  ClothSimSettings longer = solver.settings();
  longer.transitionSeconds += 1.f / longer.frameRate;
  const ClothSolver otherPath(character, solver.mesh(), longer);

  // Four solves per pose: the reference, the pose turned by +a and -a, and the longer path.
  constexpr size_t kSolves = 4;
  const size_t n = ids.size();
  std::vector<PoseSimulation> results(kSolves * n);
  Rng axes(qs.seed ^ 0xA7E5ull);
  std::vector<Vec3f> axis(n);
  for (Vec3f& a : axis) {
    do a = Vec3f(float(axes.normal()), float(axes.normal()), float(axes.normal()));
    while (!(a.norm() > 1e-3f));
    a.normalize();
  }
  const float radians = qs.noiseTurnDegrees * float(M_PI) / 180.f;
  std::mutex mutex;
  size_t done = 0;
  auto one = [&](size_t task) {
    const size_t k = task / kSolves, kind = task % kSolves;
    const Pose& p = poses[ids[k]];
    results[task] = kind == 0   ? reference.simulate(p)
                    : kind == 3 ? otherPath.simulate(p)
                                : solver.simulate(turned(p, axis[k], kind == 1 ? radians : -radians));
    std::lock_guard<std::mutex> lock(mutex);
    ++done;
    if (log) {
      char line[160];
      std::snprintf(line, sizeof line,
                    "simulation check: %zu/%zu solves (convergence, noise and path sensitivity on %zu poses)", done,
                    kSolves * n, n);
      log(line);
    }
  };
  if (qs.threads > 0) {
    tbb::task_arena arena(qs.threads);
    arena.execute([&] { tbb::parallel_for(size_t(0), kSolves * n, size_t(1), one); });
  } else {
    tbb::parallel_for(size_t(0), kSolves * n, size_t(1), one);
  }

  std::vector<double> conv, noise, path, strain, referenceStrain;
  for (size_t k = 0; k < n; ++k) {
    const Points3f& x0 = shapes[k];
    const PoseSimulation* r = &results[kSolves * k];
    const PoseSimulation &ref = r[0], &plus = r[1], &minus = r[2], &other = r[3];
    const std::string pose = "pose " + std::to_string(ids[k]);
    if (!ref.ok) q.referenceFailures.push_back(pose + " (reference): " + ref.failure);
    if (!plus.ok) q.referenceFailures.push_back(pose + " (+turn): " + plus.failure);
    if (!minus.ok) q.referenceFailures.push_back(pose + " (-turn): " + minus.failure);
    if (!other.ok) q.referenceFailures.push_back(pose + " (longer path): " + other.failure);
    if (ref.ok && ref.positions.rows() == x0.rows()) {
      ++q.convergencePoses;
      for (Eigen::Index v = 0; v < x0.rows(); ++v)
        conv.push_back(1000.0 * double((ref.positions.row(v) - x0.row(v)).norm()));
      strain.push_back(meanEdgeStrainPercent(solver.constraints(), x0));
      referenceStrain.push_back(meanEdgeStrainPercent(solver.constraints(), ref.positions));
    }
    if (other.ok && other.positions.rows() == x0.rows()) {
      ++q.pathPoses;
      for (Eigen::Index v = 0; v < x0.rows(); ++v)
        path.push_back(1000.0 * double((other.positions.row(v) - x0.row(v)).norm()));
    }
    if (plus.ok && minus.ok && plus.positions.rows() == x0.rows()) {
      ++q.noisePoses;
      for (Eigen::Index v = 0; v < x0.rows(); ++v)
        noise.push_back(1000.0 / std::sqrt(6.0) *
                        double((plus.positions.row(v) - 2.f * x0.row(v) + minus.positions.row(v)).norm()));
    }
  }
  q.convergenceMeanMm = mean(conv);
  q.convergenceP95Mm = percentile(conv, 0.95);
  q.convergenceMaxMm = conv.empty() ? 0.0 : *std::max_element(conv.begin(), conv.end());
  q.noiseMeanMm = mean(noise);
  q.noiseP95Mm = percentile(noise, 0.95);
  q.pathMeanMm = mean(path);
  q.pathP95Mm = percentile(path, 0.95);
  q.edgeStrainPercent = mean(strain);
  q.referenceEdgeStrainPercent = mean(referenceStrain);
  q.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return q;
}

}  // namespace swish::bake
