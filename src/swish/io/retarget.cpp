#include "swish/io/retarget.hpp"

#include <cmath>

#include "swish/core/error.hpp"

namespace swish::io {
namespace {

// Smallest rotation taking unit vector a onto unit vector b (any half-turn axis when opposite).
Quatd shortestArc(const Vec3d& a, const Vec3d& b) { return Quatd::FromTwoVectors(a, b).normalized(); }

// Rotation R minimising sum |R a_i - b_i|^2 (Kabsch), or nullopt when the a_i are (nearly) collinear.
std::optional<Quatd> kabsch(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b) {
  Mat3d h = Mat3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) h += a[i] * b[i].transpose();
  Eigen::JacobiSVD<Mat3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const auto s = svd.singularValues();
  if (s[1] < 1e-3 * std::max(s[0], 1e-12)) return std::nullopt;
  Mat3d d = Mat3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return Quatd(svd.matrixV() * d * svd.matrixU().transpose()).normalized();
}

}  // namespace

AnimationClip retarget(const SourceAnimation& clip, const Skeleton& character, const RetargetOptions& options,
                       RetargetReport* report) {
  const std::string what = "animation '" + clip.name + "'";
  if (clip.frames.empty()) throw Error(what + " has no frames");
  character.validate("retarget target");
  const size_t nj = character.size();
  JointMapping map = mapJoints(clip.jointNames, character, options.jointMap);

  std::vector<std::string> unmatched;
  if (map.sourceOf[0] < 0) unmatched.push_back(character.joints[0].name);
  for (const auto& name : options.requiredJoints) {
    const int j = character.find(name);
    if (j < 0) throw Error(what + ": the character has no joint '" + name + "' (a required joint)");
    if (map.sourceOf[size_t(j)] < 0 && j != 0) unmatched.push_back(name);
  }
  if (!unmatched.empty()) {
    std::string list, clipNames;
    for (const auto& n : unmatched) list += (list.empty() ? "'" : ", '") + n + "'";
    for (size_t i = 0; i < clip.jointNames.size() && i < 12; ++i) clipNames += (i ? ", " : "") + clip.jointNames[i];
    throw Error(what + ": unknown joints: the clip has no joint for character joint(s) " + list +
                " (clip joints: " + clipNames + (clip.jointNames.size() > 12 ? ", ..." : "") +
                "); add pairs to the joint map");
  }

  // Rest globals of both skeletons, in double.
  const auto charRest = character.globalTransforms(character.restPose());
  const auto clipRest = clip.restGlobals();
  auto charPos = [&](size_t j) { return charRest[j].translation.cast<double>().eval(); };
  auto clipPos = [&](int s) { return clipRest[size_t(s)].translation.cast<double>().eval(); };
  std::vector<std::vector<int>> children(nj);
  for (size_t j = 1; j < nj; ++j)
    if (character.joints[j].parent >= 0) children[size_t(character.joints[j].parent)].push_back(int(j));

  std::vector<Quatd> align(nj, Quatd::Identity());
  double charLength = 0, clipLength = 0;
  for (size_t h = 0; h < nj; ++h) {
    const int parent = character.joints[h].parent;
    const Quatd inherited = parent < 0 ? Quatd::Identity() : align[size_t(parent)];
    const int s = map.sourceOf[h];
    if (s < 0) {
      align[h] = inherited;
      continue;
    }
    std::vector<Vec3d> dh, ds;
    for (int c0 : children[h]) {
      // Zero-length bones (CMU's LHipJoint) say nothing: walk down to the first real bone.
      int c = c0;
      for (int depth = 0; depth < 4 && c >= 0 && map.sourceOf[size_t(c)] >= 0; ++depth) {
        const Vec3d a = charPos(size_t(c)) - charPos(h), b = clipPos(map.sourceOf[size_t(c)]) - clipPos(s);
        if (a.norm() > 1e-6 && b.norm() > 1e-6 * std::max(1.0, b.norm())) {
          if (b.norm() > 0) {
            dh.push_back(a.normalized());
            ds.push_back(b.normalized());
            if (c == c0) {  // a direct bone: its length calibrates the root translation
              charLength += a.norm();
              clipLength += b.norm();
            }
          }
          break;
        }
        c = children[size_t(c)].empty() ? -1 : children[size_t(c)][0];
      }
    }
    std::optional<Quatd> k;
    if (dh.size() >= 2) k = kabsch(dh, ds);
    if (k) align[h] = *k;
    else if (!dh.empty()) align[h] = shortestArc(inherited * dh[0], ds[0]) * inherited;
    else align[h] = inherited;
  }

  float scale = options.rootTranslationScale;
  if (!(scale > 0.f)) scale = clipLength > 0 ? float(charLength / clipLength) : 1.f;

  // Per joint: the constant factor C_h = R_s(rest)^-1 * A_h * R_h(rest).
  std::vector<Quatd> constant(nj, Quatd::Identity());
  for (size_t h = 0; h < nj; ++h)
    if (map.sourceOf[h] >= 0)
      constant[h] = clipRest[size_t(map.sourceOf[h])].rotation.cast<double>().conjugate() * align[h] *
                    charRest[h].rotation.cast<double>();

  AnimationClip out;
  out.name = clip.name;
  out.framesPerSecond = float(clip.framesPerSecond);
  out.frames.resize(clip.frames.size());
  const int rootSource = map.sourceOf[0];
  const Vec3d root0 = clip.frameGlobals(0)[size_t(rootSource)].translation.cast<double>();
  std::vector<Quatd> global(nj);
  for (size_t f = 0; f < clip.frames.size(); ++f) {
    const auto g = clip.frameGlobals(f);
    Pose& pose = out.frames[f];
    pose.local.resize(nj);
    for (size_t h = 0; h < nj; ++h) {
      const int parent = character.joints[h].parent;
      const int s = map.sourceOf[h];
      if (s >= 0) global[h] = (g[size_t(s)].rotation.cast<double>() * constant[h]).normalized();
      else global[h] = (parent < 0 ? Quatd::Identity() : global[size_t(parent)]) * character.joints[h].rest.rotation.cast<double>();
      const Quatd local = parent < 0 ? global[h] : global[size_t(parent)].conjugate() * global[h];
      pose.local[h] = local.normalized().cast<float>();
      if (!pose.local[h].coeffs().allFinite())
        throw Error(what + ", frame " + std::to_string(f) + ": non-finite rotation for joint '" + character.joints[h].name + "'");
    }
    const Vec3d d = g[size_t(rootSource)].translation.cast<double>() - root0;
    pose.rootTranslation = character.joints[0].rest.translation + (double(scale) * d).cast<float>();
  }
  if (report) {
    report->mapping = map;
    report->rootTranslationScale = scale;
    report->unmappedCharacterJoints.clear();
    for (size_t h = 0; h < nj; ++h)
      if (map.sourceOf[h] < 0) report->unmappedCharacterJoints.push_back(character.joints[h].name);
  }
  return out;
}

}  // namespace swish::io
