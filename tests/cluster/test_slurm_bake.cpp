// `swish bake --slurm` on a real one-node Slurm cluster: slurmctld, slurmd and munged from Debian's
// packages, started in a temporary folder by local_slurm.sh and stopped by their pids when the test
// ends (also when it fails; a watchdog stops them if this process is killed). A small bake of the
// embedded default character is baked locally and submitted to the cluster as an array of 4 or more
// tasks; one task is re-queued (killed and put back in the queue, as a pre-emption does) while it is
// part way through its shard. Checked: the re-queued task finishes its shard without simulating again
// a pose that had finished, the dataset and part 2 jobs run after the array, `--status` reports the
// whole bake done, the model's bytes equal the local bake's, and a job submitted for another pose list
// refuses to run.
//
// Without Slurm (or not as root) it skips with the reason; with CI=true it fails instead.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/cloth/simulated_pose_file.hpp"
#include "swish/cluster/process.hpp"

using namespace swish;
using swish::cluster::CommandResult;
using swish::cluster::runCommand;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

const fs::path kClip = test::debianMocap("01_01.bvh");

bool inCi() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string readText(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The recipe of e2e/test_bake_whole.cpp with fewer poses, each simulated a little longer (a longer
// transition) so that a task is still busy when it is re-queued.
nlohmann::json recipe() {
  return {{"name", "cluster"},
          {"output", "out"},
          {"part1",
           {{"character", "default"},
            {"clips", {kClip.string()}},
            {"thinning", {{"target_poses", 19}}},
            {"simulation",
             {{"vertices", 0},
              {"transition_seconds", 0.6},
              {"settle_seconds", 0.2},
              {"frame_rate", 20},
              {"threads", 2},
              {"gravity", 0}}},
            {"normal_maps", {{"size", 16}, {"dilation_rings", 2}}},
            {"preview", {{"poses", 1}, {"size", 64}}}}},
          {"train",
           {{"mesh_components", 8},
            {"normal_code_dims", 4},
            {"database_size", 8},
            {"codebook_size", 32},
            {"hidden_layers", 2},
            {"hidden_width", 16},
            {"max_epochs", 100},
            {"patience", 30},
            {"test_fraction", 0.15},
            {"bc5_baseline", false}}}};
}

// The cluster's daemons, up for the life of this object.
class LocalSlurm {
 public:
  explicit LocalSlurm(fs::path dir) : dir_(std::move(dir)) {
    const CommandResult r = runCommand({"bash", SWISH_LOCAL_SLURM, "start", dir_.string(), std::to_string(getpid())});
    if (r.exitCode != 0) {
      error_ = "local_slurm.sh start exited " + std::to_string(r.exitCode) + ": " + r.err + r.out;
      stop();
      return;
    }
    setenv("SLURM_CONF", (dir_ / "slurm.conf").c_str(), 1);
    for (const char* f : {"munged.pid", "slurmctld.pid", "slurmd.pid", "watchdog.pid"}) {
      const std::string text = readText(dir_ / f);
      if (!text.empty()) pids_[f] = std::atoi(text.c_str());
    }
    up_ = true;
  }
  ~LocalSlurm() { stop(); }
  bool up() const { return up_; }
  const std::string& error() const { return error_; }
  const std::map<std::string, int>& pids() const { return pids_; }

  // Stops every daemon by its pid file; returns the output of the stop script.
  std::string stop() {
    if (stopped_) return {};
    stopped_ = true;
    const CommandResult r = runCommand({"bash", SWISH_LOCAL_SLURM, "stop", dir_.string()});
    return r.out + r.err;
  }

 private:
  fs::path dir_;
  bool up_ = false, stopped_ = false;
  std::string error_;
  std::map<std::string, int> pids_;
};

CommandResult swishCmd(std::vector<std::string> args) {
  args.insert(args.begin(), SWISH_CLI);
  return runCommand(args);
}

// squeue's lines for these jobs ("id|state"), array tasks one per line.
std::vector<std::pair<std::string, std::string>> queue(const std::string& jobs) {
  const CommandResult r = runCommand({"squeue", "-h", "-r", "-j", jobs, "-o", "%i|%T"});
  std::vector<std::pair<std::string, std::string>> q;
  std::istringstream in(r.out);
  for (std::string line; std::getline(in, line);)
    if (const size_t bar = line.find('|'); bar != std::string::npos)
      q.push_back({line.substr(0, bar), line.substr(bar + 1)});
  return q;
}

struct FileId {
  ino_t inode = 0;
  int64_t mtimeNs = 0;
  bool operator==(const FileId&) const = default;
};
FileId fileId(const fs::path& f) {
  struct stat st {};
  if (stat(f.c_str(), &st) != 0) return {};
  return {st.st_ino, int64_t(st.st_mtim.tv_sec) * 1'000'000'000 + st.st_mtim.tv_nsec};
}

}  // namespace

TEST(SlurmBake, ArrayWithARequeuedTaskMakesTheLocalBakesModel) {
  if (!fs::exists(kClip)) {
    if (inCi()) FAIL() << kClip << " is missing (Debian package assimp-testmodels)";
    GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  }
  const test::TempDir tmp("slurm_bake");
  LocalSlurm slurm(tmp / "slurm");
  if (!slurm.up()) {
    if (inCi()) FAIL() << "CI=true: the local Slurm cluster must start: " << slurm.error();
    GTEST_SKIP() << "no local Slurm cluster (tools/setup.sh installs slurm-wlm, slurm-client and munge; the "
                    "daemons run as root): "
                 << slurm.error();
  }

  // The same recipe in two folders: one baked here, one on the cluster.
  for (const char* d : {"local", "cluster"}) {
    fs::create_directories(tmp / d);
    std::ofstream(tmp / d / "bake.json") << recipe().dump(2);
  }
  auto t = Clock::now();
  const CommandResult local = swishCmd({"bake", (tmp / "local" / "bake.json").string()});
  ASSERT_EQ(local.exitCode, 0) << local.err;
  std::printf("local bake: %.1f s\n", since(t));

  // Submit: 4 poses per task, one CPU each, two tasks at once on the two-core node.
  t = Clock::now();
  const fs::path cfg = tmp / "cluster" / "bake.json";
  const CommandResult sub = swishCmd({"bake", cfg.string(), "--slurm", "--poses-per-task", "4", "--cpus-per-task", "1",
                                      "--time", "10", "--max-running", "2"});
  ASSERT_EQ(sub.exitCode, 0) << sub.err;
  std::printf("%s", sub.err.c_str());
  const fs::path work = tmp / "cluster" / "out" / "work";
  const nlohmann::json submission = nlohmann::json::parse(readText(work / "slurm" / "submission.json"));
  const size_t poses = submission.at("poses"), shards = submission.at("shards"),
               shardSize = submission.at("shard_size");
  ASSERT_EQ(shardSize, 4u);
  ASSERT_GE(shards, 4u) << "the goal is an array of 4 or more tasks";
  const std::string array = submission.at("jobs").at("part1"), dataset = submission.at("jobs").at("dataset"),
                    part2 = submission.at("jobs").at("part2");
  const std::string allJobs = array + "," + dataset + "," + part2;

  // Re-queue one running task that has finished part of its shard, with poses left to do.
  const fs::path sim = work / "simulation";
  auto finishedIn = [&](size_t shard) {
    std::map<uint32_t, FileId> f;
    for (size_t i = shard * shardSize; i < std::min(poses, (shard + 1) * shardSize); ++i)
      if (bake::peekSimulatedPose(bake::simulatedPosePath(sim, uint32_t(i))))
        f[uint32_t(i)] = fileId(bake::simulatedPosePath(sim, uint32_t(i)));
    return f;
  };
  // Poses finished before any task ran (the one the submission simulated to time it) do not count as
  // a task's progress.
  std::map<uint32_t, FileId> atSubmission;
  for (size_t k = 0; k < shards; ++k) atSubmission.merge(finishedIn(k));
  size_t killed = SIZE_MAX;
  std::map<uint32_t, FileId> before;
  const auto waitStart = Clock::now();
  while (killed == SIZE_MAX && since(waitStart) < 180) {
    for (const auto& [id, state] : queue(array)) {
      if (state != "RUNNING" || id.find('_') == std::string::npos) continue;
      const size_t k = std::stoul(id.substr(id.find('_') + 1));
      const size_t count = std::min(poses, (k + 1) * shardSize) - k * shardSize;
      auto done = finishedIn(k);
      size_t byTask = 0;
      for (const auto& [pose, fid] : done) byTask += !atSubmission.count(pose);
      if (byTask == 0 || done.size() + 2 > count) continue;
      const CommandResult rq = runCommand({"scontrol", "requeue", id});
      if (rq.exitCode != 0) continue;  // it finished in between: try another
      killed = k;
      // Poses that finished while the kill was on its way are kept too: what counts is the set after it.
      before = finishedIn(k);
      // A re-queued job waits two minutes (BeginTime) before it may start again; once it is pending
      // (its old run ended), let it start now.
      bool released = false;
      for (const auto ws = Clock::now(); !released && since(ws) < 60;) {
        for (const auto& [qid, qstate] : queue(id))
          if (qid == id && qstate == "PENDING")
            released = runCommand({"scontrol", "update", "JobId=" + id, "StartTime=now"}).exitCode == 0;
        if (!released) std::this_thread::sleep_for(std::chrono::milliseconds(200));
      }
      EXPECT_TRUE(released) << id << " was not pending again within 60 s of its re-queue";
      std::printf("re-queued %s after %.1f s with %zu of %zu poses of its shard finished (%zu by the task)\n",
                  id.c_str(), since(waitStart), before.size(), count, byTask);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_NE(killed, SIZE_MAX) << "no array task was caught part way through its shard";

  // Wait for the whole bake (bounded), then stop the cluster.
  const auto doneStart = Clock::now();
  std::string lastQueue;
  while (since(doneStart) < 300) {
    const auto q = queue(allJobs);
    if (q.empty()) break;
    std::string now;
    for (const auto& [id, state] : q) now += " " + id + ":" + state;
    if (now != lastQueue) std::printf("%6.1f s:%s\n", since(t), now.c_str());
    lastQueue = now;
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
  }
  ASSERT_TRUE(queue(allJobs).empty()) << "the bake's jobs were still queued after 300 s";
  std::printf("cluster bake: %.1f s from submission\n", since(t));
  const CommandResult status = swishCmd({"bake", cfg.string(), "--status"});
  std::printf("%s", status.out.c_str());
  const std::string stopOutput = slurm.stop();
  for (const auto& [file, pid] : slurm.pids()) EXPECT_NE(kill(pid, 0), 0) << file << ": pid " << pid << " still runs";
  EXPECT_EQ(stopOutput.find("still running"), std::string::npos) << stopOutput;

  // The model: the local bake's bytes.
  const fs::path model = tmp / "cluster" / "out" / "cluster.swish";
  ASSERT_TRUE(fs::exists(model)) << "no model; logs in " << (work / "slurm" / "logs") << ":\n"
                                 << readText(work / "slurm" / "logs" / ("dataset_" + dataset + ".out"))
                                 << readText(work / "slurm" / "logs" / ("part2_" + part2 + ".out"));
  const std::string localBytes = readText(tmp / "local" / "out" / "cluster.swish");
  ASSERT_FALSE(localBytes.empty());
  EXPECT_TRUE(readText(model) == localBytes) << "the cluster's model differs from the local bake's";

  // The re-queued shard: finished again, and every pose that had finished before the kill untouched.
  char shardName[40];
  std::snprintf(shardName, sizeof shardName, "shard_%06zu.json", killed);
  const nlohmann::json shard = nlohmann::json::parse(readText(work / "slurm" / "shards" / shardName));
  EXPECT_EQ(shard.at("state"), "done");
  EXPECT_GE(shard.at("restart").get<int>(), 1);
  EXPECT_EQ(shard.at("done"), shard.at("count"));
  EXPECT_GE(shard.at("reused").get<size_t>(), before.size());
  EXPECT_EQ(shard.at("simulated").get<size_t>() + shard.at("reused").get<size_t>(), shard.at("count").get<size_t>());
  for (const auto& [id, fid] : before)
    EXPECT_TRUE(fileId(bake::simulatedPosePath(sim, id)) == fid) << "pose " << id << " was simulated again";
  const std::string taskLog =
      readText(work / "slurm" / "logs" / ("part1_" + array + "_" + std::to_string(killed) + ".out"));
  EXPECT_NE(taskLog.find("restart 1"), std::string::npos) << taskLog;
  EXPECT_NE(taskLog.find("finished before (kept)"), std::string::npos) << taskLog;
  for (size_t k = 0; k < shards; ++k) {
    char name[40];
    std::snprintf(name, sizeof name, "shard_%06zu.json", k);
    const fs::path f = work / "slurm" / "shards" / name;
    if (!fs::exists(f)) continue;  // a shard finished before the submission (the measured pose) has no task
    EXPECT_EQ(nlohmann::json::parse(readText(f)).at("state"), "done") << f;
  }

  // --status saw all of it.
  EXPECT_NE(status.out.find(std::to_string(poses) + " of " + std::to_string(poses) + " poses done"), std::string::npos)
      << status.out;
  EXPECT_NE(status.out.find("part 2: job " + part2 + " done"), std::string::npos) << status.out;

  // A job submitted for another pose list stops before writing anything.
  setenv("SLURM_ARRAY_TASK_ID", "0", 1);
  const CommandResult foreign =
      swishCmd({"bake", cfg.string(), "--slurm-task", "part1", "--pose-list", "123456789abcdef0", "--shard-size", "4"});
  unsetenv("SLURM_ARRAY_TASK_ID");
  EXPECT_NE(foreign.exitCode, 0);
  EXPECT_NE(foreign.err.find("submitted for 123456789abcdef0"), std::string::npos) << foreign.err;
}
