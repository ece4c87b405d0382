#include "swish/bake/cloth/simulated_pose_file.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

#include "swish/core/error.hpp"
#include "swish/core/hash.hpp"
#include "swish/files/atomic_write.hpp"

namespace swish::bake {
namespace {

constexpr char kMagic[8] = {'S', 'W', 'C', 'L', 'O', 'T', 'H', '1'};
// 2: the equilibrium residuals, the final projection's depth, the attempts and the first failure.
constexpr uint32_t kVersion = 2;
constexpr uint32_t kMaxVertices = 50'000'000;

template <class T>
void put(std::vector<uint8_t>& out, const T& v) {
  const auto* b = reinterpret_cast<const uint8_t*>(&v);
  out.insert(out.end(), b, b + sizeof(T));
}

struct Reader {
  const std::vector<uint8_t>& bytes;
  const std::filesystem::path& file;
  size_t at = 0;
  void take(void* dst, size_t n) {
    if (n == 0) return;  // a failed pose's empty positions: data() may be null, which memcpy must not get
    if (n > bytes.size() - at)
      throw Error(file.string() + ": truncated simulated-pose file (" + std::to_string(bytes.size()) + " bytes)");
    std::memcpy(dst, bytes.data() + at, n);
    at += n;
  }
  template <class T>
  T get() {
    T v;
    take(&v, sizeof v);
    return v;
  }
};

}  // namespace

std::filesystem::path simulatedPosePath(const std::filesystem::path& dir, uint32_t poseId) {
  char name[32];
  std::snprintf(name, sizeof name, "pose_%06u.clothsim", poseId);
  return dir / name;
}

void writeSimulatedPose(const std::filesystem::path& file, const SimulatedPoseRecord& rec) {
  const PoseSimulation& r = rec.result;
  std::vector<uint8_t> out;
  out.reserve(96 + r.failure.size() + size_t(r.positions.size()) * 4);
  out.insert(out.end(), kMagic, kMagic + 8);
  put(out, kVersion);
  put(out, rec.poseId);
  put(out, rec.fingerprint);
  put(out, uint32_t(r.ok));
  put(out, uint32_t(r.positions.rows()));
  put(out, r.residuals.maxConstraintViolation);
  put(out, r.residuals.maxPenetration);
  put(out, uint32_t(r.residuals.converged));
  put(out, int32_t(r.residuals.iterations));
  put(out, r.residuals.seconds);
  put(out, uint32_t(r.failure.size()));
  out.insert(out.end(), r.failure.begin(), r.failure.end());
  put(out, r.residuals.equilibriumResidual);
  put(out, r.residuals.equilibriumResidualMax);
  put(out, int32_t(r.residuals.equilibriumFrames));
  put(out, r.residuals.projectedDepth);
  put(out, uint32_t(r.attempts));
  put(out, uint32_t(r.firstFailure.size()));
  out.insert(out.end(), r.firstFailure.begin(), r.firstFailure.end());
  const auto* p = reinterpret_cast<const uint8_t*>(r.positions.data());
  out.insert(out.end(), p, p + size_t(r.positions.size()) * sizeof(float));
  put(out, fnv1a(out.data(), out.size()));
  writeFileAtomic(file, out);
}

SimulatedPoseRecord readSimulatedPose(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file.string() + ": cannot open simulated-pose file");
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 8 + 8 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    throw Error(file.string() + ": not a swish simulated-pose file (bad magic)");
  uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  if (stored != fnv1a(bytes.data(), bytes.size() - 8))
    throw Error(file.string() + ": checksum mismatch (corrupt or partly written simulated-pose file)");
  Reader rd{bytes, file, 8};
  const uint32_t version = rd.get<uint32_t>();
  if (version != 1 && version != kVersion)
    throw Error(file.string() + ": simulated-pose file version " + std::to_string(version) + ", expected 1 or " +
                std::to_string(kVersion));
  SimulatedPoseRecord rec;
  rec.poseId = rd.get<uint32_t>();
  rec.fingerprint = rd.get<uint64_t>();
  PoseSimulation& r = rec.result;
  r.ok = rd.get<uint32_t>() != 0;
  const uint32_t nv = rd.get<uint32_t>();
  if (nv > kMaxVertices) throw Error(file.string() + ": implausible vertex count " + std::to_string(nv));
  r.residuals.maxConstraintViolation = rd.get<float>();
  r.residuals.maxPenetration = rd.get<float>();
  r.residuals.converged = rd.get<uint32_t>() != 0;
  r.residuals.iterations = rd.get<int32_t>();
  r.residuals.seconds = rd.get<double>();
  const uint32_t len = rd.get<uint32_t>();
  if (len > bytes.size()) throw Error(file.string() + ": failure message longer than the file");
  r.failure.resize(len);
  rd.take(r.failure.data(), len);
  if (version >= 2) {
    r.residuals.equilibriumResidual = rd.get<float>();
    r.residuals.equilibriumResidualMax = rd.get<float>();
    r.residuals.equilibriumFrames = rd.get<int32_t>();
    r.residuals.projectedDepth = rd.get<float>();
    r.attempts = int(rd.get<uint32_t>());
    const uint32_t firstLen = rd.get<uint32_t>();
    if (firstLen > bytes.size()) throw Error(file.string() + ": first failure message longer than the file");
    r.firstFailure.resize(firstLen);
    rd.take(r.firstFailure.data(), firstLen);
  }
  r.positions.resize(nv, 3);
  rd.take(r.positions.data(), size_t(nv) * 3 * sizeof(float));
  if (rd.at != bytes.size() - 8) throw Error(file.string() + ": trailing bytes in simulated-pose file");
  if (r.ok == (nv == 0)) throw Error(file.string() + ": inconsistent record (ok flag and positions disagree)");
  if (!r.positions.allFinite()) throw Error(file.string() + ": non-finite positions");
  return rec;
}

std::optional<SimulatedPoseHeader> peekSimulatedPose(const std::filesystem::path& file) {
  // magic 8 | version 4 | id 4 | fingerprint 8 | ok 4 | vertices 4 | violation 4 | penetration 4 |
  // converged 4 | iterations 4 | seconds 8
  constexpr size_t kHead = 56;
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::vector<uint8_t> b(kHead);
  if (!in.read(reinterpret_cast<char*>(b.data()), std::streamsize(kHead))) return std::nullopt;
  if (std::memcmp(b.data(), kMagic, 8) != 0) return std::nullopt;
  Reader rd{b, file, 8};
  if (rd.get<uint32_t>() != kVersion) return std::nullopt;
  SimulatedPoseHeader h;
  h.poseId = rd.get<uint32_t>();
  h.fingerprint = rd.get<uint64_t>();
  h.ok = rd.get<uint32_t>() != 0;
  rd.at = 48;
  h.seconds = rd.get<double>();
  return h;
}

}  // namespace swish::bake
