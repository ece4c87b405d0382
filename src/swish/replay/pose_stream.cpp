#include "swish/replay/pose_stream.hpp"

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/files/json_file.hpp"

namespace swish::replay {

namespace {

using nlohmann::json;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

float component(const json& v, const std::string& where) {
  if (v.is_null()) return kNaN;
  if (!v.is_number()) throw Error(where + ": must be a number or null");
  return v.get<float>();
}

json number(float f) { return std::isfinite(f) ? json(f) : json(nullptr); }

}  // namespace

PoseStream readPoseStream(const std::filesystem::path& file) {
  const std::string src = file.string();
  const json j = readJsonFile(file, "pose stream");
  if (!j.is_object() || j.value("format", "") != "swish-pose-stream")
    throw Error(src + ": format: must be \"swish-pose-stream\"");
  if (j.value("version", 0) != 1) throw Error(src + ": version: only version 1 is supported");
  PoseStream s;
  s.name = file.stem().string();
  if (j.contains("framesPerSecond")) {
    if (!j["framesPerSecond"].is_number() || !(j["framesPerSecond"].get<double>() > 0))
      throw Error(src + ": framesPerSecond: must be a positive number");
    s.framesPerSecond = j["framesPerSecond"].get<double>();
  }
  if (!j.contains("joints") || !j["joints"].is_array() || j["joints"].empty())
    throw Error(src + ": joints: must be a non-empty array of names");
  for (size_t i = 0; i < j["joints"].size(); ++i) {
    if (!j["joints"][i].is_string()) throw Error(src + ": joints[" + std::to_string(i) + "]: must be a string");
    s.joints.push_back(j["joints"][i].get<std::string>());
  }
  if (!j.contains("frames") || !j["frames"].is_array() || j["frames"].empty())
    throw Error(src + ": frames: must be a non-empty array");
  for (size_t f = 0; f < j["frames"].size(); ++f) {
    const json& fj = j["frames"][f];
    const std::string at = src + ": frames[" + std::to_string(f) + "]";
    if (!fj.is_object()) throw Error(at + ": must be an object");
    PoseStreamFrame frame;
    frame.rotations.assign(s.joints.size(), Quatf::Identity());
    frame.present.assign(s.joints.size(), false);
    if (fj.contains("root")) {
      if (!fj["root"].is_array() || fj["root"].size() != 3) throw Error(at + ".root: must be an array of 3 numbers");
      for (int k = 0; k < 3; ++k) frame.root[k] = component(fj["root"][size_t(k)], at + ".root");
    }
    if (!fj.contains("rotations") || !fj["rotations"].is_array()) throw Error(at + ".rotations: must be an array");
    const json& rj = fj["rotations"];
    if (rj.size() > s.joints.size()) throw Error(at + ".rotations: more rotations than joints");
    for (size_t r = 0; r < rj.size(); ++r) {
      if (rj[r].is_null()) continue;
      const std::string ra = at + ".rotations[" + std::to_string(r) + "]";
      if (!rj[r].is_array() || rj[r].size() != 4) throw Error(ra + ": must be [x, y, z, w] or null");
      frame.rotations[r] =
          Quatf(component(rj[r][3], ra), component(rj[r][0], ra), component(rj[r][1], ra), component(rj[r][2], ra));
      frame.present[r] = true;
    }
    s.frames.push_back(std::move(frame));
  }
  return s;
}

void writePoseStream(const std::filesystem::path& file, const PoseStream& s) {
  json j{{"format", "swish-pose-stream"}, {"version", 1}, {"framesPerSecond", s.framesPerSecond}, {"joints", s.joints}};
  j["frames"] = json::array();
  for (const auto& f : s.frames) {
    json rot = json::array();
    for (size_t r = 0; r < f.rotations.size(); ++r) {
      if (r < f.present.size() && !f.present[r]) {
        rot.push_back(nullptr);
        continue;
      }
      const Quatf& q = f.rotations[r];
      rot.push_back({number(q.x()), number(q.y()), number(q.z()), number(q.w())});
    }
    j["frames"].push_back({{"root", {number(f.root.x()), number(f.root.y()), number(f.root.z())}}, {"rotations", rot}});
  }
  writeTextFileAtomic(file, j.dump(1));
}

}  // namespace swish::replay
