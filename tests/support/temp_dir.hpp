#pragma once
// TempDir: a fresh, empty folder for one test, removed with everything in it when it goes out of scope.
//   const test::TempDir tmp("png");
//   io::writePng(tmp / "a.png", image);
#include <gtest/gtest.h>
#include <stdlib.h>  // mkdtemp

#include <cctype>
#include <cerrno>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

namespace swish::test {

class TempDir {
 public:
  // Creates <system temp dir>/swish_<tag>_XXXXXX (mkdtemp: unique, so parallel test processes and
  // several TempDirs in one test never share a folder). Throws std::system_error if it cannot.
  explicit TempDir(const std::string& tag) {
    std::string safe = tag;
    for (char& c : safe)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
    std::string name = (std::filesystem::temp_directory_path() / ("swish_" + safe + "_XXXXXX")).string();
    if (::mkdtemp(name.data()) == nullptr)
      throw std::system_error(errno, std::generic_category(), "cannot create a temporary folder " + name);
    path_ = name;
  }
  // Named after the running test: swish_<suite>_<test>_XXXXXX.
  TempDir() : TempDir(currentTestName()) {}
  ~TempDir() {
    std::error_code ec;  // never throw from a destructor; a folder left behind is not worth a crash
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::filesystem::path& name) const { return path_ / name; }

  // The names of everything directly in the folder, e.g. to see that no temporary file was left behind.
  std::vector<std::string> entries() const {
    std::vector<std::string> names;
    for (const auto& e : std::filesystem::directory_iterator(path_)) names.push_back(e.path().filename().string());
    return names;
  }

 private:
  static std::string currentTestName() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    return info ? std::string(info->test_suite_name()) + "_" + info->name() : "test";
  }

  std::filesystem::path path_;
};

}  // namespace swish::test
