#pragma once
// The recipe of the embedded default character: every number that shapes it (skeleton joint heads,
// the swept-ellipse body parts, the jersey's cut). Committed as assets/default/recipe.json; the same
// text is compiled into the library (embeddedDefaultRecipeJson) so that the default character needs no
// file at run time. A unit test checks that the two are identical.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/core/types.hpp"

namespace swish {
class JsonReader;
}

namespace swish::bake {

struct RecipeJoint {
  std::string name, parent;  // parent "" for the root
  Vec3f head;                // world position of the joint in the A-pose
};

// One cross-section of a body part: an ellipse around the part's axis. Its centre is either given
// ("center") or a joint head plus an offset ("at" + "offset").
struct RecipeStation {
  std::string joint;  // the joint that skins this cross-section
  Vec3f center = Vec3f::Zero();
  std::string at;  // when not empty: center = head(at) + offset
  Vec3f offset = Vec3f::Zero();
  float halfWidth = 0, halfDepth = 0;
};

struct RecipePart {
  std::string name;
  bool mirror = false;  // also build the x-mirrored copy (Left -> Right names)
  int ringsPerSpan = 4;
  int segments = 16;
  std::vector<RecipeStation> stations;
};

// Extra skinning influence around a point (shoulders, hips), falling off over `radius`.
struct RecipeBlend {
  std::string joint, at;
  Vec3f offset = Vec3f::Zero();
  float radius = 0.1f;
  bool mirror = false;
};

struct RecipeJersey {
  float offset = 0.015f;    // distance of the cloth from the body's cross-sections
  float clearance = 0.01f;  // no cloth vertex closer to any body part than this
  int columns = 72, rows = 34;
  float hemY = 0.93f, collarY = 1.505f;
  float armholeBottomY = 1.31f, armholeTopY = 1.485f, armholeHalfWidth = 0.075f;
  float sleeveLength = 0.17f;
  int sleeveRings = 8;
  int skinTransferNeighbours = 4;
  // Sweeps of neighbour averaging over the jersey after the transfer: nearest body vertices switch
  // from arm to torso between neighbouring jersey vertices in the armpit, and skinning alone then
  // stretched an armpit edge by 340% when the arms came down.
  int skinSmoothingIterations = 40;
  int maxInfluences = 4;
};

struct DefaultCharacterRecipe {
  std::string name;
  bool mirrorSkeleton = true;
  std::vector<RecipeJoint> joints;
  std::vector<RecipePart> parts;
  std::vector<RecipeBlend> blends;
  RecipeJersey jersey;
};

// Reads a recipe (assets/default/recipe.json shows every key). Strict: an unknown key is an error listing
// the keys allowed there, numbers must be JSON numbers (not true or "1"), counts whole numbers,
// "center" and "offset" of a station go without and with "at". Errors are "<what>: <json.path>: <problem>"
// (files/json_reader.hpp), with the joint or body part they concern where the path alone does not say it:
//   "recipe.json: body.parts[2].segments: must be 6 to 256, is 3 (body part 'LeftArmPart')"
//   "recipe.json: jersey.offset: -1 is outside 0.001..0.1"
// for missing keys, wrong types, non-finite or out-of-range values and unknown joint references.
// "body.ringSegments" is read and checked like a part's "segments" (6..256) but not used.
DefaultCharacterRecipe parseDefaultCharacterRecipe(const JsonReader& recipe);
DefaultCharacterRecipe parseDefaultCharacterRecipe(const nlohmann::json& j, const std::string& what);
DefaultCharacterRecipe loadDefaultCharacterRecipe(const std::filesystem::path& file);
const char* embeddedDefaultRecipeJson();
DefaultCharacterRecipe embeddedDefaultRecipe();

}  // namespace swish::bake
