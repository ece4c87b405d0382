// JsonReader (files/json_reader.hpp): every error reads "<source>: <json.path>: <problem>", with the path
// built from object keys and array indices; type errors say what was found, ranges say the range, unknown
// keys list the keys allowed; optional members fall back when missing and are checked when present.
#include <gtest/gtest.h>

#include "support/error_message.hpp"
#include "swish/files/json_reader.hpp"

namespace {

using nlohmann::json;
using swish::JsonReader;
using swish::test::errorOf;

const json kDoc = json::parse(R"({
  "name": "shot",
  "count": 3,
  "whole": 4.0,
  "half": 2.5,
  "flag": true,
  "position": [1, 2, 3],
  "items": [{"model": 7}, {"model": "b.swish"}],
  "words": ["a", "b"],
  "settings": {"size": 64, "colour": "red"}
})");

TEST(JsonReader, ErrorsNameSourceAndPath) {
  const JsonReader r(kDoc, "scene.json");
  EXPECT_EQ(errorOf([&] { r.child("items").at(0).child("model").string(); }),
            "scene.json: items[0].model: must be a string, is number");
  EXPECT_EQ(r.child("items").at(1).child("model").string(), "b.swish");
  EXPECT_EQ(errorOf([&] { r.fail("is wrong"); }), "scene.json: (top level): is wrong");
  // Without a source the message starts at the path (a path given by the caller names the document).
  const JsonReader unnamed(kDoc, "", "model metadata");
  EXPECT_EQ(errorOf([&] { unnamed.child("name").number(); }), "model metadata.name: must be a number, is string");
}

TEST(JsonReader, RequiredAndMissingKeys) {
  const JsonReader r(kDoc, "f");
  EXPECT_EQ(errorOf([&] { r.required("frames"); }), "f: frames: is required");
  EXPECT_EQ(r.required("name").string(), "shot");
  EXPECT_FALSE(r.has("frames"));
  EXPECT_TRUE(r.child("frames").value().is_null());
  EXPECT_EQ(errorOf([&] { r.child("frames").boolean(); }), "f: frames: must be true or false, is null");
}

TEST(JsonReader, TypeErrorsSayWhatWasFound) {
  const JsonReader r(kDoc, "f");
  EXPECT_TRUE(r.child("flag").boolean());
  EXPECT_EQ(errorOf([&] { r.child("count").boolean(); }), "f: count: must be true or false, is number");
  EXPECT_EQ(errorOf([&] { r.child("flag").number(); }), "f: flag: must be a number, is boolean");
  EXPECT_EQ(errorOf([&] { r.child("words").string(); }), "f: words: must be a string, is array");
  EXPECT_EQ(errorOf([&] { r.child("words").requireObject({}); }), "f: words: must be a JSON object, is array");
  EXPECT_EQ(errorOf([&] { r.child("count").nonEmptyString(); }), "f: count: must be a non-empty string, is number");
  const json empty = {{"s", ""}};
  EXPECT_EQ(errorOf([&] { JsonReader(empty, "f").child("s").nonEmptyString(); }), "f: s: must be a non-empty string");
  const json nan = {{"x", std::nan("")}};
  EXPECT_EQ(errorOf([&] { JsonReader(nan, "f").child("x").number(); }), "f: x: must be finite");
}

