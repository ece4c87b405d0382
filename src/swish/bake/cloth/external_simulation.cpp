#include "swish/bake/cloth/external_simulation.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "swish/core/error.hpp"
#include "swish/core/hash.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/io/mesh_import.hpp"

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
      if (root >= 0)
        throw Error("BVH export: the skeleton has more than one root ('" + sk.joints[size_t(root)].name + "', '" +
                    sk.joints[j].name + "'); BVH holds one hierarchy");
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
  nlohmann::json j = {
      {"clip", bvhPath.filename().string()},
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

std::string objText(const Points3f& p, const Triangles& t, const std::string& comment) {
  std::string o;
  o.reserve(size_t(p.rows()) * 40 + size_t(t.rows()) * 24 + comment.size() + 8);
  if (!comment.empty()) o += "# " + comment + "\n";
  char line[128];
  for (Eigen::Index v = 0; v < p.rows(); ++v) {
    std::snprintf(line, sizeof line, "v %.9g %.9g %.9g\n", double(p(v, 0)), double(p(v, 1)), double(p(v, 2)));
    o += line;
  }
  for (Eigen::Index f = 0; f < t.rows(); ++f) {
    std::snprintf(line, sizeof line, "f %u %u %u\n", t(f, 0) + 1, t(f, 1) + 1, t(f, 2) + 1);
    o += line;
  }
  return o;
}

Vec3f ExternalSimulationSettings::toCharacter(const Vec3d& p) const {
  if (!worldSpace) return p.cast<float>();
  const Vec3d q = (p - origin) / unitsPerMetre;
  return (upAxis == 'z' ? Vec3d(q.x(), q.z(), -q.y()) : q).cast<float>();
}

nlohmann::json ExternalSimulationSettings::toJson() const {
  nlohmann::json j = {{"source", "external"}, {"path", path.string()}, {"space", worldSpace ? "world" : "character"}};
  if (worldSpace) {
    j["units_per_metre"] = unitsPerMetre;
    j["up_axis"] = std::string(1, upAxis);
    j["origin"] = {origin.x(), origin.y(), origin.z()};
  }
  return j;
}

namespace {

constexpr const char* kResultExtensions[] = {".obj", ".glb", ".gltf", ".fbx"};
// A re-meshed garment's rest shape must lie on the simulation mesh: farther than this, it is in
// another space or another garment, and binding would make every pose wrong.
constexpr float kMaxRestBindingDistance = 0.05f;

uint64_t edgeKey(uint32_t a, uint32_t b) { return a < b ? uint64_t(a) << 32 | b : uint64_t(b) << 32 | a; }

std::string lowerExtension(const std::filesystem::path& f) {
  std::string e = f.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return e;
}

bool isGarmentName(std::string n) {
  std::transform(n.begin(), n.end(), n.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  for (const char* k : {"garment", "cloth", "shirt", "jersey", "simulation"})
    if (n.find(k) != std::string::npos) return true;
  return false;
}

// The garment among a file's meshes: the only one, or the only one named like a garment.
const io::ImportedMesh& pickGarment(const std::vector<io::ImportedMesh>& meshes, const std::filesystem::path& file) {
  if (meshes.size() == 1) return meshes[0];
  const io::ImportedMesh* hit = nullptr;
  std::string names;
  for (const auto& m : meshes) {
    names += (names.empty() ? "'" : ", '") + m.name + "'";
    if (isGarmentName(m.name)) {
      if (hit) throw Error(file.string() + ": several meshes are named like a garment (" + names + "...): keep one");
      hit = &m;
    }
  }
  if (!hit)
    throw Error(file.string() + ": " + std::to_string(meshes.size()) + " meshes (" + names +
                "), none named garment/cloth/shirt/jersey: keep only the garment in the file");
  return *hit;
}

struct FileMesh {
  Points3f positions;
  Triangles triangles;
};

FileMesh readMeshFile(const std::filesystem::path& file) {
  if (lowerExtension(file) == ".obj") {
    ObjMesh m = readObj(file);
    return {std::move(m.positions), std::move(m.triangles)};
  }
  const std::vector<io::ImportedMesh> meshes = io::importMeshes(file);
  const io::ImportedMesh& g = pickGarment(meshes, file);
  return {g.positions, g.triangles};
}

void hashFile(Fnv1a& h, const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file.string() + ": cannot read");
  const std::string name = file.filename().string();
  h.bytes(name.data(), name.size());
  std::vector<char> buf(1 << 16);
  while (in) {
    in.read(buf.data(), std::streamsize(buf.size()));
    h.bytes(buf.data(), size_t(in.gcount()));
  }
}

}  // namespace

std::vector<std::filesystem::path> externalPoseCandidates(const std::filesystem::path& folder, uint32_t id) {
  char stem[32];
  std::snprintf(stem, sizeof stem, "pose_%06u", id);
  std::vector<std::filesystem::path> out;
  for (const char* e : kResultExtensions) out.push_back(folder / (std::string(stem) + e));
  return out;
}

ExternalShapeSource::~ExternalShapeSource() = default;

ExternalShapeSource::ExternalShapeSource(const ExternalSimulationSettings& settings, const Points3f& simRest,
                                         const Triangles& simTriangles, const std::vector<uint32_t>& targetFrames,
                                         uint64_t poseListDigest)
    : settings_(settings), simRest_(simRest), targetFrames_(targetFrames) {
  namespace fs = std::filesystem;
  const fs::path& path = settings.path;
  if (!(settings.unitsPerMetre > 0.0) || (settings.upAxis != 'y' && settings.upAxis != 'z'))
    throw Error("external simulation: units per metre must be positive and the up axis y or z");
  for (Eigen::Index t = 0; t < simTriangles.rows(); ++t)
    for (int k = 0; k < 3; ++k) simEdges_.push_back(edgeKey(simTriangles(t, k), simTriangles(t, (k + 1) % 3)));
  std::sort(simEdges_.begin(), simEdges_.end());
  simEdges_.erase(std::unique(simEdges_.begin(), simEdges_.end()), simEdges_.end());
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(path.string() + ": the external simulation results are not there");
  const std::string space = settings.worldSpace ? "world space" : "character space";

  auto bindRest = [&](const Points3f& rest, const Triangles& tris, const std::string& what) {
    if (tris.rows() == 0) throw Error(what + ": the re-meshed garment's rest mesh needs its faces to bind to");
    restBinding_ = std::make_unique<MeshTransfer>(rest, tris, simRest_, what);
    restVertexCount_ = size_t(rest.rows());
    restFile_ = what;
    if (restBinding_->maxBindingDistance() > kMaxRestBindingDistance) {
      char d[64];
      std::snprintf(d, sizeof d, "%.1f mm", 1000.0 * restBinding_->maxBindingDistance());
      throw Error(what + ": the re-meshed garment's rest shape is " + d +
                  " from the simulation mesh (garment.obj) at its farthest vertex (bound 50 mm): is it in the " +
                  space + " the config states, and the same garment in the rest pose?");
    }
  };
  auto toCharacter = [&](const Points3f& p) {
    Points3f out(p.rows(), 3);
    for (Eigen::Index v = 0; v < p.rows(); ++v)
      out.row(v) = settings_.toCharacter(p.row(v).transpose().cast<double>()).transpose();
    return out;
  };

  Fnv1a h;
  if (fs::is_directory(path, ec)) {
    // The export's poses.json beside the results says which pose list they were made for.
    for (const fs::path& sidecar : {path / "poses.json", path.parent_path() / "poses.json"}) {
      if (!fs::is_regular_file(sidecar, ec)) continue;
      nlohmann::json j;
      try {
        j = nlohmann::json::parse(std::ifstream(sidecar));
      } catch (const nlohmann::json::exception& e) {
        throw Error(sidecar.string() + ": not valid JSON (" + e.what() + ")");
      }
      if (j.contains("pose_list_digest") && j["pose_list_digest"] != std::to_string(poseListDigest))
        throw Error(sidecar.string() +
                    ": these results were exported for another pose list than the recipe makes now "
                    "(its clips, sampling, thinning or limb clearance changed since 'swish bake --export-poses'): "
                    "export again and simulate the new poses");
      break;
    }
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(path))
      if (e.is_regular_file()) {
        const std::string n = e.path().filename().string();
        if (n.rfind("pose_", 0) == 0 || n.rfind("rest.", 0) == 0) files.push_back(e.path());
      }
    std::sort(files.begin(), files.end());
    for (const fs::path& f : files) hashFile(h, f);
    for (const char* ext : kResultExtensions) {
      const fs::path rest = path / (std::string("rest") + ext);
      if (!fs::is_regular_file(rest, ec)) continue;
      const FileMesh m = readMeshFile(rest);
      if (!m.positions.allFinite()) throw Error(rest.string() + ": non-finite vertex positions");
      bindRest(toCharacter(m.positions), m.triangles, rest.string());
      break;
    }
    description_ = "external simulation: folder " + path.string() + " (" + std::to_string(files.size()) + " files, " +
                   space + (restBinding_ ? "; re-meshed shapes bound through " + restFile_ : "") + ")";
  } else {
    multiFrame_ = true;
    hashFile(h, path);
    const std::vector<io::ImportedMesh> meshes = io::importMeshes(path);
    std::vector<io::ImportedMesh> withFrames;
    for (const auto& m : meshes)
      if (!m.frames.empty()) withFrames.push_back(m);
    if (withFrames.empty())
      throw Error(path.string() +
                  ": no mesh with frames (morph targets / blend shapes) in the file; give a folder of "
                  "pose_<id>.obj files instead, or store one shape per pose as morph targets");
    const io::ImportedMesh& g = pickGarment(withFrames, path);
    const size_t n = g.frames.size(), poses = targetFrames.size();
    uint32_t clipFrames = 0;
    for (uint32_t f : targetFrames) clipFrames = std::max(clipFrames, f + 1);
    frames_.assign(poses, std::nullopt);
    std::string how;
    bool byName = true;
    std::vector<std::pair<uint32_t, size_t>> named;
    for (size_t k = 0; k < n && byName; ++k) {
      unsigned id = 0;
      char tail = 0;
      byName = std::sscanf(g.frames[k].first.c_str(), "pose_%u%c", &id, &tail) == 1 && id < poses;
      named.emplace_back(uint32_t(id), k);
    }
    if (byName) {
      for (const auto& [id, k] : named) frames_[id] = toCharacter(g.frames[k].second);
      how = "morph targets matched by name";
    } else if (n == poses) {
      for (size_t k = 0; k < n; ++k) frames_[k] = toCharacter(g.frames[k].second);
      how = "one morph target per pose, in pose order";
    } else if (n == clipFrames) {
      for (size_t id = 0; id < poses; ++id) frames_[id] = toCharacter(g.frames[targetFrames[id]].second);
      how = "one morph target per clip frame, each pose at its target frame";
    } else {
      throw Error(path.string() + ": mesh '" + g.name + "' has " + std::to_string(n) +
                  " frames; expected one per pose (" + std::to_string(poses) +
                  "), one per frame of the exported clip (" + std::to_string(clipFrames) +
                  "), or frames named pose_<id>");
    }
    frameTriangles_ = g.triangles;
    const Points3f base = toCharacter(g.positions);
    const bool sameMesh = size_t(base.rows()) == size_t(simRest_.rows());
    bool sameEdges = sameMesh;
    for (Eigen::Index t = 0; t < g.triangles.rows() && sameEdges; ++t)
      for (int k = 0; k < 3 && sameEdges; ++k)
        sameEdges = std::binary_search(simEdges_.begin(), simEdges_.end(),
                                       edgeKey(g.triangles(t, k), g.triangles(t, (k + 1) % 3)));
    if (!sameEdges) bindRest(base, g.triangles, path.string() + " (mesh '" + g.name + "', its base shape)");
    description_ = "external simulation: " + path.string() + ", mesh '" + g.name + "', " + std::to_string(n) +
                   " frames (" + how + ", " + space +
                   (restBinding_ ? "; re-meshed, bound through its base shape" : "") + ")";
  }
  digest_ = h.h;
}

