// The character a model was baked on, found again from its metadata: `swish replay --truth-every`
// rebuilds the simulation on it and `swish render` draws its body. A missing file is an error that names
// it and the option to pass, never the garment drawn on another body.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "support/error_message.hpp"
#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/pipeline/baked_character.hpp"

using namespace swish;
using namespace swish::bake;

namespace {
std::string metadataNaming(const nlohmann::json& character) {
  return nlohmann::json{{"dataset_settings", {{"character", character}, {"input_joints", {"Spine", "Spine1"}}}}}.dump();
}
}  // namespace

TEST(BakedCharacter, MetadataWithoutBakeSettingsIsUnknownAndDrawsTheDefaultSayingSo) {
  for (const std::string meta : {"{}", "not json", R"({"dataset_settings": 3})"}) {
    const BakedCharacter b = findBakedCharacter(meta, "model.swish");
    EXPECT_EQ(b.kind, BakedCharacter::Kind::Unknown) << meta;
    EXPECT_FALSE(b.available());
    EXPECT_NE(b.problem.find("dataset_settings"), std::string::npos) << b.problem;
  }
  std::string label;
  const Character c = characterToDraw("auto", "{}", "model.swish", label);
  EXPECT_EQ(c.name, makeDefaultCharacter().name);
  EXPECT_NE(label.find("names no bake character"), std::string::npos) << label;
}

TEST(BakedCharacter, EmptyCharacterIsTheEmbeddedDefault) {
  const BakedCharacter b = findBakedCharacter(metadataNaming({{"file", ""}, {"recipe", ""}}), "m.swish");
  EXPECT_EQ(b.kind, BakedCharacter::Kind::EmbeddedDefault);
  EXPECT_TRUE(b.available());
  EXPECT_EQ(b.settings.inputJoints, (std::vector<std::string>{"Spine", "Spine1"}));
  std::string label;
  const Character c = characterToDraw("auto", metadataNaming({{"file", ""}}), "m.swish", label);
  EXPECT_EQ(c.garment.vertexCount(), makeDefaultCharacter().garment.vertexCount());
  EXPECT_NE(label.find("baked on"), std::string::npos) << label;
}

TEST(BakedCharacter, FilesAreFoundAsWrittenOrBesideTheModel) {
  const test::TempDir dir("baked_character");
  const auto recipe = test::sourceDir() / "assets/default/recipe.json";
  std::filesystem::copy_file(recipe, dir / "recipe.json");
  // As written (absolute), and relative names beside the model.
  EXPECT_EQ(findBakedCharacter(metadataNaming({{"recipe", recipe.string()}}), dir / "m.swish").settings.characterRecipe,
            recipe);
  const BakedCharacter beside = findBakedCharacter(metadataNaming({{"recipe", "recipe.json"}}), dir / "m.swish");
  EXPECT_EQ(beside.kind, BakedCharacter::Kind::Recipe);
  EXPECT_TRUE(beside.available()) << beside.problem;
  EXPECT_EQ(beside.settings.characterRecipe, dir / "recipe.json");
  std::string label;
  characterToDraw("auto", metadataNaming({{"recipe", "recipe.json"}}), dir / "m.swish", label);
  EXPECT_NE(label.find("recipe.json"), std::string::npos) << label;
}

TEST(BakedCharacter, AMissingCharacterFileIsAnErrorNamingItAndTheOption) {
  const std::string meta = metadataNaming({{"file", "no/such/character.glb"}, {"body_mesh", {"Body"}}});
  const BakedCharacter b = findBakedCharacter(meta, "/nowhere/m.swish");
  EXPECT_EQ(b.kind, BakedCharacter::Kind::File);
  EXPECT_FALSE(b.available());
  EXPECT_EQ(b.named, "no/such/character.glb");
  EXPECT_EQ(b.settings.bodyMeshNames, std::vector<std::string>{"Body"});
  std::string label;
  const std::string err = test::errorOf([&] { characterToDraw("auto", meta, "/nowhere/m.swish", label); });
  EXPECT_NE(err.find("no/such/character.glb"), std::string::npos) << err;
  EXPECT_NE(err.find("--character"), std::string::npos) << err;
  EXPECT_NE(err.find("/nowhere/m.swish"), std::string::npos) << err;
  // An explicit choice is honoured whatever the metadata says.
  const Character d = characterToDraw("default", meta, "/nowhere/m.swish", label);
  EXPECT_EQ(d.name, makeDefaultCharacter().name);
  EXPECT_EQ(label, "the embedded default mannequin");
}
