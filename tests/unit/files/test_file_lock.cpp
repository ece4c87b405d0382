// FileLock (files/file_lock.hpp): one holder at a time, within a process and across processes; the one
// refused or waiting learns who holds it; a holder that dies, even by SIGKILL, lets go.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>

#include "support/error_message.hpp"
#include "support/temp_dir.hpp"
#include "swish/files/file_lock.hpp"

namespace {

using swish::FileLock;

TEST(FileLock, OneHolderAtATimeAndTheRefusedOneLearnsWho) {
  const swish::test::TempDir tmp;
  const auto file = tmp.path() / "part1.lock";
  std::optional<FileLock> a = FileLock::acquire(file, "bake 'first'");
  ASSERT_TRUE(a->held()) << a->unsupportedReason();
  std::string holder;
  EXPECT_FALSE(FileLock::tryAcquire(file, "bake 'second'", &holder).has_value());
  EXPECT_NE(holder.find("pid " + std::to_string(::getpid()) + " on "), std::string::npos) << holder;
  EXPECT_NE(holder.find("bake 'first'"), std::string::npos) << holder;
  a.reset();
  std::optional<FileLock> b = FileLock::tryAcquire(file, "bake 'second'", &holder);
  ASSERT_TRUE(b.has_value());
  EXPECT_TRUE(b->held());
  EXPECT_TRUE(std::filesystem::exists(file));  // left in place
}

TEST(FileLock, AcquireWaitsUntilTheHolderLetsGo) {
  const swish::test::TempDir tmp;
  const auto file = tmp.path() / "part1.lock";
  std::optional<FileLock> a = FileLock::acquire(file, "holder");
  std::atomic<bool> waiting{false}, acquired{false};
  std::string toldHolder;
  std::thread t([&] {
    FileLock b = FileLock::acquire(file, "waiter", [&](const std::string& who) {
      toldHolder = who;
      waiting = true;
    });
    acquired = b.held();
  });
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!waiting && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(waiting.load());
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  EXPECT_FALSE(acquired.load());  // still waiting while the first holds it
  a.reset();
  t.join();
  EXPECT_TRUE(acquired.load());
  EXPECT_NE(toldHolder.find("holder"), std::string::npos) << toldHolder;
}

TEST(FileLock, AKilledHolderLetsGo) {
  const swish::test::TempDir tmp;
  const auto file = tmp.path() / "part1.lock";
  int ready[2];
  ASSERT_EQ(::pipe(ready), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(ready[0]);
    FileLock l = FileLock::acquire(file, "child");
    const char c = l.held() ? 'y' : 'n';
    [[maybe_unused]] const ssize_t n = ::write(ready[1], &c, 1);
    for (;;) ::pause();  // until killed: the lock is never released by the program
  }
  ::close(ready[1]);
  char c = 0;
  ASSERT_EQ(::read(ready[0], &c, 1), 1);
  ::close(ready[0]);
  ASSERT_EQ(c, 'y');
  std::string holder;
  EXPECT_FALSE(FileLock::tryAcquire(file, "parent", &holder).has_value());
  EXPECT_NE(holder.find("pid " + std::to_string(child) + " "), std::string::npos) << holder;
  ::kill(child, SIGKILL);
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(FileLock::tryAcquire(file, "parent").has_value());
}

TEST(FileLock, AFolderThatIsNotThereIsAClearError) {
  const swish::test::TempDir tmp;
  const auto file = tmp.path() / "missing" / "part1.lock";
  const std::string e = swish::test::errorOf([&] { FileLock::acquire(file, "x"); });
  EXPECT_NE(e.find(file.string()), std::string::npos) << e;
  EXPECT_NE(e.find("cannot open the lock file"), std::string::npos) << e;
}

}  // namespace