float ExternalShapeSource::maxBindingDistance() const {
  return restBinding_ ? restBinding_->maxBindingDistance() : 0.f;
}

std::string ExternalShapeSource::description() const { return description_; }

Points3f ExternalShapeSource::fromMesh(const Points3f& p, const Triangles& tris, const std::string& what) const {
  if (!p.allFinite()) throw Error(what + ": non-finite vertex positions");
  const size_t n = size_t(p.rows()), simN = size_t(simRest_.rows());
  bool sameEdges = n == simN;
  for (Eigen::Index t = 0; t < tris.rows() && sameEdges; ++t)
    for (int k = 0; k < 3 && sameEdges; ++k)
      sameEdges = std::binary_search(simEdges_.begin(), simEdges_.end(), edgeKey(tris(t, k), tris(t, (k + 1) % 3)));
  if (sameEdges && !restBinding_) return p;
  if (sameEdges && restBinding_ && n != restVertexCount_) return p;
  if (restBinding_ && n == restVertexCount_) return restBinding_->follow(p);
  std::string why = what + ": " + std::to_string(n) + " vertices";
  if (n == simN)
    why += " in another order than the simulation mesh (its faces are not garment.obj's)";
  else
    why += ", the simulation mesh (garment.obj) has " + std::to_string(simN);
  if (restBinding_)
    why += ", the re-meshed rest mesh " + restFile_ + " " + std::to_string(restVertexCount_);
  else
    why +=
        "; a re-meshed garment needs its rest shape beside the poses (rest.obj, same vertex order as the pose files)";
  throw Error(why);
}

