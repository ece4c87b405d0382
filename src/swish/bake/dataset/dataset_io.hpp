#pragma once
// The training dataset on disk: a folder that part 1 of the bake fills pose by pose and part 2 reads.
//
//   <folder>/manifest.json              format, version, character summary, input joints, bake settings,
//                                       the encodings below, the pose list with residuals, failed poses
//   <folder>/character.bin              the character (character_snapshot.hpp)
//   <folder>/poses/pose_<id:05>.bin     one finished pose (layout below)
//   <folder>/normal_maps/pose_<id:05>.png   its normal map: RGB PNG, 16 (default) or 8 bits per channel,
//                                       X, Y as unorm v * 0.5 + 0.5 in red, green; blue = Z (io/png.hpp)
//
// Pose file, little-endian: "SWDSPOSE" | u32 version (1) | u32 pose id | u32 joint count J |
//   u32 game vertex count N | f32 rotations [J][4] (w, x, y, z, local, unit) | f32 root translation [3] |
//   f32 game mesh world [N][3] | f32 game mesh pre-skin [N][3] | f32 max constraint violation |
//   f32 max penetration | u32 converged | i32 iterations | f64 seconds (as two u32, low first) |
//   u32 normal map width | u32 height | u32 CRC-32 of everything before.
//
// Resumable: a pose is done exactly when its pose file exists. The normal map is written first and
// the pose file last, each atomically, so an interruption leaves at worst an orphan PNG that the
// re-run overwrites. The manifest is (re)written from the pose files, so it can be rebuilt at any time.
#include <filesystem>
#include <string>
#include <vector>

#include "swish/bake/dataset/dataset.hpp"

namespace swish::bake {

struct FailedPose {
  uint32_t id = 0;
  std::string reason;
};

class DatasetWriter {
 public:
  // Creates the folder (and subfolders) and writes character.bin. Reopening a folder made for a
  // different character (character.bin differs) throws Error: poses of two characters never mix.
  DatasetWriter(std::filesystem::path folder, const Character& character, std::vector<uint32_t> inputJoints,
                nlohmann::json settings, uint32_t normalMapBitDepth = 16);

  bool hasPose(uint32_t id) const;
  // Writes the normal map, then the pose file. Thread-safe for different ids. Validates sizes against
  // the character and that everything is finite; throws Error naming the pose.
  void writePose(const DatasetPose& pose) const;
  // Lists the pose files present (ascending ids) and writes manifest.json atomically. `extra` is
  // merged into the manifest's "source" entry (character file, clips, tool versions...).
  void writeManifest(const std::vector<FailedPose>& failed = {}, const nlohmann::json& source = {}) const;

  const std::filesystem::path& folder() const { return folder_; }

 private:
  std::filesystem::path folder_;
  Character character_;
  std::vector<uint32_t> inputJoints_;
  nlohmann::json settings_;
  uint32_t bitDepth_;
};

std::filesystem::path datasetPosePath(const std::filesystem::path& folder, uint32_t id);
std::filesystem::path datasetNormalMapPath(const std::filesystem::path& folder, uint32_t id);

// Reads the whole dataset back with full validation: manifest format and version, character, every
// listed pose file (magic, version, sizes, checksum, id, finite values) and normal map (size, channels).
// Throws Error naming the file and the problem.
Dataset readDataset(const std::filesystem::path& folder);

}  // namespace swish::bake
