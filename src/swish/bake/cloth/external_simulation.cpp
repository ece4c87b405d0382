#include "swish/bake/cloth/external_simulation.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"

namespace swish::bake {
namespace {

// Intrinsic Z-X-Y Euler angles (degrees) of a rotation matrix M = Rz(z) * Rx(x) * Ry(y).
Vec3f eulerZXYDegrees(const Mat3f& m) {
  const float sx = std::clamp(m(2, 1), -1.f, 1.f);
  const float x = std::asin(sx);
  float z, y;
  if (std::abs(sx) < 0.9999f) {
    z = std::atan2(-m(0, 1), m(1, 1));
    y = std::atan2(-m(2, 0), m(2, 2));
  } else {  // gimbal lock: put everything into z
    z = std::atan2(m(1, 0), m(0, 0));
    y = 0.f;
  }
  const float k = 180.f / float(M_PI);
  return {z * k, x * k, y * k};
}

void writeJoint(std::ostringstream& o, const Skeleton& sk, const std::vector<std::vector<int>>& children, int j,
                int depth) {
  const std::string pad(size_t(depth) * 2, ' ');
  const Vec3f off = sk.joints[size_t(j)].rest.translation;
  o << pad << (depth == 0 ? "ROOT " : "JOINT ") << sk.joints[size_t(j)].name << "\n" << pad << "{\n";
  o << pad << "  OFFSET " << off.x() << " " << off.y() << " " << off.z() << "\n";
  if (depth == 0)
    o << pad << "  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation\n";
  else
    o << pad << "  CHANNELS 3 Zrotation Xrotation Yrotation\n";
  for (int c : children[size_t(j)]) writeJoint(o, sk, children, c, depth + 1);
  if (children[size_t(j)].empty())
    o << pad << "  End Site\n" << pad << "  {\n" << pad << "    OFFSET 0 0 0\n" << pad << "  }\n";
  o << pad << "}\n";
}

void motionOrder(const std::vector<std::vector<int>>& children, int j, std::vector<int>& order) {
  order.push_back(j);
  for (int c : children[size_t(j)]) motionOrder(children, c, order);
}

}  // namespace

std::string bvhText(const Skeleton& sk, const std::vector<Pose>& frames, float fps) {
  sk.validate("BVH export");
  if (!(fps > 0.f)) throw Error("BVH export: frames per second must be positive");
  std::vector<std::vector<int>> children(sk.size());
  int root = -1;
  for (size_t j = 0; j < sk.size(); ++j) {
    const int p = sk.joints[j].parent;
    if (p < 0) {
      if (root >= 0) throw Error("BVH export: the skeleton has more than one root ('" + sk.joints[size_t(root)].name +
                                 "', '" + sk.joints[j].name + "'); BVH holds one hierarchy");
      root = int(j);
    } else {
      children[size_t(p)].push_back(int(j));
    }
  }
  if (root < 0) throw Error("BVH export: the skeleton has no root");
  std::ostringstream o;
  o.precision(9);
  o << "HIERARCHY\n";
  writeJoint(o, sk, children, root, 0);
  std::vector<int> order;
  motionOrder(children, root, order);
  o << "MOTION\nFrames: " << frames.size() << "\nFrame Time: " << 1.0 / double(fps) << "\n";
  for (size_t f = 0; f < frames.size(); ++f) {
    const Pose& p = frames[f];
    if (p.local.size() != sk.size())
      throw Error("BVH export: frame " + std::to_string(f) + " has " + std::to_string(p.local.size()) +
                  " rotations for " + std::to_string(sk.size()) + " joints");
    o << p.rootTranslation.x() << " " << p.rootTranslation.y() << " " << p.rootTranslation.z();
    for (int j : order) {
      const Vec3f e = eulerZXYDegrees(p.local[size_t(j)].normalized().toRotationMatrix());
      o << " " << e.x() << " " << e.y() << " " << e.z();
    }
    o << "\n";
  }
  return o.str();
}

std::vector<Pose> buildTransitionFrames(const Skeleton& sk, const std::vector<Pose>& poses,
                                        const TransitionClipSettings& s, std::vector<TransitionMarker>& markers) {
  if (!(s.framesPerSecond > 0.f) || !(s.transitionSeconds > 0.f) || !(s.holdSeconds >= 0.f))
    throw Error("transition clip: frames per second and transition time must be positive, hold time >= 0");
  const int transition = std::max(1, int(std::lround(s.transitionSeconds * s.framesPerSecond)));
  const int hold = int(std::lround(s.holdSeconds * s.framesPerSecond));
  const Pose rest = sk.restPose();
  std::vector<Pose> frames;
  markers.clear();
  for (size_t i = 0; i < poses.size(); ++i) {
    const Pose& target = poses[i];
    if (target.local.size() != sk.size())
      throw Error("transition clip: pose " + std::to_string(i) + " has " + std::to_string(target.local.size()) +
                  " rotations for " + std::to_string(sk.size()) + " joints");
    TransitionMarker m;
    m.poseId = uint32_t(i);
    m.firstFrame = uint32_t(frames.size());
    for (int f = 0; f <= transition; ++f) {
      const float t = float(f) / float(transition);
      const float e = t * t * (3.f - 2.f * t);  // smoothstep
      Pose p;
      p.local.resize(sk.size());
      for (size_t j = 0; j < sk.size(); ++j) p.local[j] = rest.local[j].slerp(e, target.local[j]).normalized();
      p.rootTranslation = (1.f - e) * rest.rootTranslation + e * target.rootTranslation;
      frames.push_back(std::move(p));
    }
    for (int f = 0; f < hold; ++f) frames.push_back(target);
    m.targetFrame = uint32_t(frames.size() - 1);
    markers.push_back(m);
  }
  return frames;
}

void writeTransitionBvh(const std::filesystem::path& bvhPath, const Skeleton& sk, const std::vector<Pose>& poses,
                        const TransitionClipSettings& s) {
  std::vector<TransitionMarker> markers;
  const std::vector<Pose> frames = buildTransitionFrames(sk, poses, s, markers);
  nlohmann::json j = {{"clip", bvhPath.filename().string()},
                      {"framesPerSecond", s.framesPerSecond},
                      {"transitionSeconds", s.transitionSeconds},
                      {"holdSeconds", s.holdSeconds},
                      {"note", "export the cloth at targetFrame of each pose, keeping the simulation mesh's vertex order"},
                      {"poses", nlohmann::json::array()}};
  for (const auto& m : markers)
    j["poses"].push_back({{"id", m.poseId}, {"firstFrame", m.firstFrame}, {"targetFrame", m.targetFrame}});
  writeTextFileAtomic(bvhPath, bvhText(sk, frames, s.framesPerSecond));
  std::filesystem::path sidecar = bvhPath;
  sidecar += ".markers.json";
  writeTextFileAtomic(sidecar, j.dump(2));
}

ObjMesh readObj(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw Error(path.string() + ": cannot open the OBJ file");
  std::vector<float> v;
  std::vector<uint32_t> tris;
  std::string line;
  size_t lineNo = 0;
  auto fail = [&](const std::string& why) -> Error {
    return Error(path.string() + ":" + std::to_string(lineNo) + ": " + why);
  };
  while (std::getline(in, line)) {
    ++lineNo;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string tag;
    if (!(ls >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      float xyz[3];
      for (float& c : xyz) {
        std::string tok;
        if (!(ls >> tok)) throw fail("a vertex needs 3 coordinates");
        const char* b = tok.data();
        const auto r = std::from_chars(b, b + tok.size(), c);
        if (r.ec != std::errc() || r.ptr != b + tok.size() || !std::isfinite(c))
          throw fail("bad vertex coordinate '" + tok + "'");
      }
      v.insert(v.end(), xyz, xyz + 3);
    } else if (tag == "f") {
      std::vector<uint32_t> poly;
      std::string tok;
      const long long count = (long long)(v.size() / 3);
      while (ls >> tok) {
        const std::string first = tok.substr(0, tok.find('/'));
        long long idx = 0;
        const auto r = std::from_chars(first.data(), first.data() + first.size(), idx);
        if (r.ec != std::errc() || r.ptr != first.data() + first.size() || idx == 0)
          throw fail("bad face index '" + tok + "'");
        const long long abs = idx > 0 ? idx - 1 : count + idx;
        if (abs < 0 || abs >= count)
          throw fail("face index " + std::to_string(idx) + " refers to a vertex not defined yet (" +
                     std::to_string(count) + " so far)");
        poly.push_back(uint32_t(abs));
      }
      if (poly.size() < 3) throw fail("a face needs at least 3 vertices");
      for (size_t k = 1; k + 1 < poly.size(); ++k) tris.insert(tris.end(), {poly[0], poly[k], poly[k + 1]});
    }
  }
  if (in.bad()) throw Error(path.string() + ": read failed");
  if (v.empty()) throw Error(path.string() + ": no vertices");
  ObjMesh m;
  m.positions = Eigen::Map<const Points3f>(v.data(), Eigen::Index(v.size() / 3), 3);
  m.triangles = Eigen::Map<const Triangles>(tris.data(), Eigen::Index(tris.size() / 3), 3);
  return m;
}

Points3f importSimulatedPositions(const std::filesystem::path& objPath, size_t simulationVertexCount) {
  ObjMesh m = readObj(objPath);
  if (size_t(m.positions.rows()) != simulationVertexCount)
    throw Error(objPath.string() + ": " + std::to_string(m.positions.rows()) + " vertices, the simulation mesh has " +
                std::to_string(simulationVertexCount) + " (the external tool must keep the vertex count and order)");
  return std::move(m.positions);
}

}  // namespace swish::bake
