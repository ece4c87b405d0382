#pragma once
// `swish bake CONFIG --slurm`: the bake as a Slurm workload, one submission for the whole bake.
//
//   on the submitting machine      part 1 up to the simulation (character, clips, sampling, thinning,
//                                  limb clearance): the pose list, written once to <work>/slurm/poses.bin
//                                  with its fingerprint; seconds per pose measured; shards sized; the
//                                  job scripts written to <work>/slurm/; three sbatch calls
//   job 1, an array (part1.sbatch) task k simulates the poses [k P, (k+1) P) into <work>/simulation,
//                                  one resumable file per pose (bake/cloth/pose_driver.hpp): a task
//                                  killed, pre-empted or re-queued loses only the poses in flight, a
//                                  re-run skips the finished ones
//   job 2, afterok:1 (dataset.sbatch)  transfer, smoothing, normal maps, the dataset folder: part 1 as
//                                  a local bake runs it, but simulating nothing (all files must be there)
//   job 3, afterok:2 (part2.sbatch)    part 2: the model and its report, as a local bake writes them
//
// The same code makes every file as a local `swish bake` does, and a pose's simulation depends on
// that pose alone, so the model is the same bytes whichever node simulated which pose in which order.
// Every job carries the pose list's fingerprint: a job submitted for another recipe's list stops
// before it writes anything. `swish bake CONFIG --status` reads the folder and the queue.
//
// Everything lives in the recipe's work and output folders, which every node must see at the same
// path (a shared file system); docs/cluster.md says what goes where.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/pipeline/bake_config.hpp"

namespace swish::cluster {

struct SlurmSubmitOptions {
  std::string partition, account;         // sbatch --partition / --account; empty: the cluster's default
  std::string timeLimit = "1:00:00";      // per array task (sbatch --time); sizes the shards
  std::string finalTimeLimit;             // the dataset and part 2 jobs; empty: the partition's default
  int cpusPerTask = 1;                    // every job's --cpus-per-task; a task simulates that many poses at once
  int maxRunning = 0;                     // array tasks at once (--array=...%N); 0: no limit
  std::vector<std::string> sbatchArgs;    // given to every sbatch call as they are, after swish's own
  double secondsPerPose = 0.0;            // one pose on one core; 0: measured (see submitSlurmBake)
  size_t posesPerTask = 0;                // 0: from seconds per pose and the time limit
  bool dryRun = false;                    // write the pose list and scripts, print the sbatch lines, submit nothing
  std::filesystem::path swishExecutable;  // what the jobs run; empty: this process's own executable
  std::function<void(const std::string&)> log;
};

// The shards: P poses per array task, so that a task's work (its setup, then ceil(P / cpus) poses one
// after the other on each of its cpus) fills at most 80 % of its time limit, the rest left for a node
// slower than the one that measured. Throws Error when the limit leaves no time for one pose.
struct ShardPlan {
  size_t posesPerTask = 0;
  size_t shards = 0;
  double taskSeconds = 0.0;  // the estimated wall time of a full task
};
ShardPlan planShards(size_t poses, double secondsPerPose, double setupSeconds, double timeLimitSeconds, int cpusPerTask,
                     size_t posesPerTaskOverride = 0);

// Slurm's time formats ("minutes", "minutes:seconds", "hours:minutes:seconds", "days-hours",
// "days-hours:minutes", "days-hours:minutes:seconds") in seconds. Throws Error naming the text.
double parseSlurmTime(const std::string& text);
// Ascending indices as sbatch's --array list: {0,1,2,3,5,7,8} -> "0-3,5,7-8".
std::string arrayIndexList(const std::vector<size_t>& indices);

// <work>/slurm: the pose list, the scripts, submission.json, shards/ (one progress file per shard), logs/.
std::filesystem::path slurmDir(const bake::BakeConfig& config);

// Computes the pose list, sizes the shards and submits the three jobs. Seconds per pose: the option
// when given; else the median of this recipe's poses already simulated (3 or more); else one pose is
// simulated here on one core and timed (its file is kept, so no work is lost). Refuses (Error) when a
// submission of this work folder still has jobs in the queue, when the recipe has no part 1, or when
// sbatch fails (its message included). Returns submission.json's content.
nlohmann::json submitSlurmBake(const bake::BakeConfig& config, const std::filesystem::path& configFile,
                               const SlurmSubmitOptions& options);

// Inside a job: `stage` is "part1" (the array task SLURM_ARRAY_TASK_ID simulates its shard of
// `shardSize` poses), "dataset" or "part2". `poseList` is the fingerprint the job was submitted with.
// CPUs: SLURM_CPUS_PER_TASK when set. Throws Error (the job fails, its dependants are cancelled) on a
// mismatch or any failure; poses whose simulation fails are recorded and left out, as locally.
void runSlurmStage(const bake::BakeConfig& config, const std::string& stage, uint64_t poseList, size_t shardSize,
                   const std::function<void(const std::string&)>& log);

// `swish bake CONFIG --status`: poses done, failed, in flight and waiting, per stage; the jobs' states
// from squeue; an estimate of the time part 1 has left. Never throws for a queue it cannot reach (it
// says so); throws Error when nothing was submitted from this work folder.
std::string slurmBakeStatus(const bake::BakeConfig& config);

}  // namespace swish::cluster
