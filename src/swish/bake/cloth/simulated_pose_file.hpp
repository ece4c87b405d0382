#pragma once
// One simulated pose on disk: what the pose driver writes when a pose is done, so that a re-run can
// skip it and an interruption loses only the poses in flight. Binary, little-endian:
//   "SWCLOTH1" | u32 version (1) | u32 pose id | u64 fingerprint | u32 ok | u32 vertex count |
//   f32 max violation | f32 max penetration | u32 converged | i32 iterations | f64 seconds |
//   u32 failure length | failure bytes | f32 positions[3 * vertex count] | u64 FNV-1a of all before.
// A failed pose is stored too (ok = 0, no positions): the failure is deterministic, so re-running
// it would only fail again; it is reported from the file and never used as a shape.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "swish/bake/cloth/cloth_solver.hpp"

namespace swish::bake {

struct SimulatedPoseRecord {
  uint32_t poseId = 0;
  uint64_t fingerprint = 0;  // the setup + pose that made it (ClothSolver::fingerprint + rotations)
  PoseSimulation result;
};

// <dir>/pose_<id, 6 digits>.clothsim
std::filesystem::path simulatedPosePath(const std::filesystem::path& dir, uint32_t poseId);

// Atomic (temporary file + rename): a reader sees the old file or the whole new one.
void writeSimulatedPose(const std::filesystem::path& file, const SimulatedPoseRecord& record);
// Throws Error naming the file for a missing, truncated, corrupt or foreign file.
SimulatedPoseRecord readSimulatedPose(const std::filesystem::path& file);

// The fixed-size head of a file alone (no positions, no checksum check): for counting finished poses
// over thousands of files (`swish bake --status`) without reading them whole. Files are written
// atomically, so a present file is a whole one. nullopt: missing, too short or not such a file.
struct SimulatedPoseHeader {
  uint32_t poseId = 0;
  uint64_t fingerprint = 0;
  bool ok = false;
  double seconds = 0.0;  // the solve's time (one core)
};
std::optional<SimulatedPoseHeader> peekSimulatedPose(const std::filesystem::path& file);

}  // namespace swish::bake
