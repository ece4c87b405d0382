#pragma once
// The thinned pose list of a cluster bake, computed once by `swish bake --slurm` before it submits and
// read by every array task: the poses to simulate (limbs already turned out of the trunk) with the
// simulation-file fingerprint each must carry, the recipe's part 1 settings digest, and the list's own
// fingerprint (DatasetPosePlan::fingerprint), which each job is submitted with. A task whose job was
// submitted for another list (the recipe changed and was submitted again) refuses to run, so shards
// of two recipes never mix in one simulation folder. Binary, little-endian:
//   "SWPOSES1" | u32 version (1) | u64 list fingerprint | u64 settings digest | u32 poses P |
//   u32 joints J | P x (u64 pose fingerprint | f32 root translation[3] | f32 rotations[J][x,y,z,w]) |
//   u64 FNV-1a of all before.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "swish/core/skeleton.hpp"

namespace swish::cluster {

struct PoseList {
  uint64_t fingerprint = 0;     // DatasetPosePlan::fingerprint of the plan it was written from
  uint64_t settingsDigest = 0;  // settingsDigest(part 1 settings) of the recipe
  std::vector<Pose> poses;      // pose id = index
  std::vector<uint64_t> poseFingerprints;
};

// Atomic (temporary file + rename). Throws Error naming the file.
void writePoseList(const std::filesystem::path& file, const PoseList& list);
// Throws Error naming the file for a missing, truncated, corrupt or foreign file.
PoseList readPoseList(const std::filesystem::path& file);

// "%016x" of a fingerprint, and back (throws Error for anything but 1 to 16 hex digits).
std::string fingerprintHex(uint64_t f);
uint64_t parseFingerprintHex(const std::string& text);

}  // namespace swish::cluster
