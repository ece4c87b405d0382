#pragma once
// The pose driver of the source simulation: every target pose simulated once, in parallel (one pose
// per TBB task; each solve is sequential, so results do not depend on the schedule), each result
// written to its own file as soon as it is done. A re-run reads the folder and skips the poses whose
// file carries the same fingerprint (same character, mesh, settings and pose), so an interruption
// loses at most the poses in flight.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "swish/bake/cloth/cloth_solver.hpp"
#include "swish/bake/cloth/simulated_pose_file.hpp"
#include "swish/bake/cloth/simulation_quality.hpp"

namespace swish::bake {

// Called after each pose (from worker threads, one call at a time) with the poses done so far
// (reused ones included), the total and an estimate of the seconds left. Return false to stop: no
// new pose starts, the ones in flight finish and are written.
using PoseSimulationProgress = std::function<bool(size_t done, size_t total, double secondsLeft)>;

struct PoseSimulationRun {
  size_t simulated = 0;  // solved in this run
  size_t reused = 0;     // found finished in the folder
  size_t failed = 0;     // failures, solved now or found recorded
  bool stopped = false;  // the progress callback asked to stop before all poses were done
  std::vector<std::pair<uint32_t, std::string>> failures;  // pose id, reason; ascending ids
  // Every finished pose's outcome (solved now or reused; ascending ids): retries, residuals, seconds.
  std::vector<SimulatedPoseSummary> poses;
};

// The fingerprint a pose's file must carry to be reused: the solver's setup and the pose's rotations.
uint64_t poseFingerprint(const ClothSolver& solver, const Pose& pose);
// The same from a solver digest (fingerprint() or firstAttemptFingerprint()).
uint64_t poseFingerprint(uint64_t solverFingerprint, const Pose& pose);

// Simulates poses[i] as pose id i into `dir` (created if needed). maxThreads 0: TBB's default.
// Throws Error if the folder cannot be made or a result cannot be written.
PoseSimulationRun simulatePoses(const ClothSolver& solver, const std::vector<Pose>& poses,
                                const std::filesystem::path& dir, const PoseSimulationProgress& progress = {},
                                int maxThreads = 0);
// The same for the poses `ids` of `poses` only (a shard of a cluster bake, swish/cluster/): the
// progress counts those; the others are neither read nor simulated. Throws Error for an id past the list.
PoseSimulationRun simulatePoses(const ClothSolver& solver, const std::vector<Pose>& poses,
                                const std::vector<uint32_t>& ids, const std::filesystem::path& dir,
                                const PoseSimulationProgress& progress = {}, int maxThreads = 0);

// Pose id i's stored result when it is present, readable and made for this solver and pose.
std::optional<SimulatedPoseRecord> loadFinishedPose(const std::filesystem::path& dir, uint32_t poseId,
                                                    uint64_t fingerprint);
// The same by the solver and the pose: also a result made under other retry settings when it was
// solved on its first attempt (ClothSolver::firstAttemptFingerprint), so that changing how failed
// poses are retried simulates again only the poses that failed or needed a retry.
std::optional<SimulatedPoseRecord> loadFinishedPose(const std::filesystem::path& dir, uint32_t poseId,
                                                    const ClothSolver& solver, const Pose& pose);

}  // namespace swish::bake