TEST(JsonReader, IntegersAndRanges) {
  const JsonReader r(kDoc, "f");
  EXPECT_EQ(r.child("count").integer(1, 10), 3u);
  EXPECT_EQ(r.child("whole").integer(1, 10), 4u);  // 4.0 is a whole number
  EXPECT_EQ(errorOf([&] { r.child("half").integer(1, 10); }), "f: half: must be an integer, is a fraction");
  EXPECT_EQ(errorOf([&] { r.child("name").integer(1, 10); }), "f: name: must be an integer, is string");
  EXPECT_EQ(errorOf([&] { r.child("count").integer(4, 10); }), "f: count: must be 4 to 10, is 3");

  EXPECT_DOUBLE_EQ(r.child("half").number(0, 2.5), 2.5);
  EXPECT_EQ(errorOf([&] { r.child("half").number(0, 1); }), "f: half: 2.5 is outside 0..1");
  EXPECT_EQ(errorOf([&] { r.child("count").number(10, 1e6); }), "f: count: 3 is outside 10..1e+06");
  EXPECT_DOUBLE_EQ(r.child("whole").wholeNumber(0, 9.007199254740992e15), 4.0);
  EXPECT_EQ(errorOf([&] { r.child("half").wholeNumber(0, 10); }), "f: half: must be an integer, is a fraction");
  EXPECT_EQ(errorOf([&] { r.child("count").wholeNumber(4, 8); }), "f: count: 3 is outside 4..8");
}

TEST(JsonReader, OptionalMembersFallBackWhenMissingAndAreCheckedWhenPresent) {
  const JsonReader r(kDoc, "f");
  EXPECT_DOUBLE_EQ(r.number("missing", 0, 1, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(r.number("half", 0, 10, 0.5), 2.5);
  EXPECT_EQ(errorOf([&] { r.number("half", 0, 1, 0.5); }), "f: half: 2.5 is outside 0..1");
  EXPECT_DOUBLE_EQ(r.wholeNumber("missing", 0, 10, 7), 7.0);
  EXPECT_DOUBLE_EQ(r.wholeNumber("count", 0, 10, 7), 3.0);
  EXPECT_FALSE(r.boolean("missing", false));
  EXPECT_TRUE(r.boolean("flag", false));
  EXPECT_EQ(r.nonEmptyString("missing", "model"), "model");
  EXPECT_EQ(r.nonEmptyString("name", "model"), "shot");
  EXPECT_EQ(r.strings("missing", {"x"}), std::vector<std::string>{"x"});
  EXPECT_EQ(r.strings("words", {}), (std::vector<std::string>{"a", "b"}));
}

TEST(JsonReader, UnknownKeysListTheAllowedOnes) {
  const JsonReader r(kDoc, "f");
  EXPECT_EQ(errorOf([&] { r.child("settings").requireObject({"size"}); }),
            "f: settings.colour: unknown key (allowed here: size)");
  EXPECT_NO_THROW(r.child("settings").requireObject({"size", "colour"}));
  // section(): an optional object; a missing one reads as empty (its members fall back).
  EXPECT_EQ(errorOf([&] {
              r.section("settings", {"size", "depth"});
            }),
            "f: settings.colour: unknown key (allowed here: depth, size)");
  const JsonReader missing = r.section("preview", {"size"});
  EXPECT_EQ(missing.path(), "preview");
  EXPECT_DOUBLE_EQ(missing.wholeNumber("size", 16, 4096, 256), 256.0);
  EXPECT_EQ(errorOf([&] { r.section("name", {}); }), "f: name: must be a JSON object, is string");
}

TEST(JsonReader, Arrays) {
  const JsonReader r(kDoc, "f");
  EXPECT_EQ(r.child("position").vec3(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(errorOf([&] { r.child("words").vec3(); }), "f: words: must be an array of 3 numbers");
  EXPECT_EQ(errorOf([&] { r.child("count").vec3(); }), "f: count: must be an array of 3 numbers");
  const json bad = {{"names", {"a", 3}}, {"none", json::array()}, {"point", {1, "y", 3}}};
  const JsonReader b(bad, "f");
  EXPECT_EQ(errorOf([&] { b.child("names").strings(); }), "f: names: must hold non-empty strings only");
  EXPECT_EQ(errorOf([&] { b.child("none").strings(); }), "f: none: must be a non-empty array of strings");
  EXPECT_EQ(errorOf([&] { b.child("point").vec3(); }), "f: point[1]: must be a number, is string");
  EXPECT_EQ(b.child("names").at(0).string(), "a");
  EXPECT_EQ(errorOf([&] { b.child("names").at(1).string(); }), "f: names[1]: must be a string, is number");
}

}  // namespace
