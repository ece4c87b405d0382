#include "swish/bake/character/default_character_recipe.hpp"

#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

#include "swish/core/error.hpp"
#include "swish/core/skeleton.hpp"
#include "swish/files/json_file.hpp"
#include "swish/files/json_reader.hpp"

namespace swish::bake {
namespace {

// Byte-for-byte the committed assets/default/recipe.json (test_default_character checks it).
constexpr const char* kEmbeddedRecipe = R"recipe({
  "format": "swish-default-character-recipe",
  "version": 1,
  "name": "swish_default_mannequin",
  "units": "metres, Y up, faces +Z, feet at y = 0, rest pose: A-pose (upper arms 50 degrees below horizontal)",
  "skeleton": {
    "mirror": true,
    "joints": [
      {"name": "Hips", "parent": "", "head": [0.0, 0.98, 0.0]},
      {"name": "LHipJoint", "parent": "Hips", "head": [0.0, 0.98, 0.0]},
      {"name": "LeftUpLeg", "parent": "LHipJoint", "head": [0.095, 0.93, 0.0]},
      {"name": "LeftLeg", "parent": "LeftUpLeg", "head": [0.105, 0.51, 0.01]},
      {"name": "LeftFoot", "parent": "LeftLeg", "head": [0.115, 0.09, -0.02]},
      {"name": "LeftToeBase", "parent": "LeftFoot", "head": [0.125, 0.02, 0.12]},
      {"name": "LowerBack", "parent": "Hips", "head": [0.0, 1.03, -0.01]},
      {"name": "Spine", "parent": "LowerBack", "head": [0.0, 1.18, -0.01]},
      {"name": "Spine1", "parent": "Spine", "head": [0.0, 1.33, -0.01]},
      {"name": "LeftShoulder", "parent": "Spine1", "head": [0.03, 1.44, 0.0]},
      {"name": "LeftArm", "parent": "LeftShoulder", "head": [0.18, 1.43, -0.02]},
      {"name": "LeftForeArm", "parent": "LeftArm", "head": [0.366, 1.208, -0.02]},
      {"name": "LeftHand", "parent": "LeftForeArm", "head": [0.533, 1.009, 0.0]},
      {"name": "LThumb", "parent": "LeftHand", "head": [0.545, 0.985, 0.03]},
      {"name": "LeftFingerBase", "parent": "LeftHand", "head": [0.555, 0.982, 0.0]},
      {"name": "LeftHandFinger1", "parent": "LeftFingerBase", "head": [0.585, 0.946, 0.0]},
      {"name": "Neck", "parent": "Spine1", "head": [0.0, 1.50, -0.015]},
      {"name": "Neck1", "parent": "Neck", "head": [0.0, 1.56, 0.0]},
      {"name": "Head", "parent": "Neck1", "head": [0.0, 1.62, 0.01]}
    ]
  },
  "body": {
    "ringSegments": 28,
    "parts": [
      {"name": "torso", "mirror": false, "ringsPerSpan": 4, "segments": 36, "stations": [
        {"joint": "Hips", "center": [0.0, 0.84, 0.0], "halfWidth": 0.10, "halfDepth": 0.08},
        {"joint": "Hips", "center": [0.0, 0.90, 0.0], "halfWidth": 0.165, "halfDepth": 0.105},
        {"joint": "Hips", "center": [0.0, 0.97, 0.0], "halfWidth": 0.175, "halfDepth": 0.112},
        {"joint": "LowerBack", "center": [0.0, 1.05, 0.0], "halfWidth": 0.16, "halfDepth": 0.105},
        {"joint": "LowerBack", "center": [0.0, 1.12, 0.0], "halfWidth": 0.152, "halfDepth": 0.10},
        {"joint": "Spine", "center": [0.0, 1.20, 0.0], "halfWidth": 0.158, "halfDepth": 0.105},
        {"joint": "Spine", "center": [0.0, 1.28, 0.005], "halfWidth": 0.172, "halfDepth": 0.115},
        {"joint": "Spine1", "center": [0.0, 1.35, 0.005], "halfWidth": 0.185, "halfDepth": 0.118},
        {"joint": "Spine1", "center": [0.0, 1.41, 0.0], "halfWidth": 0.2, "halfDepth": 0.112},
        {"joint": "Spine1", "center": [0.0, 1.455, -0.005], "halfWidth": 0.19, "halfDepth": 0.095},
        {"joint": "Spine1", "center": [0.0, 1.49, -0.01], "halfWidth": 0.12, "halfDepth": 0.07},
        {"joint": "Neck", "center": [0.0, 1.51, -0.012], "halfWidth": 0.06, "halfDepth": 0.055}
      ]},
      {"name": "head", "mirror": false, "ringsPerSpan": 4, "segments": 24, "stations": [
        {"joint": "Neck", "center": [0.0, 1.48, -0.015], "halfWidth": 0.056, "halfDepth": 0.054},
        {"joint": "Neck1", "center": [0.0, 1.57, 0.0], "halfWidth": 0.054, "halfDepth": 0.054},
        {"joint": "Head", "center": [0.0, 1.64, 0.02], "halfWidth": 0.078, "halfDepth": 0.09},
        {"joint": "Head", "center": [0.0, 1.72, 0.02], "halfWidth": 0.085, "halfDepth": 0.1},
        {"joint": "Head", "center": [0.0, 1.80, 0.01], "halfWidth": 0.06, "halfDepth": 0.07},
        {"joint": "Head", "center": [0.0, 1.835, 0.005], "halfWidth": 0.02, "halfDepth": 0.02}
      ]},
      {"name": "LeftArmPart", "mirror": true, "ringsPerSpan": 6, "segments": 16, "stations": [
        {"joint": "LeftArm", "at": "LeftArm", "offset": [0.005, -0.005, 0.0], "halfWidth": 0.04, "halfDepth": 0.04},
        {"joint": "LeftArm", "at": "LeftArm", "offset": [0.06, -0.07, 0.0], "halfWidth": 0.055, "halfDepth": 0.052},
        {"joint": "LeftForeArm", "at": "LeftForeArm", "halfWidth": 0.043, "halfDepth": 0.043},
        {"joint": "LeftHand", "at": "LeftHand", "halfWidth": 0.032, "halfDepth": 0.026},
        {"joint": "LeftHand", "at": "LeftHandFinger1", "halfWidth": 0.04, "halfDepth": 0.016},
        {"joint": "LeftHandFinger1", "at": "LeftHandFinger1", "offset": [0.045, -0.055, 0.0], "halfWidth": 0.012, "halfDepth": 0.008}
      ]},
      {"name": "LeftLegPart", "mirror": true, "ringsPerSpan": 5, "segments": 16, "stations": [
        {"joint": "LeftUpLeg", "at": "LeftUpLeg", "offset": [0.0, 0.02, 0.0], "halfWidth": 0.085, "halfDepth": 0.09},
        {"joint": "LeftUpLeg", "at": "LeftUpLeg", "offset": [0.004, -0.2, 0.01], "halfWidth": 0.075, "halfDepth": 0.078},
        {"joint": "LeftLeg", "at": "LeftLeg", "halfWidth": 0.053, "halfDepth": 0.055},
        {"joint": "LeftLeg", "at": "LeftLeg", "offset": [0.004, -0.16, -0.015], "halfWidth": 0.05, "halfDepth": 0.058},
        {"joint": "LeftFoot", "at": "LeftFoot", "offset": [0.0, 0.02, 0.0], "halfWidth": 0.036, "halfDepth": 0.038}
      ]},
      {"name": "LeftFootPart", "mirror": true, "ringsPerSpan": 4, "segments": 14, "stations": [
        {"joint": "LeftFoot", "at": "LeftFoot", "offset": [0.0, -0.01, -0.06], "halfWidth": 0.035, "halfDepth": 0.04},
        {"joint": "LeftFoot", "at": "LeftFoot", "offset": [0.0, -0.05, 0.02], "halfWidth": 0.045, "halfDepth": 0.035},
        {"joint": "LeftToeBase", "at": "LeftToeBase", "halfWidth": 0.045, "halfDepth": 0.02},
        {"joint": "LeftToeBase", "at": "LeftToeBase", "offset": [0.0, 0.0, 0.07], "halfWidth": 0.02, "halfDepth": 0.012}
      ]}
    ],
    "blends": [
      {"joint": "LeftArm", "at": "LeftArm", "offset": [0.0, -0.02, 0.0], "radius": 0.09, "mirror": true},
      {"joint": "LeftShoulder", "at": "LeftShoulder", "offset": [0.05, 0.01, 0.0], "radius": 0.08, "mirror": true},
      {"joint": "LeftUpLeg", "at": "LeftUpLeg", "offset": [0.0, -0.04, 0.0], "radius": 0.1, "mirror": true}
    ]
  },
  "jersey": {
    "offset": 0.012,
    "clearance": 0.008,
    "columns": 72,
    "rows": 34,
    "hemY": 0.93,
    "collarY": 1.505,
    "armholeBottomY": 1.31,
    "armholeTopY": 1.485,
    "armholeHalfWidth": 0.075,
    "sleeveLength": 0.14,
    "sleeveRings": 8,
    "skinTransferNeighbours": 4,
    "skinSmoothingIterations": 40,
    "maxInfluences": 4
  }
}
)recipe";

