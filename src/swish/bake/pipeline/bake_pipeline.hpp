#pragma once
// `swish bake`: the whole bake from a validated BakeConfig.
//   part 1 (character + clips -> thinned poses -> simulation -> transfer -> normal maps -> dataset folder)
//   part 2 (dataset folder -> PCA, database, VQ, MLP -> <output>/<name>.swish + <output>/report/)
// Resumable: part 1 keeps finished poses in the dataset folder (dataset_io.hpp); part 2 is skipped when
// the model file exists and was made from the same dataset manifest and the same train settings.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "swish/bake/pipeline/bake_config.hpp"

namespace swish::bake {

struct BakeRunOptions {
  bool force = false;  // redo part 2 even if its output is current
  // Run one part only (a cluster bake runs them as separate jobs, swish/cluster/): without part 1 the
  // dataset must exist; without part 2 the run ends when the dataset is written.
  bool part1 = true, part2 = true;
  // Nonzero: part 1's simulations were made by a cluster's array tasks for this pose list
  // (DatasetBuildSettings::simulatedPoseList); part 1 then only checks, transfers and writes the dataset.
  uint64_t simulatedPoseList = 0;
  std::function<void(const std::string& line)> log;  // progress lines (stage, %, time left)
};

struct BakeRunResult {
  std::filesystem::path model, report;
  bool part2Skipped = false;
  double seconds = 0.0, part1Seconds = 0.0, part2Seconds = 0.0;
  nlohmann::json part1;  // DatasetBuildResult::toJson + "seconds" (also <report>/part1.json); null without part 1
  nlohmann::json holdoutPart1;  // the held-out subjects' dataset build (part1.holdout); null without
};

// Part 1's settings split by part1.holdout: the training clips (the held-out subjects' removed) and the
// held-out subjects' clips, with the settings that build their evaluation dataset (evenly spaced
// frames, one unmirrored character, no rest pose, no preview). Without held-out subjects the second has
// no clips. Throws Error when every clip is held out.
std::pair<DatasetBuildSettings, DatasetBuildSettings> splitHeldOutSubjects(const DatasetBuildSettings& settings);

// `settings` made to simulate `count` frames spread evenly over its clips as a game plays them (one
// unmirrored character, no rest pose, no preview, no cluster pose list): the held-out subjects' frames,
// and the training clips' frames the body anchors are fitted on (train.anchor_poses, "simulated").
DatasetBuildSettings framesAsPlayed(DatasetBuildSettings settings, size_t count);

// The settings of the poses the bake simulates and trains on (config.part1, which it must have): the
// training split above, with the network's input joints required of the clips. `swish bake`, its Slurm
// array and `--export-poses` all plan their pose list from this, so the lists (and their digests) agree.
DatasetBuildSettings bakeTrainingSettings(const BakeConfig& config);

// train.anchor_poses "as_played" (BakeTrainSettings::anchorsAsPlayed): about train.anchorFramesAsPlayed
// frames spread evenly over the training clips of config.part1 (the held-out subjects' left out; by
// length, at least one per clip: evenlySpacedFrames), one character, unmirrored, each upright as part 1
// simulates it (canonicalPose), on `skeleton`; empty when it is off. `clipOf` (optional): per frame, the
// file name of its clip. Throws Error for a clip that does not read (named) or a recipe without part1.
std::vector<Pose> anchorFramesAsPlayed(const BakeConfig& config, const Skeleton& skeleton,
                                       const std::function<void(const std::string&)>& log = {},
                                       std::vector<std::string>* clipOf = nullptr);

BakeRunResult runBake(const BakeConfig& config, const BakeRunOptions& options = {});

}  // namespace swish::bake
