// The .swish model file and atomic writes: round trips, truncation, corruption, hostile counts,
// version handling, and that a failed save never damages an existing file.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "swish/core/error.hpp"
#include "swish/model/atomic_write.hpp"

namespace fs = std::filesystem;

namespace {

// A fresh, empty folder per test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() /
            ("swish_test_model_file_" + std::to_string(::getpid()) + "_" + info->test_suite_name() + "_" + info->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }
  fs::path operator/(const std::string& name) const { return path_ / name; }
  // Everything in the folder, to see that no temporary file was left behind.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(path_)) names.push_back(e.path().filename().string());
    return names;
  }

 private:
  fs::path path_;
};

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace

TEST(AtomicWrite, WritesNewFileAndReplacesExistingOne) {
  TempDir dir;
  const fs::path target = dir / "out.txt";
  swish::writeTextFileAtomic(target, "first");
  EXPECT_EQ(readText(target), "first");
  swish::writeTextFileAtomic(target, "second, longer content");
  EXPECT_EQ(readText(target), "second, longer content");
  const std::vector<uint8_t> bytes = {0, 1, 2, 255, 0};
  swish::writeFileAtomic(target, bytes);
  EXPECT_EQ(readText(target), std::string("\0\1\2\xff\0", 5));
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"out.txt"});
}

TEST(AtomicWrite, StreamAndRawWritesKeepTheirOrder) {
  TempDir dir;
  const fs::path target = dir / "mixed.bin";
  swish::AtomicFileWriter w(target);
  w.stream() << "ab";
  const std::vector<uint8_t> mid = {'c', 'd'};
  w.write(mid);
  w.stream() << "ef" << 12;
  EXPECT_FALSE(fs::exists(target)) << "nothing may appear at the target before commit";
  w.commit();
  EXPECT_EQ(readText(target), "abcdef12");
}

TEST(AtomicWrite, LargeStreamedOutputArrivesWhole) {
  TempDir dir;
  const fs::path target = dir / "large.txt";
  std::string expected;
  swish::writeFileAtomicWith(target, [&](std::ostream& os) {
    for (int i = 0; i < 50000; ++i) {
      const std::string line = "line " + std::to_string(i) + "\n";
      os << line;
      expected += line;
    }
  });
  EXPECT_EQ(readText(target), expected);
}

TEST(AtomicWrite, ThrowingWriterLeavesOldFileAndNoTemporary) {
  TempDir dir;
  const fs::path target = dir / "keep.txt";
  swish::writeTextFileAtomic(target, "precious");
  EXPECT_THROW(swish::writeFileAtomicWith(target,
                                          [](std::ostream& os) {
                                            os << "half written";
                                            throw swish::Error("writer gave up");
                                          }),
               swish::Error);
  EXPECT_EQ(readText(target), "precious");
  EXPECT_EQ(dir.entries(), std::vector<std::string>{"keep.txt"});
}

TEST(AtomicWrite, UncommittedWriterDiscardsItsTemporary) {
  TempDir dir;
  const fs::path target = dir / "never.txt";
  {
    swish::AtomicFileWriter w(target);
    w.stream() << "abandoned";
    EXPECT_TRUE(fs::exists(w.temporaryPath()));
  }
  EXPECT_TRUE(dir.entries().empty());
}

TEST(AtomicWrite, ErrorsNameThePathAndTheReason) {
  TempDir dir;
  // The parent "folder" is a regular file: creating the temporary fails with ENOTDIR, even as root.
  swish::writeTextFileAtomic(dir / "plain", "x");
  try {
    swish::writeTextFileAtomic(dir / "plain" / "child.txt", "y");
    FAIL() << "expected an Error";
  } catch (const swish::Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("child.txt"), std::string::npos) << msg;
    EXPECT_NE(msg.find("Not a directory"), std::string::npos) << msg;
  }
  // Missing folder.
  EXPECT_THROW(swish::writeTextFileAtomic(dir / "missing" / "a.txt", "y"), swish::Error);
  // The target is a folder: refused before anything is written, and the folder survives.
  fs::create_directory(dir / "sub");
  try {
    swish::writeTextFileAtomic(dir / "sub", "y");
    FAIL() << "expected an Error";
  } catch (const swish::Error& e) {
    EXPECT_NE(std::string(e.what()).find("directory"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::is_directory(dir / "sub"));
  EXPECT_EQ(readText(dir / "plain"), "x");
}
