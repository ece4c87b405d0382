#pragma once
// Where tests find data that lives outside the project.
#include <cstdlib>
#include <filesystem>
#include <string>

namespace swish::test {

// ../shared/assets beside the project (the CC0 test character). Tests that need it skip when absent:
//   if (!std::filesystem::exists(sharedAsset("tshirt_lo.glb"))) GTEST_SKIP() << "...";
inline std::filesystem::path sharedAsset(const std::string& name) {
  return std::filesystem::path(SWISH_SHARED_ASSETS_DIR) / name;
}
// The project's source folder (assets/, docs/): where it was built, unless SWISH_SOURCE_DIR says where a
// copy is (tools/bundle.sh runs the benchmarks away from the build).
inline std::filesystem::path sourceDir() {
  if (const char* e = std::getenv("SWISH_SOURCE_DIR"); e && *e) return e;
  return SWISH_SOURCE_DIR;
}
// ../shared/mocap beside the project (the CMU motion corpus: cmu/, cmu-daz/, each with index.tsv).
inline std::filesystem::path sharedMocap(const std::string& name = "") {
  return std::filesystem::path(SWISH_SHARED_ASSETS_DIR).parent_path() / "mocap" / name;
}
// The CMU clips of Debian's assimp-testmodels package.
inline std::filesystem::path debianMocap(const std::string& name) {
  return std::filesystem::path("/usr/share/assimp/models/BVH") / name;
}

}  // namespace swish::test