Points3f ExternalShapeSource::shape(uint32_t id) const {
  namespace fs = std::filesystem;
  if (id >= targetFrames_.size())
    throw Error("external simulation: pose " + std::to_string(id) + " is not in the pose list (" +
                std::to_string(targetFrames_.size()) + " poses)");
  if (multiFrame_) {
    if (!frames_[id]) throw Error(settings_.path.string() + ": no frame named pose_" + std::to_string(id));
    return fromMesh(*frames_[id], frameTriangles_, settings_.path.string() + " frame of pose " + std::to_string(id));
  }
  std::vector<fs::path> found;
  std::error_code ec;
  const std::vector<fs::path> candidates = externalPoseCandidates(settings_.path, id);
  for (const fs::path& c : candidates)
    if (fs::exists(c, ec)) found.push_back(c);
  if (found.empty()) throw Error(candidates[0].string() + ": missing (also looked for .glb, .gltf and .fbx)");
  if (found.size() > 1)
    throw Error(found[0].string() + " and " + found[1].string() + ": two results for one pose; keep one");
  FileMesh m = readMeshFile(found[0]);
  Points3f c(m.positions.rows(), 3);
  if (!m.positions.allFinite()) throw Error(found[0].string() + ": non-finite vertex positions");
  for (Eigen::Index v = 0; v < c.rows(); ++v)
    c.row(v) = settings_.toCharacter(m.positions.row(v).transpose().cast<double>()).transpose();
  return fromMesh(c, m.triangles, found[0].string());
}

}  // namespace swish::bake
