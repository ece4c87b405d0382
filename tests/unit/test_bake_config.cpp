// The bake recipe is validated before any work: unknown keys and out-of-range values are errors that
// name the key; defaults fill what is absent; paths resolve against the config's folder.
#include <gtest/gtest.h>

#include "swish/bake/bake_config.hpp"
#include "swish/core/error.hpp"

using namespace swish;
using namespace swish::bake;

namespace {
std::string errorOf(const nlohmann::json& j) {
  try {
    parseBakeConfig(j, "recipe.json", "/base");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(BakeConfig, DefaultsAndPaths) {
  const BakeConfig c = parseBakeConfig({{"name", "jersey"}, {"output", "out"}, {"train", {{"codebook_size", 2048}}}},
                                       "recipe.json", "/base");
  EXPECT_EQ(c.modelPath(), std::filesystem::path("/base/out/jersey.swish"));
  EXPECT_EQ(c.dataset, std::filesystem::path("/base/out/dataset"));
  EXPECT_EQ(c.train.vq.codebookSize, 2048u);
  EXPECT_EQ(c.train.mlp.hiddenLayers, 5);
  EXPECT_EQ(c.train.mlp.hiddenWidth, 32);
  EXPECT_EQ(c.train.databaseSize, 128);
}

TEST(BakeConfig, ErrorsNameTheKey) {
  EXPECT_NE(errorOf({{"output", "o"}, {"colour", 1}}).find("colour: unknown key"), std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"codebook_size", 70000}}}}).find("train.codebook_size: 70000 is outside"),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"hidden_layerz", 3}}}}).find("train.hidden_layerz: unknown key"),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"max_epochs", 1.5}}}}).find("train.max_epochs: must be an integer"),
            std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"activation", "relu"}}}}).find("train.activation"), std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"train", {{"learning_rate", "fast"}}}}).find("train.learning_rate: must be a number"),
            std::string::npos);
  EXPECT_NE(errorOf({{"name", "../x"}, {"output", "o"}}).find("name"), std::string::npos);
  EXPECT_NE(errorOf({{"name", "x"}}).find("output: is required"), std::string::npos);
  EXPECT_NE(errorOf(nlohmann::json::array()).find("must be a JSON object"), std::string::npos);
  EXPECT_NE(errorOf({{"output", "o"}, {"part1", 3}}).find("part1: must be a JSON object"), std::string::npos);
}

TEST(BakeConfig, MissingFileIsAClearError) {
  EXPECT_THROW(loadBakeConfig("/nonexistent/recipe.json"), Error);
}
