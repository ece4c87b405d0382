// Writes the seed corpus of the .swish loader fuzzer: serialized random models of several shapes
// (small ones, since the fuzzer mutates small inputs fastest), plus a file of a newer minor version
// carrying a section this reader does not know. Run at build time:
//   swish_fuzz_seed_generator OUTPUT_DIR
#include <cstdio>
#include <exception>
#include <filesystem>
#include <string>

#include "support/random_model.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/files/byte_writer.hpp"
#include "swish/files/crc32.hpp"
#include "swish/model/model_file.hpp"

namespace {

// The same model with a "NEWS" section appended and the minor version raised by one.
std::vector<uint8_t> withFutureSection(const std::vector<uint8_t>& file) {
  const auto info = swish::readModelFileInfo(file, "seed");
  swish::ByteWriter payload;
  payload.text("a section a later minor version adds");
  swish::ByteWriter w;
  w.bytes(std::span<const uint8_t>(file.data(), 8));
  w.u16(swish::kModelFileMajorVersion);
  w.u16(uint16_t(swish::kModelFileMinorVersion + 1));
  w.u32(uint32_t(info.sections.size() + 1));
  w.u64(file.size() + swish::kModelSectionHeaderBytes + payload.size());
  w.u32(0);
  w.u32(swish::crc32(std::span<const uint8_t>(w.data().data(), 28)));
  w.bytes(
      std::span<const uint8_t>(file.data() + swish::kModelFileHeaderBytes, file.size() - swish::kModelFileHeaderBytes));
  w.text("NEWS");
  w.u64(payload.size());
  w.u32(swish::crc32(payload.data()));
  w.bytes(payload.data());
  return w.take();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR\n", argv[0]);
    return 2;
  }
  try {
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    using swish::test::RandomModelSpec;
    auto small = [] {
      RandomModelSpec s;
      s.joints = 3;
      s.inputJoints = 2;
      s.vertices = 6;
      s.influences = 2;
      s.meshComponents = 2;
      s.hiddenLayers = 1;
      s.hiddenWidth = 3;
      s.normalMaps = 2;
      s.codeDims = 2;
      s.mapSize = 4;
      s.codebookSize = 2;
      return s;
    };
    std::vector<std::pair<std::string, RandomModelSpec>> shapes;
    shapes.push_back({"small", small()});
    RandomModelSpec s = small();
    s.normalMaps = 0;
    shapes.push_back({"no_normal_maps", s});
    s = small();
    s.vertices = 1;
    shapes.push_back({"one_vertex", s});
    s = small();
    s.influences = 8;
    s.joints = 9;
    shapes.push_back({"eight_influences", s});
    s = small();
    s.hiddenLayers = 0;
    shapes.push_back({"linear_mlp", s});
    s = small();
    s.bodyAnchors = true;
    shapes.push_back({"body_anchors", s});
    s.secondAnchors = true;
    shapes.push_back({"second_anchors", s});
    s.thirdAnchors = true;
    shapes.push_back({"third_anchors", s});
    s = small();
    s.noveltyCentres = 3;
    shapes.push_back({"novelty_guard", s});
    s = small();
    s.vertices = 20;
    s.mapSize = 8;
    s.codebookSize = 5;
    s.hiddenLayers = 3;
    shapes.push_back({"medium", s});
    swish::Rng rng(0xF022);
    std::vector<uint8_t> first;
    for (const auto& [name, spec] : shapes) {
      swish::Model m = swish::test::makeRandomModel(rng, spec);
      if (name == "novelty_guard") m.bodyCoverage = {7, {0, 3, 6}};  // format 1.2's other section filled too
      const auto bytes = swish::serializeModel(m);
      if (first.empty()) first = bytes;
      swish::writeFileAtomic(dir / ("seed_" + name + ".swish"), bytes);
    }
    swish::writeFileAtomic(dir / "seed_future_minor_version.swish", withFutureSection(first));
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "swish_fuzz_seed_generator: %s\n", e.what());
    return 1;
  }
}
