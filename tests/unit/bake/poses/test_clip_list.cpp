// Clip lists that scale (bake/poses/clip_list.hpp): folders, globs and index files expand in sorted order
// with subjects, weights and joint maps; every mistake is an error naming the entry and the file.
// Joint maps with chains (io/joint_map.hpp, io/retarget.hpp): a clip joint drives several character
// joints, the rotation shared out along them, the last joint's global rotation kept. On the shared
// CMU corpus (../shared/mocap, skipped when absent): every clip of both skeletons reads onto the
// default character, the Daz rig through assets/joint_maps/cmu_daz.json, and a bad file is named.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>

#include "support/error_message.hpp"
#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/pipeline/bake_config.hpp"
#include "swish/bake/pipeline/bake_pipeline.hpp"
#include "swish/bake/poses/clip_list.hpp"
#include "swish/bake/poses/pose_sampling.hpp"
#include "swish/bake/report/bake_evaluation.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rotation.hpp"
#include "swish/io/animation_import.hpp"
#include "swish/io/bvh_reader.hpp"
#include "swish/io/character_import.hpp"
#include "swish/runtime/theta.hpp"

using namespace swish;
using namespace swish::bake;
namespace fs = std::filesystem;

namespace {

void touch(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

std::vector<ClipSource> parse(const nlohmann::json& clips, const fs::path& base) {
  return parseClipList(clips, "recipe.json: ", base);
}

std::string parseError(const nlohmann::json& clips, const fs::path& base) {
  return test::errorOf([&] { parse(clips, base); });
}

#define EXPECT_SAYS(text, part) EXPECT_NE((text).find(part), std::string::npos) << (text)

// A corpus folder of 4 clips, 2 subjects, and its index.
struct Corpus {
  test::TempDir dir{"clip_list"};
  Corpus() {
    for (const char* f : {"01_01.bvh", "01_02.bvh", "02_01.bvh", "02_07.bvh"}) touch(dir / "mocap" / f);
    touch(dir / "mocap" / "README.md");
    touch(dir / "mocap" / "index.tsv",
          "file\tsubject\ttrial\tdescription\tframes\tfps\n01_01.bvh\t1\t01\twalk\t100\t30\n"
          "01_02.bvh\t1\t02\trun\t50\t30\r\n02_01.bvh\t2\t01\tjump\t20\t30\n02_07.bvh\t2\t07\tdance\t30\t30\n");
  }
  fs::path base() const { return dir.path(); }
};

}  // namespace

TEST(ClipList, FoldersGlobsAndIndexFilesExpandSortedWithSubjects) {
  const Corpus c;
  const auto folder = parse({"mocap"}, c.base());
  ASSERT_EQ(folder.size(), 4u);  // README.md and index.tsv are not clips
  EXPECT_EQ(folder[0].file.filename(), "01_01.bvh");
  EXPECT_EQ(folder[3].file.filename(), "02_07.bvh");
  EXPECT_EQ(folder[2].subject, "02");
  EXPECT_EQ(folder[0].weight, 1.0);

  const auto glob = parse({"mocap/02_*.bvh"}, c.base());
  ASSERT_EQ(glob.size(), 2u);
  EXPECT_EQ(glob[1].file.filename(), "02_07.bvh");

  const auto index = parse({{{"index", "mocap/index.tsv"},
                             {"exclude_subjects", {"02"}},
                             {"weights", {{"01_02", 3}}},
                             {"weight", 0.5},
                             {"joint_map", {{"abdomen", "LowerBack"}, {"chest", {"Spine", "Spine1"}}}}}},
                           c.base());
  ASSERT_EQ(index.size(), 2u);
  EXPECT_EQ(index[0].subject, "1");
  EXPECT_EQ(index[0].expectedFrames, 100u);
  EXPECT_EQ(index[1].expectedFrames, 50u);  // a CRLF row
  EXPECT_DOUBLE_EQ(index[0].weight, 0.5);
  EXPECT_DOUBLE_EQ(index[1].weight, 1.5);
  ASSERT_EQ(index[0].jointChains.size(), 1u);
  EXPECT_EQ(index[0].jointChains[0].joints, (std::vector<std::string>{"Spine", "Spine1"}));
  EXPECT_FLOAT_EQ(index[0].jointChains[0].shares[0], 0.5f);
  ASSERT_EQ(index[0].jointMap.size(), 2u);

  // An index whose files are in another folder.
  touch(c.dir / "lists" / "index.tsv", "file\tsubject\n02_07.bvh\t2\n");
  const auto other = parse({{{"index", "lists/index.tsv"}, {"folder", "mocap"}}}, c.base());
  ASSERT_EQ(other.size(), 1u);
  EXPECT_EQ(other[0].file, c.dir / "mocap" / "02_07.bvh");

  // Per-subject weights, a subject filter, and a joint map file.
  touch(c.dir / "maps" / "daz.json",
        R"({"hip": "Hips", "chest": {"joints": ["Spine", "Spine1"], "shares": [0.3, 0.7]}})");
  const auto two =
      parse({{{"glob", "mocap/*.bvh"}, {"subjects", {"2"}}, {"weights", {{"2", 2}}}, {"joint_map", "maps/daz.json"}}},
            c.base());
  ASSERT_EQ(two.size(), 2u);
  EXPECT_DOUBLE_EQ(two[0].weight, 2.0);
  ASSERT_EQ(two[0].jointChains.size(), 1u);
  EXPECT_FLOAT_EQ(two[0].jointChains[0].shares[1], 0.7f);

  // The whole recipe takes the list.
  const BakeConfig cfg = parseBakeConfig(
      {{"output", "o"},
       {"part1",
        {{"clips", {"mocap", "/usr/share/assimp/models/BVH/01_01.bvh"}}, {"thinning", {{"target_poses", 10}}}}}},
      "recipe.json", c.base());
  EXPECT_EQ(cfg.part1->clips.size(), 5u);
}

TEST(ClipList, MistakesNameTheEntryAndTheFile) {
  const Corpus c;
  EXPECT_SAYS(parseError({"nowhere/*.bvh"}, c.base()), "part1.clips[0]: folder " + (c.base() / "nowhere").string());
  EXPECT_SAYS(parseError({"mocap/*.fbx"}, c.base()), "no file in");
  EXPECT_SAYS(parseError({"mo*/01_01.bvh"}, c.base()), "wildcards are allowed in the file name only");
  EXPECT_SAYS(parseError({"mocap", "mocap/01_01.bvh"}, c.base()), "part1.clips[1]: clip");
  EXPECT_SAYS(parseError({"mocap", "mocap/01_01.bvh"}, c.base()), "is listed again (first by part1.clips[0])");
  EXPECT_SAYS(parseError({{{"index", "mocap/missing.tsv"}}}, c.base()), "part1.clips[0].index: index file");
  EXPECT_SAYS(parseError({{{"index", "mocap/index.tsv"}, {"glob", "x"}}}, c.base()), "exactly one of");
  EXPECT_SAYS(parseError({{{"index", "mocap/index.tsv"}, {"subjects", {"7"}}}}, c.base()), "no clip of subject '7'");
  EXPECT_SAYS(parseError({{{"index", "mocap/index.tsv"}, {"weights", {{"99_01", 2}}}}}, c.base()),
              "part1.clips[0].weights.99_01: names neither a clip");
  EXPECT_SAYS(parseError({{{"file", "mocap/01_01.bvh"}, {"weight", 0}}}, c.base()),
              "part1.clips[0].weight: 0 is outside 0.01..100");
  EXPECT_SAYS(parseError({{{"file", "mocap/01_01.bvh"}, {"joint_map", "none.json"}}}, c.base()), "joint map file");
  const auto badShares = nlohmann::json::parse(
      R"([{"file": "mocap/01_01.bvh", "joint_map": {"chest": {"joints": ["Spine", "Spine1"], "shares": [0.3, 0.3]}}}])");
  EXPECT_SAYS(parseError(badShares, c.base()), "part1.clips[0].joint_map.chest.shares: must sum to 1");
  EXPECT_SAYS(parseError({{{"file", "mocap/01_01.bvh"}, {"joint_map", {{"chest", 3}}}}}, c.base()), "joint_map.chest");
  EXPECT_SAYS(parseError({{{"folder", "mocap"}, {"subject", "1"}}}, c.base()), "applies to a \"file\" entry only");

  touch(c.dir / "bad" / "index.tsv", "subject\tframes\n1\t10\n");
  EXPECT_SAYS(parseError({{{"index", "bad/index.tsv"}}}, c.base()),
              "index.tsv:1: the header row names no \"file\" column");
  touch(c.dir / "bad" / "index.tsv", "file\tframes\n01_01.bvh\t10\nlost.bvh\t3\n");
  EXPECT_SAYS(parseError({{{"index", "bad/index.tsv"}}}, c.base()), "index.tsv:2: clip file");
  touch(c.dir / "bad" / "01_01.bvh");
  EXPECT_SAYS(parseError({{{"index", "bad/index.tsv"}}}, c.base()),
              "index.tsv:3: clip file " + (c.dir / "bad" / "lost.bvh").string());
  touch(c.dir / "bad" / "index.tsv", "file\tframes\n01_01.bvh\tmany\n");
  EXPECT_SAYS(parseError({{{"index", "bad/index.tsv"}}}, c.base()), "frames 'many' is not a positive integer");
}

// Through a bake config, the messages name the config file and the entry's JSON path.
TEST(ClipList, ErrorsNameTheConfigFileAndTheJsonPath) {
  const Corpus c;
  auto error = [&](const nlohmann::json& entry) {
    const nlohmann::json config = {
        {"output", "o"}, {"part1", {{"clips", {"mocap/01_01.bvh", entry}}, {"thinning", {{"target_poses", 10}}}}}};
    return test::errorOf([&] { parseBakeConfig(config, "bake.json", c.base()); });
  };
  EXPECT_EQ(error({{"glob", "mocap/02_*.bvh"}, {"fps", 2000}}),
            "bake.json: part1.clips[1].fps: 2000 is outside 0..1000");
  EXPECT_EQ(error({{"glob", "mocap/02_*.bvh"}, {"fps", "30"}}),
            "bake.json: part1.clips[1].fps: must be a number, is string");
  EXPECT_EQ(error({{"glob", "mocap/02_*.bvh"}, {"weights", {{"02_01", "x"}}}}),
            "bake.json: part1.clips[1].weights.02_01: must be a number, is string");
  EXPECT_EQ(error({{"glob", 5}}), "bake.json: part1.clips[1].glob: must be a non-empty string, is number");
  EXPECT_EQ(error({{"glob", "mocap/02_*.bvh"}, {"subjects", {"2", 7}}}),
            "bake.json: part1.clips[1].subjects[1]: must be a non-empty string, is number");
  EXPECT_EQ(error({{"glob", "mocap/02_*.bvh"}, {"speed", 2}}),
            "bake.json: part1.clips[1].speed: unknown key (allowed here: exclude_subjects, file, folder, fps, glob, "
            "index, joint_map, naming, subject, subjects, weight, weights)");
  EXPECT_EQ(
      error({{"glob", "mocap/02_*.bvh"}, {"joint_map", {{"chest", {{"joints", {"A", "B"}}, {"shares", {2, 0}}}}}}}),
      "bake.json: part1.clips[1].joint_map.chest.shares[0]: 2 is outside 0..1");
  EXPECT_EQ(error("mocap/01_*.bvh"), "bake.json: part1.clips[1]: clip " + (c.dir / "mocap" / "01_01.bvh").string() +
                                         " is listed again (first by part1.clips[0]); give it a weight instead");
  // A list read from elsewhere (swish levels: a model's metadata) keeps its caller's prefix.
  EXPECT_EQ(test::errorOf([&] { parseClipList({5}, "m.swish: metadata dataset_settings.clips: ", c.base()); }),
            "m.swish: metadata dataset_settings.clips: part1.clips[0]: must be a clip file, folder or glob (string) or "
            "an object");
  EXPECT_EQ(test::errorOf([&] { parseClipList(nlohmann::json::array(), "", c.base()); }),
            "part1.clips: must be a non-empty array of clip files, folders, globs or clip objects");
}

TEST(ClipList, SubjectsCompareWithoutLeadingZeros) {
  EXPECT_EQ(normaliseSubject("01"), "1");
  EXPECT_EQ(normaliseSubject("000"), "0");
  EXPECT_EQ(normaliseSubject("S01"), "S01");
  EXPECT_EQ(subjectOfClipFile("/a/13_29.bvh"), "13");
  EXPECT_EQ(subjectOfClipFile("/a/walk.fbx"), "walk");
}

TEST(ClipList, WeightsSampleClipsMoreDensely) {
  // Two 31-frame clips on a one-joint-chain skeleton: weight 2 doubles the first clip's samples.
  Skeleton s;
  s.joints.push_back({"Hips", -1, {}});
  s.joints.push_back({"Spine", 0, {}});
  AnimationClip a, b;
  for (AnimationClip* c : {&a, &b}) {
    c->framesPerSecond = 30.f;
    for (int f = 0; f < 31; ++f) {
      Pose p;
      p.local = {Quatf::Identity(), Quatf(Eigen::AngleAxisf(0.01f * float(f), Vec3f::UnitX()))};
      p.rootTranslation = Vec3f::Zero();
      c->frames.push_back(p);
    }
  }
  PoseSamplingOptions o;
  o.joints = {"Spine"};
  o.mirrorOddCharacters = false;
  const size_t plain = samplePoses(s, {a, b}, o).size();
  EXPECT_EQ(plain, 62u);
  o.clipWeights = {2.0, 1.0};
  const PoseSamples w = samplePoses(s, {a, b}, o);
  size_t first = 0;
  for (const auto& origin : w.origins) first += origin.clip == 0;
  EXPECT_EQ(first, 61u);  // frames 0, 0.5, ..., 30
  EXPECT_EQ(w.size(), 61u + 31u);
  o.clipWeights = {1.0};
  EXPECT_SAYS(test::errorOf([&] { samplePoses(s, {a, b}, o); }), "1 clip weights for 2 clips");
}

TEST(JointMapChain, SharesTheRotationAlongTheChainAndKeepsTheLastJointsGlobal) {
  // Character: Hips > A > B > C (unit bones up +Y). Clip: hip > x > y, y drives the chain [B, C].
  Skeleton ch;
  ch.joints.push_back({"Hips", -1, {Quatf::Identity(), Vec3f(0, 1, 0)}});
  ch.joints.push_back({"A", 0, {Quatf::Identity(), Vec3f(0, 0.1f, 0)}});
  ch.joints.push_back({"B", 1, {Quatf::Identity(), Vec3f(0, 0.1f, 0)}});
  ch.joints.push_back({"C", 2, {Quatf::Identity(), Vec3f(0, 0.1f, 0)}});
  ch.joints.push_back({"D", 3, {Quatf::Identity(), Vec3f(0, 0.1f, 0)}});
  io::SourceAnimation clip;
  clip.name = "bend";
  clip.jointNames = {"hip", "x", "y", "z"};
  clip.parents = {-1, 0, 1, 2};
  clip.rest = {{Quatf::Identity(), Vec3f(0, 1, 0)},
               {Quatf::Identity(), Vec3f(0, 0.1f, 0)},
               {Quatf::Identity(), Vec3f(0, 0.2f, 0)},
               {Quatf::Identity(), Vec3f(0, 0.1f, 0)}};
  const Quatf bend(Eigen::AngleAxisf(0.8f, Vec3f::UnitZ()));
  clip.frames = {clip.rest};
  clip.frames[0][2].rotation = bend;
  io::RetargetOptions o;
  o.requiredJoints = {"A", "C"};
  o.jointMap = io::parseJointMap(
      {{"hip", "Hips"}, {"x", "A"}, {"y", {{"joints", {"B", "C"}}, {"shares", {0.25, 0.75}}}}, {"z", "D"}}, "map");
  const AnimationClip out = io::retarget(clip, ch, o);
  const Pose& p = out.frames[0];
  EXPECT_NEAR(p.local[2].angularDistance(Quatf::Identity()), 0.25f * 0.8f, 1e-4f);  // B: a quarter
  EXPECT_NEAR(p.local[3].angularDistance(Quatf::Identity()), 0.75f * 0.8f, 1e-4f);  // C: the rest
  EXPECT_NEAR((p.local[2] * p.local[3]).angularDistance(bend), 0.f, 1e-4f);         // C's global is the clip's
  EXPECT_NEAR(p.local[4].angularDistance(Quatf::Identity()), 0.f, 1e-4f);           // D unchanged below it
  // Without the chain, C takes the whole bend and B stays at rest.
  o.jointMap = io::parseJointMap({{"hip", "Hips"}, {"x", "A"}, {"y", "C"}, {"z", "D"}}, "map");
  const AnimationClip plain = io::retarget(clip, ch, o);
  EXPECT_NEAR(plain.frames[0].local[2].angularDistance(Quatf::Identity()), 0.f, 1e-4f);
  EXPECT_NEAR(plain.frames[0].local[3].angularDistance(bend), 0.f, 1e-4f);
  // A chain that is not a parent chain, or whose last joint no clip joint drives, is an error.
  o.jointMap = io::parseJointMap({{"hip", "Hips"}, {"y", {"A", "C"}}}, "map");
  EXPECT_SAYS(test::errorOf([&] { io::retarget(clip, ch, o); }), "'C' is not the child of 'A'");
  o.jointMap = io::parseJointMap({{"hip", "Hips"}, {"nothing", {"B", "C"}}}, "map");
  o.requiredJoints = {};
  EXPECT_SAYS(test::errorOf([&] { io::retarget(clip, ch, o); }), "no clip joint drives its last joint 'C'");
  EXPECT_SAYS(test::errorOf([&] {
                io::parseJointMap({{"y", nlohmann::json::array()}}, "m");
              }),
              "m.y: a chain must list");
  // Round trip through the JSON form.
  const io::JointMapOptions m = io::parseJointMap({{"y", {{"joints", {"B", "C"}}, {"shares", {0.25, 0.75}}}}}, "m");
  EXPECT_EQ(io::jointMapToJson(m)["y"]["joints"], nlohmann::json({"B", "C"}));
}

// Joint map errors name the map (its file, or the path of an inline map) and the JSON path of the value.
TEST(JointMapErrors, NameTheFileAndTheJsonPath) {
  const test::TempDir dir("joint_map_errors");
  auto fileError = [&](const std::string& text) {
    std::ofstream(dir / "map.json") << text;
    return test::errorOf([&] { io::readJointMapFile(dir / "map.json"); });
  };
  const std::string f = (dir / "map.json").string();
  EXPECT_EQ(fileError(R"({"chest": {"joints": ["Spine", "Spine1"], "shares": [0.5, 1.5]}})"),
            f + ": chest.shares[1]: 1.5 is outside 0..1");
  EXPECT_EQ(fileError(R"({"chest": {"joints": ["Spine", "Spine1"], "shares": [0.5, "half"]}})"),
            f + ": chest.shares[1]: must be a number, is string");
  EXPECT_EQ(fileError(R"({"chest": {"joints": ["Spine", "Spine1"], "shares": [0.3, 0.3]}})"),
            f + ": chest.shares: must sum to 1 (they sum to 0.600000)");
  EXPECT_EQ(fileError(R"({"chest": ["Spine", 3]})"), f + ": chest[1]: must be a non-empty joint name, is number");
  EXPECT_EQ(fileError(R"({"chest": {"joints": ["Spine", ""]}})"),
            f + ": chest.joints[1]: must be a non-empty joint name");
  EXPECT_EQ(fileError(R"({"chest": {"joints": []}})"),
            f + ": chest.joints: a chain must list at least one character joint, parent first");
  EXPECT_EQ(fileError(R"({"chest": {"joint": ["Spine"]}})"),
            f + ": chest.joint: unknown key (allowed here: joints, shares)");
  EXPECT_EQ(fileError(R"({"": "Hips"})"), f + ": \"\": an empty clip joint name");
  EXPECT_EQ(
      fileError(R"(["Hips"])"),
      f + ": (top level): must be a JSON object {\"clip joint\": \"character joint\" or [chain joints, parent first]}");
  EXPECT_EQ(fileError("{").rfind(f + ": not valid JSON: ", 0), 0u) << fileError("{");
  EXPECT_EQ(test::errorOf([&] { io::readJointMapFile(dir / "none.json"); }),
            (dir / "none.json").string() + ": cannot open the joint map file");
  // An inline map: `what` starts the message, the map's path.
  EXPECT_EQ(test::errorOf([] {
              io::parseJointMap({{"hip", ""}}, "scene.json: characters[2].animation.jointMap");
            }),
            "scene.json: characters[2].animation.jointMap.hip: must be a non-empty joint name");
}

namespace {
#define SKIP_WITHOUT_CORPUS()                                                                                 \
  if (!fs::exists(test::sharedMocap("cmu-daz/index.tsv")) || !fs::exists(test::sharedMocap("index.tsv"))) {   \
    if (std::getenv("CI")) FAIL() << "the shared mocap corpus " << test::sharedMocap() << " is absent in CI"; \
    GTEST_SKIP() << "the shared mocap corpus " << test::sharedMocap() << " is absent";                        \
  }

const std::vector<std::string> kNetworkJoints = {"LowerBack",     "Spine",     "Spine1",    "LeftShoulder",
                                                 "RightShoulder", "LeftArm",   "RightArm",  "LeftForeArm",
                                                 "RightForeArm",  "LeftUpLeg", "RightUpLeg"};
}  // namespace

TEST(ClipListCorpus, EveryClipOfBothSkeletonsReadsOntoTheDefaultCharacter) {
  SKIP_WITHOUT_CORPUS();
  const fs::path map = test::sourceDir() / "assets/joint_maps/cmu_daz.json";
  const auto sources =
      parse({{{"index", test::sharedMocap("index.tsv").string()}, {"folder", test::sharedMocap("cmu").string()}},
             {{"index", test::sharedMocap("cmu-daz/index.tsv").string()}, {"joint_map", map.string()}}},
            "/");
  ASSERT_EQ(sources.size(), 150u);
  const Character character = makeDefaultCharacter();
  const auto clips = importClips(sources, character.skeleton, kNetworkJoints, 0);
  ASSERT_EQ(clips.size(), 150u);
  for (size_t i = 0; i < clips.size(); ++i)
    EXPECT_EQ(clips[i].frames.size(), sources[i].expectedFrames) << sources[i].file;

  // Frame 0 of both conversions is a reference T-pose (arms along +-X, legs down). Through the joint map
  // the character's upper arms, forearms and thighs point the same way in both (within 10 degrees, the forearms 30; a
  // left/right swap or a wrong axis is 90 or more). Their local rotations differ more: the two rigs
  // twist their limbs differently at rest, and direction-based retargeting keeps that twist (printed).
  const auto gc = character.skeleton.globalTransforms(clips[0].frames[0]);
  const auto gd = character.skeleton.globalTransforms(clips[67].frames[0]);
  for (const char* pair : {"LeftArm>LeftForeArm", "RightArm>RightForeArm", "LeftForeArm>LeftHand",
                           "RightForeArm>RightHand", "LeftUpLeg>LeftLeg", "RightUpLeg>RightLeg", "LowerBack>Neck"}) {
    const std::string p(pair);
    const size_t a = size_t(character.skeleton.find(p.substr(0, p.find('>'))));
    const size_t b = size_t(character.skeleton.find(p.substr(p.find('>') + 1)));
    const Vec3f dc = (gc[b].translation - gc[a].translation).normalized();
    const Vec3f dd = (gd[b].translation - gd[a].translation).normalized();
    const double degrees = std::acos(std::clamp(double(dc.dot(dd)), -1.0, 1.0)) * 180.0 / M_PI;
    const double rotation = gc[a].rotation.angularDistance(gd[a].rotation) * 180.0 / M_PI;
    std::printf("T-pose, CMU vs Daz conversion: %-24s direction %5.1f deg, global rotation %5.1f deg\n", pair, degrees,
                rotation);
    // The forearms differ by about 20 degrees: the Daz reference pose bends the elbows a little.
    EXPECT_LT(degrees, p.find("ForeArm>") != std::string::npos ? 30.0 : 10.0) << pair << " of " << sources[67].file;
  }
  // The chain bends the Daz spine over Spine and Spine1 by the map's shares (0.65 / 0.35): over a
  // clip, Spine turns 0.65 / 0.35 times as far as Spine1, never stays at rest.
  const size_t spine = size_t(character.skeleton.find("Spine")), spine1 = size_t(character.skeleton.find("Spine1"));
  double a = 0.0, b = 0.0;
  for (const Pose& p : clips[67 + 7].frames) {  // 13_01: sit on a stool and stand up
    a += p.local[spine].angularDistance(clips[67 + 7].frames[0].local[spine]);
    b += p.local[spine1].angularDistance(clips[67 + 7].frames[0].local[spine1]);
  }
  EXPECT_GT(a, 0.0);
  EXPECT_NEAR(a / b, 0.65 / 0.35, 0.05);
}

// The same reference T-poses on the shared T-shirt character (a MakeHuman skeleton whose collar bones
// start ahead of its neck, where the Daz rig's start behind it): the chest's rest alignment is the one
// place where the two skeletons' children cannot tell a rotation (Kabsch's best fit is a mirror image,
// two singular values tie). It used to come out turned 180 degrees about the spine (Spine1 179.6 degrees
// from rest at the Daz T-pose, every Daz-rig pose of the T-shirt exploding at the armpits); now the chest is
// aligned by the left-right axis of its collar bones and the neck (io/retarget.cpp).
TEST(ClipListCorpus, DazClipsKeepTheSharedTshirtsChestFacingForwards) {
  SKIP_WITHOUT_CORPUS();
  const fs::path file = test::sharedAsset("tshirt_lo.glb");
  if (!fs::exists(file)) {
    if (std::getenv("CI")) FAIL() << "the shared test character " << file << " is absent in CI";
    GTEST_SKIP() << "the shared test character " << file << " is absent";
  }
  const fs::path map = test::sourceDir() / "assets/joint_maps/cmu_daz.json";
  const auto sources = parse({test::sharedMocap("cmu/08_01.bvh").string(),
                              {{"file", test::sharedMocap("cmu-daz/10_01.bvh").string()}, {"joint_map", map.string()}}},
                             "/");
  const Character character = io::importCharacter(file);
  const Skeleton& sk = character.skeleton;
  const auto clips = importClips(sources, sk, kNetworkJoints, 0);
  ASSERT_EQ(clips.size(), 2u);
  const auto rest = sk.globalTransforms(sk.restPose());
  const auto gc = sk.globalTransforms(clips[0].frames[0]);
  const auto gd = sk.globalTransforms(clips[1].frames[0]);
  for (const char* name : {"Spine", "Spine1", "Neck"}) {
    const size_t j = size_t(sk.find(name));
    const double cmu = gc[j].rotation.angularDistance(rest[j].rotation) * 180.0 / M_PI;
    const double daz = gd[j].rotation.angularDistance(rest[j].rotation) * 180.0 / M_PI;
    std::printf("T-shirt, T-pose: %-7s from rest: CMU conversion %5.1f deg, Daz %5.1f deg\n", name, cmu, daz);
    // On the mannequin the Daz T-pose holds Spine1 34 degrees from rest (the conversions' spines differ, the
    // section above); a chest turned about the spine is 90 or more.
    EXPECT_LT(daz, 60.0) << name;
  }
  // And over the clip the chest faces the way the hips do: the left collar bone stays on the left.
  const size_t hips = 0, left = size_t(sk.find("LeftShoulder")), right = size_t(sk.find("RightShoulder"));
  for (const Pose& pose : clips[1].frames) {
    const auto g = sk.globalTransforms(pose);
    const Vec3f across = g[left].translation - g[right].translation;
    const Vec3f hipsLeft = g[hips].rotation * Vec3f::UnitX();
    ASSERT_GT(across.normalized().dot(hipsLeft), 0.5f) << "frame " << &pose - clips[1].frames.data();
  }
}

TEST(ClipListCorpus, ABadFileAmongManyIsNamed) {
  SKIP_WITHOUT_CORPUS();
  const test::TempDir dir("bad_corpus");
  std::ofstream index(dir / "index.tsv");
  index << "file\tsubject\tframes\n";
  for (const char* f : {"01_01.bvh", "02_01.bvh", "05_01.bvh"}) {
    fs::copy_file(test::sharedMocap("cmu") / f, dir / f);
    index << f << "\t" << std::string(f).substr(0, 2) << "\t\n";
  }
  index.close();
  {  // truncate the middle clip's motion
    std::ifstream in(dir / "02_01.bvh");
    std::string text((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(dir / "02_01.bvh") << text.substr(0, text.size() - 5000);
  }
  const auto sources = parse({{{"index", (dir / "index.tsv").string()}}}, "/");
  const Character character = makeDefaultCharacter();
  const std::string e = test::errorOf([&] { importClips(sources, character.skeleton, kNetworkJoints, 0); });
  EXPECT_SAYS(e, "bake part 1: clip " + (dir / "02_01.bvh").string());
  // A Daz clip without its joint map stops on the unmapped joints, naming the file.
  const auto daz = parse({test::sharedMocap("cmu-daz/10_04.bvh").string()}, "/");
  const std::string d = test::errorOf([&] { importClips(daz, character.skeleton, kNetworkJoints, 0); });
  EXPECT_SAYS(d, "10_04.bvh");
  EXPECT_SAYS(d, "add pairs to the joint map");
}

namespace {
Vec3d rotationVector(const Quatf& qf) {
  Quatd q = qf.cast<double>();
  if (q.w() < 0) q.coeffs() *= -1.0;
  const Eigen::AngleAxisd aa(q);
  return aa.axis() * aa.angle();
}
}  // namespace

// How the Daz rig's chest drives CMU's Spine and Spine1 (assets/joint_maps/cmu_daz.json): the CMU
// clips themselves show how their spine bends over the two joints. Fitting Spine's rotation vector as
// a share s of the rotation Spine * Spine1 over every frame of the 67 CMU clips gives the share the
// map gives Spine; the test prints the fit and the per-joint errors of the split against the
// recorded rotations, beside the errors of leaving Spine at rest (the map without a chain).
TEST(ClipListCorpus, TheSpineChainSharesAreWhatTheCmuClipsShow) {
  SKIP_WITHOUT_CORPUS();
  const auto sources =
      parse({{{"index", test::sharedMocap("index.tsv").string()}, {"folder", test::sharedMocap("cmu").string()}}}, "/");
  const Character character = makeDefaultCharacter();
  const auto clips = importClips(sources, character.skeleton, kNetworkJoints, 0);
  const size_t spine = size_t(character.skeleton.find("Spine")), spine1 = size_t(character.skeleton.find("Spine1"));
  double num = 0.0, den = 0.0;
  std::vector<std::pair<Quatf, Quatf>> frames;
  for (const AnimationClip& c : clips)
    for (size_t f = 1; f < c.frames.size(); ++f) {  // frame 0 is the conversion's T-pose
      const Quatf a = c.frames[f].local[spine], b = c.frames[f].local[spine1];
      const Vec3d va = rotationVector(a), vc = rotationVector(a * b);
      num += va.dot(vc);
      den += vc.squaredNorm();
      frames.emplace_back(a, b);
    }
  const double share = num / den;
  auto errors = [&](double s) {
    std::vector<double> e0, e1;
    for (const auto& [a, b] : frames) {
      const Quatd c = (a * b).cast<double>();
      const Quatd sa = Quatd::Identity().slerp(s, c.w() < 0 ? Quatd(-c.w(), -c.x(), -c.y(), -c.z()) : c);
      const Quatd sb = sa.conjugate() * c;
      e0.push_back(sa.angularDistance(a.cast<double>()) * 180.0 / M_PI);
      e1.push_back(sb.angularDistance(b.cast<double>()) * 180.0 / M_PI);
    }
    return std::make_pair(distanceStats(e0), distanceStats(e1));
  };
  const io::JointMapOptions map = io::readJointMapFile(test::sourceDir() / "assets/joint_maps/cmu_daz.json");
  ASSERT_EQ(map.chains.size(), 2u);
  const double committed = map.chains[0].joints[0] == "Spine" ? map.chains[0].shares[0] : map.chains[1].shares[0];
  const auto [split0, split1] = errors(committed);
  const auto [rest0, rest1] = errors(0.0);
  std::printf(
      "CMU spine over %zu frames of %zu clips: least-squares share of Spine %.3f (committed %.3f)\n"
      "  split:        Spine error mean %.2f p95 %.2f deg, Spine1 mean %.2f p95 %.2f deg\n"
      "  Spine at rest: Spine error mean %.2f p95 %.2f deg, Spine1 mean %.2f p95 %.2f deg\n",
      frames.size(), clips.size(), share, committed, split0.mean, split0.p95, split1.mean, split1.p95, rest0.mean,
      rest0.p95, rest1.mean, rest1.p95);
  EXPECT_NEAR(committed, share, 0.1);
  EXPECT_LT(split0.mean + split1.mean, rest0.mean + rest1.mean);
}

// The committed small corpus recipe (assets/corpus_small/bake.json, docs/baking.md) loads: both
// skeletons' 150 clips, subjects 8 and 10 held out.
TEST(ClipListCorpus, TheSmallCorpusRecipeLoads) {
  SKIP_WITHOUT_CORPUS();
  const BakeConfig cfg = loadBakeConfig(test::sourceDir() / "assets/corpus_small/bake.json");
  ASSERT_TRUE(cfg.part1.has_value());
  EXPECT_EQ(cfg.part1->clips.size(), 150u);
  const auto [training, heldOut] = splitHeldOutSubjects(*cfg.part1);
  EXPECT_EQ(heldOut.clips.size(), 17u);  // 11 walks of subject 8, 6 clips of subject 10
  EXPECT_EQ(training.clips.size(), 133u);
  EXPECT_EQ(heldOut.evenPoses, 60u);
  EXPECT_FALSE(heldOut.includeRestPose);
}

// train.anchor_poses "as_played" on the small corpus recipe: the frames the anchors' poses are chosen by
// come from the training clips of both skeletons (the Daz-rig ones through the joint map), upright as
// part 1 simulates them, and none from the held-out subjects.
TEST(ClipListCorpus, FramesAsPlayedForTheAnchorsLeaveTheHeldOutSubjectsOut) {
  SKIP_WITHOUT_CORPUS();
  BakeConfig cfg = loadBakeConfig(test::sourceDir() / "assets/corpus_small/bake.json");
  ASSERT_TRUE(cfg.part1.has_value());
  const Character character = makeDefaultCharacter();
  EXPECT_TRUE(anchorFramesAsPlayed(cfg, character.skeleton).empty());  // off: none read
  cfg.train.anchorsAsPlayed = true;
  cfg.train.anchorFramesAsPlayed = 120;
  std::vector<std::string> clipOf;
  const std::vector<Pose> frames = anchorFramesAsPlayed(cfg, character.skeleton, {}, &clipOf);
  // (evenlySpacedFrames: about that many, spread by length, at least one per clip.)
  const auto [trainingSources, heldOutSources] = splitHeldOutSubjects(*cfg.part1);
  ASSERT_GE(frames.size(), 120u);
  ASSERT_LE(frames.size(), 120u + trainingSources.clips.size());
  ASSERT_EQ(clipOf.size(), frames.size());
  std::set<std::string> held, trainingClips, seen;
  for (const ClipSource& c : heldOutSources.clips) held.insert(c.file.filename().string());
  for (const ClipSource& c : trainingSources.clips) trainingClips.insert(c.file.filename().string());
  for (const std::string& c : clipOf) {
    EXPECT_FALSE(held.count(c)) << c << " is a held-out subject's clip";
    EXPECT_TRUE(trainingClips.count(c)) << c;
    seen.insert(c);
  }
  EXPECT_EQ(seen, trainingClips) << "every training clip, of both skeletons, gives at least one frame";
  const std::vector<uint32_t> joints = [&] {
    std::vector<uint32_t> j;
    for (const std::string& name : cfg.part1->inputJoints) j.push_back(uint32_t(character.skeleton.find(name)));
    return j;
  }();
  const std::vector<float> rest = runtime::computeTheta(joints, character.skeleton.restPose().local);
  size_t moving = 0;
  for (const Pose& f : frames) {
    ASSERT_EQ(f.local.size(), character.skeleton.size());
    const std::vector<float> th = runtime::computeTheta(joints, f.local);
    float d = 0.f;
    for (size_t k = 0; k < th.size(); ++k) d += (th[k] - rest[k]) * (th[k] - rest[k]);
    moving += d > 1e-4f;
  }
  EXPECT_GT(moving, 100u) << "the frames are poses of the clips, not the rest pose";
}

TEST(ClipList, HeldOutSubjectsMustBeInTheListAndLeaveSomethingToTrainOn) {
  const Corpus c;
  auto config = [&](const nlohmann::json& holdout) {
    return nlohmann::json{
        {"output", "o"}, {"part1", {{"clips", {"mocap"}}, {"thinning", {{"target_poses", 10}}}, {"holdout", holdout}}}};
  };
  const BakeConfig ok = parseBakeConfig(config({{"subjects", {"2"}}, {"poses", 12}}), "recipe.json", c.base());
  EXPECT_EQ(ok.part1->holdoutPoses, 12u);
  const auto [training, heldOut] = splitHeldOutSubjects(*ok.part1);
  EXPECT_EQ(training.clips.size(), 2u);
  EXPECT_EQ(heldOut.clips.size(), 2u);
  EXPECT_EQ(heldOut.clips[0].file.filename(), "02_01.bvh");
  auto error = [&](const nlohmann::json& h) {
    return test::errorOf([&] { parseBakeConfig(config(h), "recipe.json", c.base()); });
  };
  EXPECT_SAYS(error({{"subjects", {"7"}}}), "part1.holdout.subjects: no clip of subject '7'");
  EXPECT_SAYS(error({{"subjects", {"1", "02"}}}), "holds out every clip");
  EXPECT_SAYS(error({{"poses", 3}}), "part1.holdout.subjects: is required");
  EXPECT_SAYS(error({{"subjects", {"2"}}, {"every", 3}}), "part1.holdout.every: unknown key");
}
