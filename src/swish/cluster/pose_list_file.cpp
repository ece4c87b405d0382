#include "swish/cluster/pose_list_file.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "swish/core/error.hpp"
#include "swish/core/hash.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/files/byte_reader.hpp"
#include "swish/files/byte_writer.hpp"

namespace swish::cluster {
namespace {

constexpr char kMagic[8] = {'S', 'W', 'P', 'O', 'S', 'E', 'S', '1'};
constexpr uint32_t kVersion = 1;
constexpr uint32_t kMaxPoses = 10'000'000, kMaxJoints = 4096;

}  // namespace

void writePoseList(const std::filesystem::path& file, const PoseList& list) {
  if (list.poses.size() != list.poseFingerprints.size())
    throw Error(file.string() + ": pose list with " + std::to_string(list.poses.size()) + " poses and " +
                std::to_string(list.poseFingerprints.size()) + " fingerprints");
  const uint32_t joints = list.poses.empty() ? 0 : uint32_t(list.poses.front().local.size());
  ByteWriter w;
  w.bytes({reinterpret_cast<const uint8_t*>(kMagic), 8});
  w.u32(kVersion);
  w.u64(list.fingerprint);
  w.u64(list.settingsDigest);
  w.u32(uint32_t(list.poses.size()));
  w.u32(joints);
  for (size_t i = 0; i < list.poses.size(); ++i) {
    const Pose& p = list.poses[i];
    if (p.local.size() != joints) throw Error(file.string() + ": poses of different joint counts");
    w.u64(list.poseFingerprints[i]);
    w.f32s({p.rootTranslation.data(), 3});
    for (const Quatf& q : p.local) w.f32s({q.coeffs().data(), 4});
  }
  w.u64(fnv1a(w.data().data(), w.size()));
  writeFileAtomic(file, w.data());
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
  // Between the magic and the checksum; every read bounds-checked, every count checked before allocating.
  ByteReader rd(std::span<const uint8_t>(bytes).subspan(8, bytes.size() - 16), file.string(), "pose list");
  if (const uint32_t v = rd.u32("version"); v != kVersion)
    throw Error(file.string() + ": pose list version " + std::to_string(v) + ", expected " + std::to_string(kVersion));
  PoseList list;
  list.fingerprint = rd.u64("list fingerprint");
  list.settingsDigest = rd.u64("settings digest");
  const uint32_t n = rd.u32("pose count"), joints = rd.u32("joint count");
  if (n > kMaxPoses || joints > kMaxJoints)
    throw Error(file.string() + ": implausible pose list (" + std::to_string(n) + " poses, " + std::to_string(joints) +
                " joints)");
  if (size_t(n) * (8 + 12 + size_t(joints) * 16) != rd.remaining())
    throw Error(file.string() + ": pose list size does not match its " + std::to_string(n) + " poses");
  list.poses.resize(n);
  list.poseFingerprints.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    list.poseFingerprints[i] = rd.u64("pose fingerprint");
    Pose& p = list.poses[i];
    rd.f32s(p.rootTranslation.data(), 3, "root translation");
    p.local.resize(joints);
    for (Quatf& q : p.local) rd.f32s(q.coeffs().data(), 4, "rotation");
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
