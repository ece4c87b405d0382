#include "swish/bake/cloth/pose_driver.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "swish/core/error.hpp"
#include "swish/core/hash.hpp"

namespace swish::bake {

uint64_t poseFingerprint(const ClothSolver& solver, const Pose& pose) {
  return poseFingerprint(solver.fingerprint(), pose);
}

uint64_t poseFingerprint(uint64_t solverFingerprint, const Pose& pose) {
  Fnv1a f(solverFingerprint ^ 0x9E3779B97F4A7C15ull);
  for (const Quatf& q : pose.local) f.matrix(q.coeffs());
  // The root translation is ignored by the solve, so it is not part of the fingerprint.
  return f.h;
}

std::optional<SimulatedPoseRecord> loadFinishedPose(const std::filesystem::path& dir, uint32_t poseId,
                                                    uint64_t fingerprint) {
  const std::filesystem::path file = simulatedPosePath(dir, poseId);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) return std::nullopt;
  try {
    SimulatedPoseRecord rec = readSimulatedPose(file);
    if (rec.poseId != poseId || rec.fingerprint != fingerprint) return std::nullopt;
    return rec;
  } catch (const Error&) {
    return std::nullopt;  // unreadable leftovers are simply simulated again (and overwritten)
  }
}

std::optional<SimulatedPoseRecord> loadFinishedPose(const std::filesystem::path& dir, uint32_t poseId,
                                                    const ClothSolver& solver, const Pose& pose) {
  if (auto rec = loadFinishedPose(dir, poseId, poseFingerprint(solver, pose))) return rec;
  if (solver.firstAttemptFingerprint() == solver.fingerprint()) return std::nullopt;
  auto rec = loadFinishedPose(dir, poseId, poseFingerprint(solver.firstAttemptFingerprint(), pose));
  if (rec && rec->result.ok && rec->result.attempts == 1) return rec;
  return std::nullopt;
}

PoseSimulationRun simulatePoses(const ClothSolver& solver, const std::vector<Pose>& poses,
                                const std::filesystem::path& dir, const PoseSimulationProgress& progress,
                                int maxThreads) {
  std::vector<uint32_t> all(poses.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = uint32_t(i);
  return simulatePoses(solver, poses, all, dir, progress, maxThreads);
}

PoseSimulationRun simulatePoses(const ClothSolver& solver, const std::vector<Pose>& poses,
                                const std::vector<uint32_t>& ids, const std::filesystem::path& dir,
                                const PoseSimulationProgress& progress, int maxThreads) {
  for (uint32_t id : ids)
    if (id >= poses.size())
      throw Error("simulatePoses: pose id " + std::to_string(id) + " is past the " + std::to_string(poses.size()) +
                  " poses");
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir))
    throw Error(dir.string() + ": cannot create the simulation output folder: " + ec.message());

  PoseSimulationRun run;
  const size_t total = ids.size();
  const size_t nv = solver.mesh().vertexCount();
  std::vector<uint64_t> fingerprints(poses.size());
  std::vector<uint32_t> todo;
  std::vector<std::pair<uint32_t, std::string>> failures;
  std::vector<SimulatedPoseSummary> summaries;
  auto summary = [](uint32_t id, const PoseSimulation& r) {
    return SimulatedPoseSummary{id, r.ok, r.failure, r.attempts, r.firstFailure, r.residuals};
  };
  for (uint32_t i : ids) {
    fingerprints[i] = poseFingerprint(solver, poses[i]);
    auto rec = loadFinishedPose(dir, i, solver, poses[i]);
    if (rec && (!rec->result.ok || size_t(rec->result.positions.rows()) == nv)) {
      ++run.reused;
      summaries.push_back(summary(i, rec->result));
      if (!rec->result.ok) failures.push_back({i, rec->result.failure});
    } else {
      todo.push_back(i);
    }
  }

  std::mutex mutex;  // guards the counters below and serialises the callback
  size_t done = run.reused;
  double solveSeconds = 0.0;
  std::atomic<bool> stop = false;
  const auto start = std::chrono::steady_clock::now();
  if (progress && !progress(done, total, 0.0)) stop = true;

  auto work = [&] {
    tbb::parallel_for(size_t(0), todo.size(), size_t(1), [&](size_t k) {
      if (stop.load()) return;
      const uint32_t id = todo[k];
      SimulatedPoseRecord rec;
      rec.poseId = id;
      rec.fingerprint = fingerprints[id];
      rec.result = solver.simulate(poses[id]);
      writeSimulatedPose(simulatedPosePath(dir, id), rec);
      std::lock_guard<std::mutex> lock(mutex);
      ++done;
      ++run.simulated;
      solveSeconds += rec.result.residuals.seconds;
      summaries.push_back(summary(id, rec.result));
      if (!rec.result.ok) failures.push_back({id, rec.result.failure});
      // Time left from the wall-clock rate of this run (it already includes the parallelism).
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const double left = elapsed / double(run.simulated) * double(total - done);
      if (progress && !progress(done, total, left)) stop = true;
    });
  };
  if (maxThreads > 0) {
    tbb::task_arena arena(maxThreads);
    arena.execute(work);
  } else {
    work();
  }
  run.stopped = done < total;
  std::sort(failures.begin(), failures.end());
  run.failed = failures.size();
  run.failures = std::move(failures);
  std::sort(summaries.begin(), summaries.end(), [](const auto& a, const auto& b) { return a.id < b.id; });
  run.poses = std::move(summaries);
  return run;
}

}  // namespace swish::bake