// "<value> is outside <lo>..<hi>", in JsonReader's wording, of the float the recipe keeps.
std::string outside(float v, float lo, float hi) {
  std::ostringstream s;
  s << v << " is outside " << lo << ".." << hi;
  return s.str();
}

// A number in [lo, hi], compared as the float the recipe keeps.
float real(const JsonReader& r, float lo, float hi) {
  const float v = float(r.number());
  if (!(std::isfinite(v) && v >= lo && v <= hi)) r.fail(outside(v, lo, hi));
  return v;
}

int count(const JsonReader& r, int lo, int hi) { return int(r.integer(uint64_t(lo), uint64_t(hi))); }

// [x, y, z] in metres, each within 10 m of the origin.
Vec3f vec3(const JsonReader& r) {
  if (!r.value().is_array() || r.value().size() != 3) r.fail("must be an array of 3 numbers [x, y, z]");
  return {real(r.at(0), -10.f, 10.f), real(r.at(1), -10.f, 10.f), real(r.at(2), -10.f, 10.f)};
}

// An array (possibly empty) of the elements at `r`.
void requireArray(const JsonReader& r, const std::string& of) {
  if (!r.value().is_array()) r.fail("must be an array of " + of + ", is " + std::string(r.value().type_name()));
}

// Runs f; an error it throws gets `about` appended ("... (body part 'torso')"): the path says where the
// value is, `about` which part of the character it shapes.
template <class F>
void about(const std::string& what, F&& f) {
  try {
    f();
  } catch (const Error& e) {
    throw Error(std::string(e.what()) + " (" + what + ")");
  }
}

}  // namespace

