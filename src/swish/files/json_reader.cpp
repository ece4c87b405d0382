#include "swish/files/json_reader.hpp"

#include <cmath>
#include <set>
#include <sstream>
#include <utility>

#include "swish/core/error.hpp"

namespace swish {

using nlohmann::json;

JsonReader::JsonReader(const json& value, std::string source, std::string path)
    : j_(value), source_(std::move(source)), path_(std::move(path)) {}

void JsonReader::fail(const std::string& problem) const {
  throw Error((source_.empty() ? std::string() : source_ + ": ") +
              (path_.empty() ? std::string("(top level)") : path_) + ": " + problem);
}

void JsonReader::requireObject(std::initializer_list<const char*> allowed) const {
  if (!j_.is_object()) fail("must be a JSON object, is " + std::string(j_.type_name()));
  const std::set<std::string> ok(allowed.begin(), allowed.end());
  for (const auto& [key, v] : j_.items())
    if (!ok.count(key)) {
      std::string list;
      for (const auto& k : ok) list += (list.empty() ? "" : ", ") + k;
      child(key).fail("unknown key (allowed here: " + list + ")");
    }
}

JsonReader JsonReader::child(const std::string& key) const {
  static const json null;
  const json& v = j_.contains(key) ? j_.at(key) : null;
  return JsonReader(v, source_, path_.empty() ? key : path_ + "." + key);
}

JsonReader JsonReader::at(size_t i) const {
  return JsonReader(j_.at(i), source_, path_ + "[" + std::to_string(i) + "]");
}

JsonReader JsonReader::required(const char* key) const {
  if (!j_.contains(key)) child(key).fail("is required");
  return child(key);
}

JsonReader JsonReader::section(const std::string& key, std::initializer_list<const char*> allowed) const {
  static const json empty = json::object();
  JsonReader r = j_.contains(key) ? child(key) : JsonReader(empty, source_, child(key).path());
  r.requireObject(allowed);
  return r;
}

std::string JsonReader::string() const {
  if (!j_.is_string()) fail("must be a string, is " + std::string(j_.type_name()));
  return j_.get<std::string>();
}

bool JsonReader::boolean() const {
  if (!j_.is_boolean()) fail("must be true or false, is " + std::string(j_.type_name()));
  return j_.get<bool>();
}

double JsonReader::number() const {
  if (!j_.is_number()) fail("must be a number, is " + std::string(j_.type_name()));
  const double v = j_.get<double>();
  if (!std::isfinite(v)) fail("must be finite");
  return v;
}

uint32_t JsonReader::integer(uint64_t lo, uint64_t hi) const {
  if (!j_.is_number_integer() && !(j_.is_number_float() && j_.get<double>() == std::floor(j_.get<double>())))
    fail("must be an integer, is " + std::string(j_.is_number() ? "a fraction" : j_.type_name()));
  const double v = j_.get<double>();
  if (v < double(lo) || v > double(hi))
    fail("must be " + std::to_string(lo) + " to " + std::to_string(hi) + ", is " + j_.dump());
  return uint32_t(v);
}

Eigen::Vector3d JsonReader::vec3() const {
  if (!j_.is_array() || j_.size() != 3) fail("must be an array of 3 numbers");
  Eigen::Vector3d v;
  for (size_t i = 0; i < 3; ++i) v[Eigen::Index(i)] = at(i).number();
  return v;
}

namespace {
std::string outside(double v, double lo, double hi) {
  std::ostringstream s;
  s << v << " is outside " << lo << ".." << hi;
  return s.str();
}
}  // namespace

double JsonReader::number(double lo, double hi) const {
  const double v = number();
  if (!(v >= lo && v <= hi)) fail(outside(v, lo, hi));
  return v;
}

double JsonReader::wholeNumber(double lo, double hi) const {
  const double v = number();
  if (!j_.is_number_integer() && v != std::floor(v)) fail("must be an integer, is a fraction");
  if (!(v >= lo && v <= hi)) fail(outside(v, lo, hi));
  return v;
}

std::string JsonReader::nonEmptyString() const {
  if (!j_.is_string()) fail("must be a non-empty string, is " + std::string(j_.type_name()));
  if (j_.get<std::string>().empty()) fail("must be a non-empty string");
  return j_.get<std::string>();
}

std::vector<std::string> JsonReader::strings() const {
  if (!j_.is_array() || j_.empty()) fail("must be a non-empty array of strings");
  std::vector<std::string> out;
  for (const auto& e : j_) {
    if (!e.is_string() || e.get<std::string>().empty()) fail("must hold non-empty strings only");
    out.push_back(e.get<std::string>());
  }
  return out;
}

double JsonReader::number(const char* key, double lo, double hi, double fallback) const {
  return has(key) ? child(key).number(lo, hi) : fallback;
}

double JsonReader::wholeNumber(const char* key, double lo, double hi, double fallback) const {
  return has(key) ? child(key).wholeNumber(lo, hi) : fallback;
}

bool JsonReader::boolean(const char* key, bool fallback) const { return has(key) ? child(key).boolean() : fallback; }

std::string JsonReader::nonEmptyString(const char* key, const std::string& fallback) const {
  return has(key) ? child(key).nonEmptyString() : fallback;
}

std::vector<std::string> JsonReader::strings(const char* key, std::vector<std::string> fallback) const {
  return has(key) ? child(key).strings() : std::move(fallback);
}

}  // namespace swish
