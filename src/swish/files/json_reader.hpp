#pragma once
// JsonReader: reads a parsed JSON document (a scene file, a bake config, a pose stream) node by node,
// knowing the path of the node it stands on, so that every error says where the problem is:
//
//   <source>: <json.path>: <problem>       e.g.  "shot.json: characters[3].model: must be a string, is number"
//
// <source> names the document (usually its file; with an empty source the message starts at the
// path: "model metadata dataset_settings.simulation.substeps: ..." when the path starts with a name), <json.path> is
// the node's path from the top ("frames.count", "characters[0].placement";
// "(top level)" for the document itself), and <problem> says what is wrong with the value found there.
// Errors are swish::Error. A reader refers to the JSON it reads (it keeps no copy): the document must
// outlive it. A missing key reads as null, so child("x").string() of a missing "x" says
// "x: must be a string, is null"; required("x") says "x: is required".
//
// The getters without a key read the node itself; those with a key and a fallback read an optional
// member of an object (the fallback when it is missing, an error at "<path>.<key>" when it is wrong).
// Type errors say what was found ("must be a number, is string"). Ranges have two phrasings, both
// kept from the readers that had them: integer(lo, hi) for counts and indices says
// "must be <lo> to <hi>, is <value>"; number(lo, hi) and wholeNumber(lo, hi) say
// "<value> is outside <lo>..<hi>".
#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/core/types.hpp"

namespace swish {

class JsonReader {
 public:
  JsonReader(const nlohmann::json& value, std::string source, std::string path = "");

  // Throws "<source>: <path>: <problem>".
  [[noreturn]] void fail(const std::string& problem) const;

  const nlohmann::json& value() const { return j_; }
  const std::string& path() const { return path_; }
  const std::string& source() const { return source_; }

  // The node must be an object whose keys are all in `allowed` (an unknown key is an error at its
  // own path that lists the keys allowed here).
  void requireObject(std::initializer_list<const char*> allowed) const;
  bool has(const char* key) const { return j_.contains(key); }
  // The value of `key` (null when it is missing), at "<path>.<key>".
  JsonReader child(const std::string& key) const;
  // Element i of an array, at "<path>[i]".
  JsonReader at(size_t i) const;
  // Like child(), but a missing key is the error "is required".
  JsonReader required(const char* key) const;
  // An optional object member checked with requireObject(allowed); an empty object when missing.
  JsonReader section(const std::string& key, std::initializer_list<const char*> allowed) const;

  std::string string() const;  // "must be a string, is <type>"
  bool boolean() const;        // "must be true or false, is <type>"
  double number() const;       // "must be a number, is <type>", "must be finite"
  // A whole number in [lo, hi] (2 and 2.0 are both 2): "must be an integer, is a fraction",
  // "must be <lo> to <hi>, is <value>".
  uint32_t integer(uint64_t lo, uint64_t hi) const;
  Eigen::Vector3d vec3() const;  // "must be an array of 3 numbers"
  // A number in [lo, hi]: "<value> is outside <lo>..<hi>".
  double number(double lo, double hi) const;
  // A whole number in [lo, hi], as a double (seeds up to 2^53): "must be an integer, is a fraction",
  // "<value> is outside <lo>..<hi>".
  double wholeNumber(double lo, double hi) const;
  std::string nonEmptyString() const;  // "must be a non-empty string"
  // A non-empty array of non-empty strings: "must be a non-empty array of strings",
  // "must hold non-empty strings only".
  std::vector<std::string> strings() const;

  // Optional members of an object.
  double number(const char* key, double lo, double hi, double fallback) const;
  double wholeNumber(const char* key, double lo, double hi, double fallback) const;
  bool boolean(const char* key, bool fallback) const;
  std::string nonEmptyString(const char* key, const std::string& fallback) const;
  std::vector<std::string> strings(const char* key, std::vector<std::string> fallback) const;

 private:
  const nlohmann::json& j_;
  std::string source_, path_;
};

}  // namespace swish
