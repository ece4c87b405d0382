#include "swish/replay/pose_stream.hpp"

#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/files/json_file.hpp"
#include "swish/files/json_reader.hpp"

namespace swish::replay {

namespace {

using nlohmann::json;
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A coordinate: a number, or null for a value the source did not have (NaN).
float component(const JsonReader& r) {
  if (r.value().is_null()) return kNaN;
  if (!r.value().is_number()) r.fail("must be a number or null");
  return r.value().get<float>();
}

json number(float f) { return std::isfinite(f) ? json(f) : json(nullptr); }

}  // namespace

PoseStream readPoseStream(const std::filesystem::path& file) {
  const json j = readJsonFile(file, "pose stream");
  const JsonReader root(j, file.string());
  const JsonReader format = root.child("format");
  if (!j.is_object() || !format.value().is_string() || format.value().get<std::string>() != "swish-pose-stream")
    format.fail("must be \"swish-pose-stream\"");
  // As before the reader was shared: a number whose whole part is 1 (or true) reads as version 1.
  const JsonReader version = root.child("version");
  if (!(version.value().is_number() || version.value().is_boolean()) || version.value().get<int>() != 1)
    version.fail("only version 1 is supported");
  PoseStream s;
  s.name = file.stem().string();
  if (root.has("framesPerSecond")) {
    const JsonReader fps = root.child("framesPerSecond");
    if (!fps.value().is_number() || !(fps.value().get<double>() > 0)) fps.fail("must be a positive number");
    s.framesPerSecond = fps.value().get<double>();
  }
  const JsonReader joints = root.child("joints");
  if (!joints.value().is_array() || joints.value().empty()) joints.fail("must be a non-empty array of names");
  for (size_t i = 0; i < joints.value().size(); ++i) s.joints.push_back(joints.at(i).string());
  const JsonReader frames = root.child("frames");
  if (!frames.value().is_array() || frames.value().empty()) frames.fail("must be a non-empty array");
  for (size_t f = 0; f < frames.value().size(); ++f) {
    const JsonReader fr = frames.at(f);
    if (!fr.value().is_object()) fr.fail("must be an object");
    PoseStreamFrame frame;
    frame.rotations.assign(s.joints.size(), Quatf::Identity());
    frame.present.assign(s.joints.size(), false);
    if (fr.has("root")) {
      const JsonReader rootPosition = fr.child("root");
      if (!rootPosition.value().is_array() || rootPosition.value().size() != 3)
        rootPosition.fail("must be an array of 3 numbers");
      for (size_t k = 0; k < 3; ++k) frame.root[Eigen::Index(k)] = component(rootPosition.at(k));
    }
    const JsonReader rotations = fr.child("rotations");
    if (!rotations.value().is_array()) rotations.fail("must be an array");
    if (rotations.value().size() > s.joints.size()) rotations.fail("more rotations than joints");
    for (size_t r = 0; r < rotations.value().size(); ++r) {
      const JsonReader q = rotations.at(r);
      if (q.value().is_null()) continue;
      if (!q.value().is_array() || q.value().size() != 4) q.fail("must be [x, y, z, w] or null");
      frame.rotations[r] = Quatf(component(q.at(3)), component(q.at(0)), component(q.at(1)), component(q.at(2)));
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
