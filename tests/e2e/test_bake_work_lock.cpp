// Two bakes that share a work folder (part 2 variants of one dataset) take turns at part 1: the second
// waits while another holds <work>/part1.lock, says who holds it, and builds (or finds) the dataset once
// the first lets go. Without the lock both walked part 1 at once and rewrote its manifest and pose files.
//
// Small recipe: the default character, 3 thinned poses of CMU 01_01 plus the rest pose, the game mesh as
// the simulation mesh, a short transition, part 1 only: a few seconds on two cores.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/pipeline/bake_pipeline.hpp"
#include "swish/files/file_lock.hpp"

using namespace swish;
using namespace swish::bake;
namespace fs = std::filesystem;

namespace {

TEST(BakeWorkLock, ASecondPart1OnTheSameWorkFolderWaitsForTheFirst) {
  const fs::path clip = test::debianMocap("01_01.bvh");
  if (!fs::exists(clip)) GTEST_SKIP() << clip << " is missing (Debian's assimp-testmodels)";
  const test::TempDir tmp;
  const nlohmann::json recipe = {
      {"name", "locked"},
      {"output", "out"},
      {"work", "work"},
      {"part1",
       {{"character", "default"},
        {"clips", {clip.string()}},
        {"thinning", {{"target_poses", 3}}},
        {"simulation",
         {{"vertices", 0}, {"transition_seconds", 0.2}, {"settle_seconds", 0.1}, {"frame_rate", 20}, {"threads", 2}}},
        {"normal_maps", {{"size", 16}, {"dilation_rings", 2}}},
        {"preview", {{"poses", 0}}}}}};
  const BakeConfig cfg = parseBakeConfig(recipe, "locked.json", tmp.path());
  fs::create_directories(cfg.work);
  std::optional<FileLock> other = FileLock::acquire(cfg.work / "part1.lock", "another bake's part 1");
  ASSERT_TRUE(other->held()) << other->unsupportedReason();

  std::mutex m;
  std::vector<std::string> lines;
  std::atomic<bool> done{false};
  BakeRunOptions o;
  o.part2 = false;
  o.log = [&](const std::string& l) {
    const std::lock_guard g(m);
    lines.push_back(l);
  };
  std::thread bake([&] {
    runBake(cfg, o);
    done = true;
  });
  auto waitingLine = [&] {
    const std::lock_guard g(m);
    for (const std::string& l : lines)
      if (l.find("part 1: waiting for pid ") != std::string::npos) return l;
    return std::string();
  };
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (waitingLine().empty() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const std::string waiting = waitingLine();
  EXPECT_NE(waiting.find("another bake's part 1"), std::string::npos) << waiting;
  EXPECT_NE(waiting.find((cfg.work / "part1.lock").string()), std::string::npos) << waiting;
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(done.load());
  EXPECT_FALSE(fs::exists(cfg.dataset / "manifest.json"));  // nothing of part 1 done while it waits
  other.reset();
  bake.join();
  EXPECT_TRUE(done.load());
  EXPECT_TRUE(fs::exists(cfg.dataset / "manifest.json"));
  // Released at the end of part 1: a third bake takes the lock at once.
  EXPECT_TRUE(FileLock::tryAcquire(cfg.work / "part1.lock", "third").has_value());
}

}  // namespace
