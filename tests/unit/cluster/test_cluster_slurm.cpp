// The parts of `swish bake --slurm` that need no cluster: shard sizing, Slurm's time formats, the
// --array list, the pose list file and its guards, quoting for the job scripts.
#include <gtest/gtest.h>

#include <fstream>

#include "support/error_message.hpp"
#include "support/temp_dir.hpp"
#include "swish/cluster/pose_list_file.hpp"
#include "swish/cluster/process.hpp"
#include "swish/cluster/slurm_bake.hpp"
#include "swish/core/error.hpp"

using namespace swish;
using namespace swish::cluster;
namespace fs = std::filesystem;

TEST(ClusterSlurm, ShardsFillEightyPercentOfTheTimeLimit) {
  // 10 s per pose, 20 s setup, 1 hour: (2880 - 20) / 10 = 286 poses per cpu.
  ShardPlan p = planShards(2835, 10.0, 20.0, 3600.0, 1);
  EXPECT_EQ(p.posesPerTask, 286u);
  EXPECT_EQ(p.shards, 10u);  // ceil(2835 / 286)
  EXPECT_LE(p.taskSeconds, 0.8 * 3600.0);
  // Four cpus simulate four poses at once: four times the poses per task.
  p = planShards(2835, 10.0, 20.0, 3600.0, 4);
  EXPECT_EQ(p.posesPerTask, 4u * 286u);
  EXPECT_EQ(p.shards, 3u);
  EXPECT_LE(p.taskSeconds, 0.8 * 3600.0);
  // Half the time limit, twice the tasks (up to rounding): linear.
  EXPECT_EQ(planShards(2835, 10.0, 0.0, 1800.0, 1).posesPerTask, 144u);
  // A shard never holds more than the poses there are; an override wins.
  EXPECT_EQ(planShards(30, 1.0, 0.0, 3600.0, 1).shards, 1u);
  EXPECT_EQ(planShards(30, 1.0, 0.0, 3600.0, 1, 4).shards, 8u);
  // A limit that leaves no time for one pose is an error that says what to do.
  const std::string msg = test::errorOf([] { planShards(100, 60.0, 10.0, 60.0, 1); });
  EXPECT_NE(msg.find("--time"), std::string::npos) << msg;
  EXPECT_THROW(planShards(100, 0.0, 0.0, 60.0, 1), Error);
}

TEST(ClusterSlurm, ParsesSlurmTimeLimits) {
  EXPECT_EQ(parseSlurmTime("30"), 1800.0);
  EXPECT_EQ(parseSlurmTime("30:15"), 1815.0);
  EXPECT_EQ(parseSlurmTime("2:00:00"), 7200.0);
  EXPECT_EQ(parseSlurmTime("1-0"), 86400.0);
  EXPECT_EQ(parseSlurmTime("1-2:30"), 86400.0 + 9000.0);
  EXPECT_EQ(parseSlurmTime("1-02:00:05"), 86400.0 + 7205.0);
  for (const char* bad : {"", "abc", "1:2:3:4", "1-2-3", "0", "-5", "1h"})
    EXPECT_THROW(parseSlurmTime(bad), Error) << bad;
  EXPECT_NE(test::errorOf([] { parseSlurmTime("1h"); }).find("'1h'"), std::string::npos);
}

TEST(ClusterSlurm, ArrayIndexListCompressesRuns) {
  EXPECT_EQ(arrayIndexList({0, 1, 2, 3, 5, 7, 8}), "0-3,5,7-8");
  EXPECT_EQ(arrayIndexList({4}), "4");
  EXPECT_EQ(arrayIndexList({}), "");
}

TEST(ClusterSlurm, PoseListRoundTripsAndRefusesDamage) {
  PoseList list;
  list.fingerprint = 0x0123456789abcdefull;
  list.settingsDigest = 42;
  for (int i = 0; i < 3; ++i) {
    Pose p;
    p.local = {Quatf(Eigen::AngleAxisf(0.1f * float(i), Vec3f::UnitX())), Quatf::Identity()};
    p.rootTranslation = Vec3f(0.f, 1.f, float(i));
    list.poses.push_back(p);
    list.poseFingerprints.push_back(1000u + uint64_t(i));
  }
  const test::TempDir tmp("pose_list");
  writePoseList(tmp / "poses.bin", list);
  const PoseList back = readPoseList(tmp / "poses.bin");
  EXPECT_EQ(back.fingerprint, list.fingerprint);
  EXPECT_EQ(back.settingsDigest, 42u);
  EXPECT_EQ(back.poseFingerprints, list.poseFingerprints);
  ASSERT_EQ(back.poses.size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.poses[i].rootTranslation, list.poses[i].rootTranslation);
    for (size_t j = 0; j < 2; ++j) EXPECT_EQ(back.poses[i].local[j].coeffs(), list.poses[i].local[j].coeffs());
  }
  // A flipped byte, a cut file, a missing file: errors naming the file.
  std::string bytes;
  {
    std::ifstream in(tmp / "poses.bin", std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  std::string flipped = bytes;
  flipped[40] ^= 1;
  std::ofstream(tmp / "flipped.bin", std::ios::binary) << flipped;
  std::ofstream(tmp / "cut.bin", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  for (const char* f : {"flipped.bin", "cut.bin", "missing.bin"}) {
    const std::string msg = test::errorOf([&] { readPoseList(tmp / f); });
    EXPECT_NE(msg.find(f), std::string::npos) << msg;
  }
  EXPECT_EQ(fingerprintHex(list.fingerprint), "0123456789abcdef");
  EXPECT_EQ(parseFingerprintHex("0123456789abcdef"), list.fingerprint);
  EXPECT_THROW(parseFingerprintHex("xyz"), Error);
  EXPECT_THROW(parseFingerprintHex("0123456789abcdef0"), Error);
}

TEST(ClusterSlurm, RunsCommandsAndQuotesForTheShell) {
  const CommandResult r = runCommand({"sh", "-c", "echo out; echo err >&2; exit 3"});
  EXPECT_EQ(r.exitCode, 3);
  EXPECT_EQ(r.out, "out\n");
  EXPECT_EQ(r.err, "err\n");
  EXPECT_EQ(runCommand({"/nonexistent/program"}).exitCode, 127);
  EXPECT_EQ(shellLine({"sbatch", "--array=0-3%2", "it's a file.sh"}), "sbatch --array=0-3%2 'it'\\''s a file.sh'");
  const CommandResult echo = runCommand({"bash", "-c", "eval \"printf %s $0\"", shellQuote("a 'b' $c")});
  EXPECT_EQ(echo.out, "a 'b' $c");
}
