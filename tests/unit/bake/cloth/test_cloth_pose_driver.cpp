// The pose driver: parallel, deterministic, resumable; per-pose files written atomically.
#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "support/cloth_fixture.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/cloth/pose_driver.hpp"
#include "swish/bake/cloth/simulated_pose_file.hpp"
#include "swish/core/error.hpp"

using namespace swish;
using namespace swish::bake;
namespace fs = std::filesystem;

namespace {

ClothSimSettings fastSettings() {
  ClothSimSettings s;
  s.transitionSeconds = 0.3f;
  s.settleSeconds = 0.2f;
  s.frameRate = 20.f;
  return s;
}

std::vector<Pose> somePoses(const Skeleton& sk, int n) {
  std::vector<Pose> poses;
  for (int i = 0; i < n; ++i) {
    Pose p = sk.restPose();
    p.local[2] = Quatf(Eigen::AngleAxisf(0.15f * float(i - n / 2), Vec3f(1.f, 0.f, 0.3f).normalized()));
    poses.push_back(p);
  }
  return poses;
}

bool sameBits(const Points3f& a, const Points3f& b) {
  return a.rows() == b.rows() && std::memcmp(a.data(), b.data(), sizeof(float) * size_t(a.size())) == 0;
}

}  // namespace

TEST(ClothPoseDriver, ResumesWithoutLosingOrRedoingFinishedPoses) {
  const Character ch = test::capsuleCharacter();
  const ClothSolver solver(ch, buildSimulationMesh(ch, 0), fastSettings());
  std::vector<Pose> poses = somePoses(ch.skeleton, 6);
  poses[3].local[1] = Quatf(std::numeric_limits<float>::quiet_NaN(), 0, 0, 0);  // fails, and is reported

  const test::TempDir tmp("cloth_resume");
  const fs::path whole = tmp / "whole", resumed = tmp / "resumed";
  const PoseSimulationRun ref = simulatePoses(solver, poses, whole, {}, 2);
  EXPECT_EQ(ref.simulated, 6u);
  EXPECT_EQ(ref.failed, 1u);
  ASSERT_EQ(ref.failures.size(), 1u);
  EXPECT_EQ(ref.failures[0].first, 3u);
  EXPECT_FALSE(ref.stopped);

  // Interrupted after two poses (one thread, so exactly two are done), then run again.
  size_t calls = 0;
  const PoseSimulationRun first = simulatePoses(
      solver, poses, resumed,
      [&](size_t done, size_t total, double left) {
        ++calls;
        EXPECT_EQ(total, 6u);
        EXPECT_GE(left, 0.0);
        return done < 2;
      },
      1);
  EXPECT_TRUE(first.stopped);
  EXPECT_EQ(first.simulated, 2u);
  std::vector<fs::file_time_type> stamps;
  for (uint32_t id : {0u, 1u}) stamps.push_back(fs::last_write_time(simulatedPosePath(resumed, id)));
  const PoseSimulationRun second = simulatePoses(solver, poses, resumed, {}, 2);
  EXPECT_EQ(second.reused, 2u);
  EXPECT_EQ(second.simulated, 4u);
  EXPECT_FALSE(second.stopped);
  EXPECT_EQ(second.failures, ref.failures);
  for (uint32_t id : {0u, 1u})  // finished poses were not written again
    EXPECT_EQ(fs::last_write_time(simulatedPosePath(resumed, id)), stamps[id]);
  // Same results, bit for bit, as the uninterrupted run (which ran on two threads).
  for (uint32_t id = 0; id < 6; ++id) {
    const SimulatedPoseRecord a = readSimulatedPose(simulatedPosePath(whole, id));
    const SimulatedPoseRecord b = readSimulatedPose(simulatedPosePath(resumed, id));
    EXPECT_EQ(a.result.ok, id != 3);
    EXPECT_EQ(a.result.ok, b.result.ok);
    EXPECT_TRUE(sameBits(a.result.positions, b.result.positions)) << "pose " << id;
  }
  // A third run has nothing left to do.
  const PoseSimulationRun third = simulatePoses(solver, poses, resumed);
  EXPECT_EQ(third.simulated, 0u);
  EXPECT_EQ(third.reused, 6u);
}

