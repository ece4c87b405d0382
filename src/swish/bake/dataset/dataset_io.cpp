#include "swish/bake/dataset/dataset_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "swish/bake/dataset/character_snapshot.hpp"
#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/files/byte_reader.hpp"
#include "swish/files/byte_writer.hpp"
#include "swish/files/crc32.hpp"
#include "swish/io/png.hpp"

namespace swish::bake {
namespace fs = std::filesystem;
namespace {

constexpr char kPoseMagic[8] = {'S', 'W', 'D', 'S', 'P', 'O', 'S', 'E'};
constexpr uint32_t kPoseVersion = 1;
constexpr int kManifestVersion = 1;
const char* kNormalMapEncoding =
    "RGB PNG; texel (x, y) covers UV ((x+.5)/width, (y+.5)/height), row 0 is v = 0; red = X, green = Y "
    "as unorm v*0.5+0.5 in the game mesh's tangent frame (core/mesh_frames.hpp); blue = Z = sqrt(1-X^2-Y^2), "
    "ignored on read";

std::vector<uint8_t> readBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open the file");
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(path.string() + ": read failed");
  return bytes;
}

std::string poseName(uint32_t id) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "pose_%05u", id);
  return buf;
}

struct PoseFile {
  DatasetPose pose;
  uint32_t mapWidth = 0, mapHeight = 0;
};

std::vector<uint8_t> encodePoseFile(const DatasetPose& p) {
  ByteWriter w;
  w.bytes({reinterpret_cast<const uint8_t*>(kPoseMagic), 8});
  w.u32(kPoseVersion);
  w.u32(p.id);
  w.u32(uint32_t(p.pose.local.size()));
  w.u32(uint32_t(p.gameMeshWorld.rows()));
  for (const Quatf& q : p.pose.local) w.f32(q.w()), w.f32(q.x()), w.f32(q.y()), w.f32(q.z());
  for (int k = 0; k < 3; ++k) w.f32(p.pose.rootTranslation[k]);
  w.f32s({p.gameMeshWorld.data(), size_t(p.gameMeshWorld.size())});
  w.f32s({p.gameMeshPreSkin.data(), size_t(p.gameMeshPreSkin.size())});
  w.f32(p.residuals.maxConstraintViolation);
  w.f32(p.residuals.maxPenetration);
  w.u32(p.residuals.converged ? 1 : 0);
  w.i32(p.residuals.iterations);
  uint64_t secs;
  std::memcpy(&secs, &p.residuals.seconds, 8);
  w.u64(secs);
  w.u32(p.normalMap.width);
  w.u32(p.normalMap.height);
  w.u32(crc32(w.data()));
  return w.take();
}

