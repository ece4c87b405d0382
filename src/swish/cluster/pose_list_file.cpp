#include "swish/cluster/pose_list_file.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "swish/core/error.hpp"
#include "swish/core/hash.hpp"
#include "swish/files/atomic_write.hpp"

namespace swish::cluster {
namespace {

constexpr char kMagic[8] = {'S', 'W', 'P', 'O', 'S', 'E', 'S', '1'};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kMaxPoses = 10'000'000, kMaxJoints = 4096;

template <class T>
void put(std::vector<uint8_t>& out, const T& v) {
  const auto* b = reinterpret_cast<const uint8_t*>(&v);
  out.insert(out.end(), b, b + sizeof(T));
}

struct Reader {
  const std::vector<uint8_t>& bytes;
  const std::filesystem::path& file;
  size_t at = 0;
  template <class T>
  T get() {
    T v;
    if (sizeof v > bytes.size() - 8 - at)
      throw Error(file.string() + ": truncated pose list (" + std::to_string(bytes.size()) + " bytes)");
    std::memcpy(&v, bytes.data() + at, sizeof v);
    at += sizeof v;
    return v;
  }
};

}  // namespace

void writePoseList(const std::filesystem::path& file, const PoseList& list) {
  if (list.poses.size() != list.poseFingerprints.size())
    throw Error(file.string() + ": pose list with " + std::to_string(list.poses.size()) + " poses and " +
                std::to_string(list.poseFingerprints.size()) + " fingerprints");
  const uint32_t joints = list.poses.empty() ? 0 : uint32_t(list.poses.front().local.size());
  std::vector<uint8_t> out(kMagic, kMagic + 8);
  put(out, kVersion);
  put(out, list.fingerprint);
  put(out, list.settingsDigest);
  put(out, uint32_t(list.poses.size()));
  put(out, joints);
  for (size_t i = 0; i < list.poses.size(); ++i) {
    const Pose& p = list.poses[i];
    if (p.local.size() != joints) throw Error(file.string() + ": poses of different joint counts");
    put(out, list.poseFingerprints[i]);
    for (int k = 0; k < 3; ++k) put(out, p.rootTranslation[k]);
    for (const Quatf& q : p.local)
      for (int k = 0; k < 4; ++k) put(out, q.coeffs()[k]);
  }
  put(out, fnv1a(out.data(), out.size()));
  writeFileAtomic(file, out);
}

PoseList readPoseList(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file.string() + ": cannot open the pose list (was the bake submitted with --slurm?)");
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 16 || std::memcmp(bytes.data(), kMagic, 8) != 0)
    throw Error(file.string() + ": not a swish pose list (bad magic)");
  uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
  if (stored != fnv1a(bytes.data(), bytes.size() - 8))
    throw Error(file.string() + ": checksum mismatch (corrupt or partly written pose list)");
  Reader rd{bytes, file, 8};
  if (const uint32_t v = rd.get<uint32_t>(); v != kVersion)
    throw Error(file.string() + ": pose list version " + std::to_string(v) + ", expected " + std::to_string(kVersion));
  PoseList list;
  list.fingerprint = rd.get<uint64_t>();
  list.settingsDigest = rd.get<uint64_t>();
  const uint32_t n = rd.get<uint32_t>(), joints = rd.get<uint32_t>();
  if (n > kMaxPoses || joints > kMaxJoints)
    throw Error(file.string() + ": implausible pose list (" + std::to_string(n) + " poses, " + std::to_string(joints) +
                " joints)");
  if (size_t(n) * (8 + 12 + size_t(joints) * 16) != bytes.size() - 8 - rd.at)
    throw Error(file.string() + ": pose list size does not match its " + std::to_string(n) + " poses");
  list.poses.resize(n);
  list.poseFingerprints.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    list.poseFingerprints[i] = rd.get<uint64_t>();
    Pose& p = list.poses[i];
    for (int k = 0; k < 3; ++k) p.rootTranslation[k] = rd.get<float>();
    p.local.resize(joints);
    for (Quatf& q : p.local)
      for (int k = 0; k < 4; ++k) q.coeffs()[k] = rd.get<float>();
  }
  return list;
}

std::string fingerprintHex(uint64_t f) {
  char s[20];
  std::snprintf(s, sizeof s, "%016llx", static_cast<unsigned long long>(f));
  return s;
}

uint64_t parseFingerprintHex(const std::string& text) {
  if (text.empty() || text.size() > 16 || text.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
    throw Error("'" + text + "' is not a pose list fingerprint (1 to 16 hex digits)");
  return std::stoull(text, nullptr, 16);
}

}  // namespace swish::cluster