TEST(ClothPoseDriver, RedoesPosesWhoseSetupChangedOrWhoseFileIsDamaged) {
  const Character ch = test::capsuleCharacter();
  const ClothSolver solver(ch, buildSimulationMesh(ch, 0), fastSettings());
  const std::vector<Pose> poses = somePoses(ch.skeleton, 2);
  const test::TempDir tmp("cloth_changed");
  const fs::path dir = tmp / "changed";
  simulatePoses(solver, poses, dir);
  // Damage pose 0's file: it must be detected and simulated again.
  {
    std::fstream f(simulatedPosePath(dir, 0), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(60);
    f.put('\x7f');
  }
  EXPECT_THROW(readSimulatedPose(simulatedPosePath(dir, 0)), Error);
  const PoseSimulationRun again = simulatePoses(solver, poses, dir);
  EXPECT_EQ(again.simulated, 1u);
  EXPECT_EQ(again.reused, 1u);
  // Another material: nothing is reused.
  ClothSimSettings cotton = fastSettings();
  cotton.material = clothMaterialPreset("cotton");
  const ClothSolver other(ch, buildSimulationMesh(ch, 0), cotton);
  EXPECT_NE(other.fingerprint(), solver.fingerprint());
  EXPECT_EQ(simulatePoses(other, poses, dir).simulated, 2u);
}

TEST(ClothPoseDriver, PoseFileRoundTripsAndRejectsGarbage) {
  SimulatedPoseRecord rec;
  rec.poseId = 42;
  rec.fingerprint = 0x1234'5678'9abc'def0ull;
  rec.result.ok = true;
  rec.result.positions = Points3f::Random(17, 3);
  rec.result.residuals.maxConstraintViolation = 0.03f;
  rec.result.residuals.maxPenetration = 0.001f;
  rec.result.residuals.converged = true;
  rec.result.residuals.iterations = 360;
  const test::TempDir tmp("cloth_file");
  const fs::path dir = tmp.path();
  const fs::path file = simulatedPosePath(dir, 42);
  EXPECT_EQ(file.filename(), "pose_000042.clothsim");
  writeSimulatedPose(file, rec);
  const SimulatedPoseRecord back = readSimulatedPose(file);
  EXPECT_EQ(back.poseId, 42u);
  EXPECT_EQ(back.fingerprint, rec.fingerprint);
  EXPECT_TRUE(sameBits(back.result.positions, rec.result.positions));
  EXPECT_EQ(back.result.residuals.iterations, 360);
  EXPECT_TRUE(back.result.residuals.converged);
  // Truncated and foreign files give an Error naming the file.
  fs::resize_file(file, fs::file_size(file) - 5);
  try {
    readSimulatedPose(file);
    FAIL() << "truncated file accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("pose_000042"), std::string::npos) << e.what();
  }
  std::ofstream(file, std::ios::binary) << "not a pose file at all";
  EXPECT_THROW(readSimulatedPose(file), Error);
}

// A cluster shard simulates only its ids (swish/cluster/): the same bytes as the whole run, nothing else
// written, and a header-only read (swish bake --status) agrees with the full one.
TEST(ClothPoseDriver, ShardOfIdsMatchesTheWholeRun) {
  const Character ch = test::capsuleCharacter();
  const ClothSolver solver(ch, buildSimulationMesh(ch, 0), fastSettings());
  const std::vector<Pose> poses = somePoses(ch.skeleton, 5);
  const test::TempDir tmp("cloth_shard");
  simulatePoses(solver, poses, tmp / "whole", {}, 1);
  const PoseSimulationRun shard = simulatePoses(solver, poses, {1, 3}, tmp / "shard", {}, 1);
  EXPECT_EQ(shard.simulated, 2u);
  for (uint32_t id = 0; id < 5; ++id) {
    const fs::path f = simulatedPosePath(tmp / "shard", id);
    EXPECT_EQ(fs::exists(f), id == 1 || id == 3) << id;
    if (!fs::exists(f)) continue;
    const SimulatedPoseRecord a = readSimulatedPose(f), b = readSimulatedPose(simulatedPosePath(tmp / "whole", id));
    EXPECT_TRUE(sameBits(a.result.positions, b.result.positions)) << id;
    const auto head = peekSimulatedPose(f);
    ASSERT_TRUE(head.has_value());
    EXPECT_EQ(head->poseId, id);
    EXPECT_EQ(head->fingerprint, a.fingerprint);
    EXPECT_EQ(head->ok, a.result.ok);
    EXPECT_EQ(head->seconds, a.result.residuals.seconds);
  }
  EXPECT_EQ(simulatePoses(solver, poses, {1, 3}, tmp / "shard", {}, 1).reused, 2u);
  EXPECT_THROW(simulatePoses(solver, poses, {5}, tmp / "shard"), Error);
  EXPECT_FALSE(peekSimulatedPose(tmp / "none.clothsim").has_value());
}