PoseFile decodePoseFile(std::span<const uint8_t> bytes, const std::string& what) {
  if (bytes.size() < 16 || std::memcmp(bytes.data(), kPoseMagic, 8) != 0)
    throw Error(what + ": not a swish dataset pose file (bad magic)");
  const size_t n = bytes.size();
  const uint32_t stored = uint32_t(bytes[n - 4]) | uint32_t(bytes[n - 3]) << 8 | uint32_t(bytes[n - 2]) << 16 |
                          uint32_t(bytes[n - 1]) << 24;
  if (crc32(bytes.first(n - 4)) != stored) throw Error(what + ": checksum mismatch (corrupt or truncated file)");
  ByteReader r(bytes.first(n - 4), what, "file");
  r.skip(8, "magic");
  const uint32_t version = r.u32("version");
  if (version != kPoseVersion) r.fail("version " + std::to_string(version) + " (this build reads 1)");
  PoseFile f;
  f.pose.id = r.u32("pose id");
  const size_t joints = r.checkCount(r.u32("joint"), 16, "joint");
  const uint32_t verts = r.u32("vertex");
  r.checkCount(r.multiply(verts, 24, "vertex"), 1, "vertex");
  f.pose.pose.local.resize(joints);
  for (Quatf& q : f.pose.pose.local) {
    const float qw = r.f32("rotation"), qx = r.f32("rotation"), qy = r.f32("rotation"), qz = r.f32("rotation");
    q = Quatf(qw, qx, qy, qz);
  }
  for (int k = 0; k < 3; ++k) f.pose.pose.rootTranslation[k] = r.f32("root translation");
  f.pose.gameMeshWorld.resize(verts, 3);
  f.pose.gameMeshPreSkin.resize(verts, 3);
  r.f32s(f.pose.gameMeshWorld.data(), size_t(verts) * 3, "world positions");
  r.f32s(f.pose.gameMeshPreSkin.data(), size_t(verts) * 3, "pre-skin positions");
  f.pose.residuals.maxConstraintViolation = r.f32("residual");
  f.pose.residuals.maxPenetration = r.f32("residual");
  f.pose.residuals.converged = r.u32("converged") != 0;
  f.pose.residuals.iterations = r.i32("iterations");
  const uint64_t secs = r.u64("seconds");
  std::memcpy(&f.pose.residuals.seconds, &secs, 8);
  f.mapWidth = r.u32("normal map width");
  f.mapHeight = r.u32("normal map height");
  r.expectEnd();
  for (const Quatf& q : f.pose.pose.local)
    if (!q.coeffs().allFinite() || std::abs(q.norm() - 1.f) > 1e-3f)
      r.fail("a joint rotation is not a unit quaternion");
  if (!f.pose.gameMeshWorld.allFinite() || !f.pose.gameMeshPreSkin.allFinite() ||
      !f.pose.pose.rootTranslation.allFinite())
    r.fail("non-finite positions");
  return f;
}

nlohmann::json residualsJson(const SimResiduals& r) {
  return {{"maxConstraintViolation", r.maxConstraintViolation},
          {"maxPenetration", r.maxPenetration},
          {"converged", r.converged},
          {"iterations", r.iterations},
          {"seconds", r.seconds}};
}

}  // namespace

fs::path datasetPosePath(const fs::path& folder, uint32_t id) { return folder / "poses" / (poseName(id) + ".bin"); }
fs::path datasetNormalMapPath(const fs::path& folder, uint32_t id) {
  return folder / "normal_maps" / (poseName(id) + ".png");
}

DatasetWriter::DatasetWriter(fs::path folder, const Character& character, std::vector<uint32_t> inputJoints,
                             nlohmann::json settings, uint32_t bitDepth)
    : folder_(std::move(folder)),
      character_(character),
      inputJoints_(std::move(inputJoints)),
      settings_(std::move(settings)),
      bitDepth_(bitDepth) {
  if (bitDepth != 8 && bitDepth != 16)
    throw Error("dataset " + folder_.string() + ": normal-map bit depth must be 8 or 16");
  for (uint32_t j : inputJoints_)
    if (j >= character.skeleton.size())
      throw Error("dataset " + folder_.string() + ": input joint " + std::to_string(j) + " is not in the skeleton");
  std::error_code ec;
  fs::create_directories(folder_ / "poses", ec);
  if (!ec) fs::create_directories(folder_ / "normal_maps", ec);
  if (ec) throw Error("dataset " + folder_.string() + ": cannot create the folder (" + ec.message() + ")");
  const std::vector<uint8_t> snapshot = encodeCharacterSnapshot(character);
  const fs::path charFile = folder_ / "character.bin";
  if (fs::exists(charFile)) {
    if (readBytes(charFile) != snapshot)
      throw Error(charFile.string() +
                  ": this dataset folder was made for a different character (or different "
                  "meshes); use a new folder or delete it");
  } else {
    writeFileAtomic(charFile, snapshot);
  }
}

bool DatasetWriter::hasPose(uint32_t id) const { return fs::exists(datasetPosePath(folder_, id)); }