DefaultCharacterRecipe parseDefaultCharacterRecipe(const JsonReader& j) {
  j.requireObject({"format", "version", "name", "units", "skeleton", "body", "jersey"});
  if (j.required("format").string() != "swish-default-character-recipe")
    j.child("format").fail("not a swish default character recipe (must be \"swish-default-character-recipe\")");
  const JsonReader version = j.required("version");
  if (version.number() != 1)
    version.fail("unsupported recipe version " + version.value().dump() + " (this swish reads version 1)");
  DefaultCharacterRecipe r;
  r.name = j.required("name").string();
  if (j.has("units")) j.child("units").string();  // a note for people: where the numbers are measured

  const JsonReader sk = j.required("skeleton");
  sk.requireObject({"mirror", "joints"});
  r.mirrorSkeleton = sk.boolean("mirror", true);
  const JsonReader joints = sk.required("joints");
  requireArray(joints, "joints");
  std::set<std::string> names;
  for (size_t i = 0; i < joints.value().size(); ++i) {
    const JsonReader jj = joints.at(i);
    jj.requireObject({"name", "parent", "head"});
    RecipeJoint joint;
    joint.name = jj.required("name").string();
    about("joint '" + joint.name + "'", [&] {
      joint.parent = jj.required("parent").string();
      joint.head = vec3(jj.required("head"));
      if (!joint.parent.empty() && !names.count(joint.parent))
        jj.child("parent").fail("parent '" + joint.parent + "' must be listed before it");
      if (!names.insert(joint.name).second) jj.child("name").fail("repeats an earlier joint's name");
    });
    r.joints.push_back(joint);
  }
  if (r.joints.empty() || !r.joints[0].parent.empty()) joints.fail("the first joint must be the root (parent \"\")");
  auto known = [&](const JsonReader& name) {
    std::string n = name.string();
    if (!names.count(n) && !(r.mirrorSkeleton && names.count(mirroredJointName(n))))
      name.fail("unknown joint '" + n + "'");
    return n;
  };

  const JsonReader body = j.required("body");
  // "ringSegments" is read and checked like a part's "segments" but not used: each part's decide.
  body.requireObject({"ringSegments", "parts", "blends"});
  if (body.has("ringSegments")) count(body.child("ringSegments"), 6, 256);
  const JsonReader parts = body.required("parts");
  requireArray(parts, "body parts");
  for (size_t i = 0; i < parts.value().size(); ++i) {
    const JsonReader pj = parts.at(i);
    pj.requireObject({"name", "mirror", "ringsPerSpan", "segments", "stations"});
    RecipePart p;
    p.name = pj.required("name").string();
    about("body part '" + p.name + "'", [&] {
      p.mirror = pj.boolean("mirror", false);
      p.ringsPerSpan = count(pj.required("ringsPerSpan"), 1, 64);
      p.segments = count(pj.required("segments"), 6, 256);
      const JsonReader stations = pj.required("stations");
      requireArray(stations, "stations");
      for (size_t k = 0; k < stations.value().size(); ++k) {
        const JsonReader sj = stations.at(k);
        sj.requireObject({"joint", "at", "offset", "center", "halfWidth", "halfDepth"});
        RecipeStation s;
        s.joint = known(sj.required("joint"));
        if (sj.has("at")) {
          s.at = known(sj.child("at"));
          if (sj.has("center")) sj.child("center").fail("applies without \"at\" only (with \"at\": \"offset\")");
          if (sj.has("offset")) s.offset = vec3(sj.child("offset"));
        } else {
          if (sj.has("offset")) sj.child("offset").fail("applies with \"at\" only (without it: \"center\")");
          s.center = vec3(sj.required("center"));
        }
        s.halfWidth = real(sj.required("halfWidth"), 1e-3f, 1.f);
        s.halfDepth = real(sj.required("halfDepth"), 1e-3f, 1.f);
        p.stations.push_back(s);
      }
      if (p.stations.size() < 2) stations.fail("needs at least two stations");
    });
    r.parts.push_back(p);
  }
  if (body.has("blends")) {
    const JsonReader blends = body.child("blends");
    requireArray(blends, "blends");
    for (size_t i = 0; i < blends.value().size(); ++i) {
      const JsonReader bj = blends.at(i);
      bj.requireObject({"joint", "at", "offset", "radius", "mirror"});
      RecipeBlend b;
      b.joint = known(bj.required("joint"));
      b.at = known(bj.required("at"));
      if (bj.has("offset")) b.offset = vec3(bj.child("offset"));
      b.radius = real(bj.required("radius"), 1e-3f, 1.f);
      b.mirror = bj.boolean("mirror", false);
      r.blends.push_back(b);
    }
  }

  const JsonReader js = j.required("jersey");
  js.requireObject({"offset", "clearance", "columns", "rows", "hemY", "collarY", "armholeBottomY", "armholeTopY",
                    "armholeHalfWidth", "sleeveLength", "sleeveRings", "skinTransferNeighbours",
                    "skinSmoothingIterations", "maxInfluences"});
  RecipeJersey& g = r.jersey;
  g.offset = real(js.required("offset"), 1e-3f, 0.1f);
  g.clearance = real(js.required("clearance"), 1e-4f, 0.1f);
  g.columns = count(js.required("columns"), 16, 1024);
  g.rows = count(js.required("rows"), 4, 1024);
  g.hemY = real(js.required("hemY"), -10.f, 10.f);
  g.collarY = real(js.required("collarY"), -10.f, 10.f);
  g.armholeBottomY = real(js.required("armholeBottomY"), -10.f, 10.f);
  g.armholeTopY = real(js.required("armholeTopY"), -10.f, 10.f);
  g.armholeHalfWidth = real(js.required("armholeHalfWidth"), 1e-3f, 1.f);
  g.sleeveLength = real(js.required("sleeveLength"), 1e-3f, 1.f);
  g.sleeveRings = count(js.required("sleeveRings"), 1, 256);
  g.skinTransferNeighbours = count(js.required("skinTransferNeighbours"), 1, 16);
  g.skinSmoothingIterations = count(js.required("skinSmoothingIterations"), 0, 10000);
  g.maxInfluences = count(js.required("maxInfluences"), 1, 8);
  if (!(g.hemY < g.armholeBottomY && g.armholeBottomY < g.armholeTopY && g.armholeTopY < g.collarY))
    js.fail("need hemY < armholeBottomY < armholeTopY < collarY");
  return r;
}

DefaultCharacterRecipe parseDefaultCharacterRecipe(const nlohmann::json& j, const std::string& what) {
  return parseDefaultCharacterRecipe(JsonReader(j, what));
}

DefaultCharacterRecipe loadDefaultCharacterRecipe(const std::filesystem::path& file) {
  return parseDefaultCharacterRecipe(readJsonFile(file, "recipe"), file.string());
}

const char* embeddedDefaultRecipeJson() { return kEmbeddedRecipe; }

DefaultCharacterRecipe embeddedDefaultRecipe() {
  return parseDefaultCharacterRecipe(nlohmann::json::parse(kEmbeddedRecipe), "embedded default recipe");
}

}  // namespace swish::bake
