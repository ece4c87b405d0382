// The pose driver: parallel, deterministic, resumable; per-pose files written atomically.
#include <gtest/gtest.h>

#include <algorithm>
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
  return a.rows() == b.rows() &&
         (a.size() == 0 || std::memcmp(a.data(), b.data(), sizeof(float) * size_t(a.size())) == 0);
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
  // Another carry: likewise (the shapes differ; the skinning carry keeps the fingerprint it always had).
  ClothSimSettings translated = fastSettings();
  translated.carry = ClothCarry::Translation;
  const ClothSolver third(ch, buildSimulationMesh(ch, 0), translated);
  EXPECT_NE(third.fingerprint(), solver.fingerprint());
  EXPECT_EQ(simulatePoses(third, poses, dir).simulated, 2u);
}

TEST(ClothPoseDriver, RetrySettingsKeepFirstAttemptResults) {
  const Character ch = test::capsuleCharacter();
  ClothSimSettings skinningRetry = fastSettings();
  skinningRetry.retryCarries = {ClothCarry::Skinning};  // as bakes before the setting retried
  skinningRetry.saferPathRetries = false;               // and before the safer paths
  const ClothSolver solver(ch, buildSimulationMesh(ch, 0), skinningRetry);
  const std::vector<Pose> poses = somePoses(ch.skeleton, 2);
  const test::TempDir tmp("cloth_retry_settings");
  const fs::path dir = tmp / "retry";
  const PoseSimulationRun first = simulatePoses(solver, poses, dir);
  ASSERT_EQ(first.failed, 0u);
  // Pose 1 as if it had needed a retry: its shape depends on the retry settings.
  SimulatedPoseRecord rec = readSimulatedPose(simulatedPosePath(dir, 1));
  ASSERT_EQ(rec.result.attempts, 1);
  rec.result.attempts = 2;
  rec.result.firstFailure = "the solve exploded (test)";
  writeSimulatedPose(simulatedPosePath(dir, 1), rec);
  // Other retry carries: only the first attempt's digest stays; pose 0 (solved on its first attempt)
  // is reused, pose 1 is simulated again.
  ClothSimSettings retried = fastSettings();
  retried.retryCarries = {ClothCarry::Skinning, ClothCarry::Translation};
  const ClothSolver other(ch, buildSimulationMesh(ch, 0), retried);
  EXPECT_NE(other.fingerprint(), solver.fingerprint());
  EXPECT_EQ(other.firstAttemptFingerprint(), solver.fingerprint());
  EXPECT_TRUE(loadFinishedPose(dir, 0, other, poses[0]));
  EXPECT_FALSE(loadFinishedPose(dir, 1, other, poses[1]));
  EXPECT_FALSE(loadFinishedPose(dir, 0, poseFingerprint(other, poses[0])));  // not by the full digest
  const PoseSimulationRun again = simulatePoses(other, poses, dir);
  EXPECT_EQ(again.reused, 1u);
  EXPECT_EQ(again.simulated, 1u);
  // Written under the full digest, found by it.
  EXPECT_TRUE(loadFinishedPose(dir, 1, poseFingerprint(other, poses[1])));
  EXPECT_EQ(simulatePoses(other, poses, dir).simulated, 0u);
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
  rec.result.residuals.equilibriumResidual = 0.004f;
  rec.result.residuals.equilibriumResidualMax = 0.05f;
  rec.result.residuals.equilibriumFrames = 7;
  rec.result.residuals.projectedDepth = 0.002f;
  rec.result.attempts = 2;
  rec.result.firstFailure = "the solve exploded at frame 3";
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
  EXPECT_EQ(back.result.residuals.equilibriumResidual, 0.004f);
  EXPECT_EQ(back.result.residuals.equilibriumResidualMax, 0.05f);
  EXPECT_EQ(back.result.residuals.equilibriumFrames, 7);
  EXPECT_EQ(back.result.residuals.projectedDepth, 0.002f);
  EXPECT_EQ(back.result.attempts, 2);
  EXPECT_EQ(back.result.firstFailure, rec.result.firstFailure);
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

// The report's simulation figures: failures per reason with their share, the retried poses, the
// seconds per pose per core and the equilibrium residuals.
TEST(ClothPoseDriver, SimulationReportCountsFailuresPerReasonAndRetries) {
  EXPECT_EQ(failureCategory("the solve exploded at frame 26: 26 of 19482 edges"), "explosion");
  EXPECT_EQ(failureCategory("the garment ends 0.0104 m inside the body (bound 0.01 m)"), "penetration");
  EXPECT_EQ(failureCategory("after 2 attempts (...): the garment ends 0.02 m inside the body; first attempt: the "
                            "solve exploded at frame 3"),
            "penetration");
  EXPECT_EQ(failureCategory("transfer: no triangle"), "transfer");
  std::vector<SimulatedPoseSummary> poses(10);
  for (uint32_t i = 0; i < 10; ++i) {
    poses[i].id = i;
    poses[i].ok = true;
    poses[i].residuals.seconds = 1.0 + i;  // mean 5.5
    poses[i].residuals.equilibriumResidual = 0.001f * float(i);
  }
  poses[3].ok = false;
  poses[3].failure = "the solve exploded at frame 9";
  poses[4].attempts = 2;
  poses[4].firstFailure = "the garment ends 0.011 m inside the body";
  ClothSimSettings s;
  s.equilibriumTolerance = 0.0075f;
  const nlohmann::json j = simulationRunJson(poses, s, {{7, "transfer: no triangle"}});
  EXPECT_EQ(j.at("failed"), 2);
  EXPECT_DOUBLE_EQ(j.at("failures_by_reason").at("explosion").at("share").get<double>(), 0.1);
  EXPECT_EQ(j.at("failures_by_reason").at("transfer").at("count"), 1);
  EXPECT_EQ(j.at("retried_poses"), 1);
  EXPECT_EQ(j.at("retried")[0].at("pose"), 4);
  EXPECT_DOUBLE_EQ(j.at("seconds_per_pose_per_core").get<double>(), 5.5);
  EXPECT_EQ(j.at("poses_not_at_equilibrium"), 2);  // 0.008 and 0.009 of the 9 kept
  // The sample is seeded: the same seed the same poses, ascending, without repeats.
  std::vector<uint32_t> ids(100);
  for (uint32_t i = 0; i < 100; ++i) ids[i] = 2 * i;
  const std::vector<uint32_t> a = sampleQualityPoses(ids, 8, 3), b = sampleQualityPoses(ids, 8, 3);
  EXPECT_EQ(a, b);
  EXPECT_TRUE(std::is_sorted(a.begin(), a.end()));
  EXPECT_EQ(std::adjacent_find(a.begin(), a.end()), a.end());
  EXPECT_NE(a, sampleQualityPoses(ids, 8, 4));
  EXPECT_EQ(sampleQualityPoses(ids, 500, 1).size(), 100u);
}