void DatasetWriter::writePose(const DatasetPose& p) const {
  const std::string what = "dataset " + folder_.string() + ": pose " + std::to_string(p.id);
  const size_t n = character_.garment.vertexCount();
  if (p.pose.local.size() != character_.skeleton.size())
    throw Error(what + ": " + std::to_string(p.pose.local.size()) + " joint rotations for a skeleton of " +
                std::to_string(character_.skeleton.size()));
  if (size_t(p.gameMeshWorld.rows()) != n || size_t(p.gameMeshPreSkin.rows()) != n)
    throw Error(what + ": game mesh shapes have " + std::to_string(p.gameMeshWorld.rows()) + " / " +
                std::to_string(p.gameMeshPreSkin.rows()) + " vertices, the garment " + std::to_string(n));
  if (!p.gameMeshWorld.allFinite() || !p.gameMeshPreSkin.allFinite()) throw Error(what + ": non-finite positions");
  if (p.normalMap.width == 0 || p.normalMap.xy.size() != size_t(p.normalMap.width) * p.normalMap.height * 2)
    throw Error(what + ": normal map is empty or its size does not match its data");
  io::writePng(datasetNormalMapPath(folder_, p.id),
               io::encodeNormalMap(p.normalMap.width, p.normalMap.height, p.normalMap.xy, bitDepth_));
  writeFileAtomic(datasetPosePath(folder_, p.id), encodePoseFile(p));
}

void DatasetWriter::writeManifest(const std::vector<FailedPose>& failed, const nlohmann::json& source) const {
  std::vector<uint32_t> ids;
  for (const auto& e : fs::directory_iterator(folder_ / "poses")) {
    const std::string name = e.path().filename().string();
    unsigned id = 0;
    char tail[8] = {};
    if (std::sscanf(name.c_str(), "pose_%u.%7s", &id, tail) == 2 && std::string(tail) == "bin" &&
        name == poseName(id) + ".bin")
      ids.push_back(id);
  }
  std::sort(ids.begin(), ids.end());
  nlohmann::json poses = nlohmann::json::array();
  uint32_t width = 0, height = 0;
  for (uint32_t id : ids) {
    const fs::path file = datasetPosePath(folder_, id);
    const PoseFile f = decodePoseFile(readBytes(file), file.string());
    width = f.mapWidth, height = f.mapHeight;
    poses.push_back({{"id", id},
                     {"file", "poses/" + poseName(id) + ".bin"},
                     {"normalMap", "normal_maps/" + poseName(id) + ".png"},
                     {"residuals", residualsJson(f.pose.residuals)}});
  }
  nlohmann::json joints = nlohmann::json::array();
  for (uint32_t j : inputJoints_) joints.push_back({{"index", j}, {"name", character_.skeleton.joints[j].name}});
  nlohmann::json failedJson = nlohmann::json::array();
  for (const FailedPose& f : failed) failedJson.push_back({{"id", f.id}, {"reason", f.reason}});
  nlohmann::json m = {
      {"format", "swish-dataset"},
      {"version", kManifestVersion},
      {"character",
       {{"name", character_.name},
        {"file", "character.bin"},
        {"joints", character_.skeleton.size()},
        {"gameVertices", character_.garment.vertexCount()},
        {"gameTriangles", character_.garment.triangleCount()},
        {"bodyVertices", character_.body.vertexCount()}}},
      {"inputJoints", joints},
      {"settings", settings_},
      {"source", source},
      {"normalMap", {{"width", width}, {"height", height}, {"bitDepth", bitDepth_}, {"encoding", kNormalMapEncoding}}},
      {"poseFile",
       "little-endian: SWDSPOSE, u32 version, u32 id, u32 joints J, u32 vertices N, f32 quaternions [J][w,x,y,z], "
       "f32 root translation [3], f32 world [N][3], f32 pre-skin [N][3], residuals, u32 map width, height, u32 CRC-32"},
      {"poses", poses},
      {"failedPoses", failedJson}};
  writeTextFileAtomic(folder_ / "manifest.json", m.dump(2));
}

Dataset readDataset(const fs::path& folder) {
  const fs::path manifestPath = folder / "manifest.json";
  const std::string mwhat = manifestPath.string();
  nlohmann::json m;
  try {
    const std::vector<uint8_t> bytes = readBytes(manifestPath);
    m = nlohmann::json::parse(bytes.begin(), bytes.end());
  } catch (const nlohmann::json::exception& e) {
    throw Error(mwhat + ": not valid JSON (" + std::string(e.what()) + ")");
  }
  Dataset d;
  uint32_t width = 0, height = 0;
  std::vector<uint32_t> ids;
  try {
    if (!m.is_object() || m.value("format", "") != "swish-dataset")
      throw Error(mwhat + ": not a swish dataset manifest (format is not \"swish-dataset\")");
    if (m.at("version").get<int>() != kManifestVersion)
      throw Error(mwhat + ": manifest version " + m.at("version").dump() + " (this build reads 1)");
    d.settings = m.at("settings");
    width = m.at("normalMap").at("width").get<uint32_t>();
    height = m.at("normalMap").at("height").get<uint32_t>();
    for (const auto& j : m.at("inputJoints")) d.inputJoints.push_back(j.at("index").get<uint32_t>());
    for (const auto& p : m.at("poses")) ids.push_back(p.at("id").get<uint32_t>());
  } catch (const nlohmann::json::exception& e) {
    throw Error(mwhat + ": missing or malformed entry (" + std::string(e.what()) + ")");
  }
  const fs::path charFile = folder / "character.bin";
  d.character = decodeCharacterSnapshot(readBytes(charFile), charFile.string());
  for (uint32_t j : d.inputJoints)
    if (j >= d.character.skeleton.size())
      throw Error(mwhat + ": input joint " + std::to_string(j) + " is not in the skeleton");
  const size_t n = d.character.garment.vertexCount();
  for (size_t k = 0; k < ids.size(); ++k) {
    if (k && ids[k] <= ids[k - 1]) throw Error(mwhat + ": pose ids are not strictly ascending");
    const fs::path file = datasetPosePath(folder, ids[k]);
    const std::string what = file.string();
    PoseFile f = decodePoseFile(readBytes(file), what);
    if (f.pose.id != ids[k])
      throw Error(what + ": holds pose " + std::to_string(f.pose.id) + ", not " + std::to_string(ids[k]));
    if (f.pose.pose.local.size() != d.character.skeleton.size())
      throw Error(what + ": " + std::to_string(f.pose.pose.local.size()) + " joints, the character has " +
                  std::to_string(d.character.skeleton.size()));
    if (size_t(f.pose.gameMeshWorld.rows()) != n)
      throw Error(what + ": " + std::to_string(f.pose.gameMeshWorld.rows()) + " vertices, the garment has " +
                  std::to_string(n));
    if (f.mapWidth != width || f.mapHeight != height)
      throw Error(what + ": normal map " + std::to_string(f.mapWidth) + "x" + std::to_string(f.mapHeight) +
                  ", the manifest says " + std::to_string(width) + "x" + std::to_string(height));
    const fs::path png = datasetNormalMapPath(folder, ids[k]);
    const io::PngImage im = io::readPng(png);
    if (im.width != width || im.height != height)
      throw Error(png.string() + ": " + std::to_string(im.width) + "x" + std::to_string(im.height) + ", expected " +
                  std::to_string(width) + "x" + std::to_string(height));
    f.pose.normalMap.width = width;
    f.pose.normalMap.height = height;
    f.pose.normalMap.xy = io::decodeNormalMap(im, png.string());
    d.poses.push_back(std::move(f.pose));
  }
  return d;
}

}  // namespace swish::bake
