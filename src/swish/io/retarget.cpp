#include "swish/io/retarget.hpp"

#include <algorithm>
#include <cmath>

#include "swish/core/error.hpp"

namespace swish::io {
namespace {

// Smallest rotation taking unit vector a onto unit vector b (any half-turn axis when opposite).
Quatd shortestArc(const Vec3d& a, const Vec3d& b) { return Quatd::FromTwoVectors(a, b).normalized(); }

// Rotation R minimising sum |R a_i - b_i|^2 (Kabsch), or nullopt when the a_i are (nearly) collinear.
// `ambiguous` is set when the answer is not one rotation: the directions fit best mirrored (a reflection)
// and the two smallest singular values nearly tie, so that the SVD may return either of two rotations far
// apart. The shared T-shirt's chest (collar bones ahead of the neck) against the Daz rig's (behind it):
// singular values 2.79, 0.0612, 0.0611, and the chest came out turned 180 degrees about the spine.
std::optional<Quatd> kabsch(const std::vector<Vec3d>& a, const std::vector<Vec3d>& b, bool& ambiguous) {
  Mat3d h = Mat3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) h += a[i] * b[i].transpose();
  Eigen::JacobiSVD<Mat3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const auto& s = svd.singularValues();
  if (s[1] < 1e-3 * std::max(s[0], 1e-12)) return std::nullopt;
  Mat3d d = Mat3d::Identity();
  d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  ambiguous = d(2, 2) < 0 && s[2] > 0.5 * s[1];
  return Quatd(svd.matrixV() * d * svd.matrixU().transpose()).normalized();
}

// The alignment where Kabsch is ambiguous (a chest whose collar bones lie ahead of its neck, as the
// shared T-shirt's, against one whose collar bones lie behind it, as the Daz rig's: no rotation fits both,
// and the best fits are a tilt or a half turn about the spine). What both skeletons agree on is used
// instead: each mirrored pair of children (names that differ by left / right) gives the direction from the
// right one to the left one, the other children their own directions, and Kabsch fits those. Without a
// pair (or if that fit is ambiguous too) the smallest turn of the directions' mean onto the clip's after
// the parent's alignment `inherited`, so that the twist follows the parent as for a joint with one child.
Quatd agreedAlignment(const std::vector<int>& child, const std::vector<Vec3d>& a, const std::vector<Vec3d>& b,
                      const std::vector<Vec3d>& aOffset, const std::vector<Vec3d>& bOffset, const Skeleton& character,
                      const Quatd& inherited) {
  std::vector<Vec3d> da, db;
  std::vector<char> paired(child.size(), 0);
  for (size_t i = 0; i < child.size(); ++i) {
    const std::string name = normaliseJointName(character.joints[size_t(child[i])].name);
    const size_t at = name.find("left");
    if (at == std::string::npos) continue;
    const std::string mirror = name.substr(0, at) + "right" + name.substr(at + 4);
    for (size_t k = 0; k < child.size(); ++k)
      if (k != i && !paired[k] && normaliseJointName(character.joints[size_t(child[k])].name) == mirror) {
        const Vec3d sa = aOffset[i] - aOffset[k], sb = bOffset[i] - bOffset[k];
        if (sa.norm() > 1e-9 && sb.norm() > 1e-9) {
          da.push_back(sa.normalized());
          db.push_back(sb.normalized());
          paired[i] = paired[k] = 1;
        }
        break;
      }
  }
  if (!da.empty()) {
    for (size_t i = 0; i < child.size(); ++i)
      if (!paired[i]) da.push_back(a[i]), db.push_back(b[i]);
    bool ambiguous = false;
    if (da.size() >= 2)
      if (const std::optional<Quatd> k = kabsch(da, db, ambiguous); k && !ambiguous) return *k;
  }
  Vec3d ma = Vec3d::Zero(), mb = Vec3d::Zero();
  for (size_t i = 0; i < a.size(); ++i) ma += a[i], mb += b[i];
  if (!(ma.norm() > 1e-9) || !(mb.norm() > 1e-9)) ma = a[0], mb = b[0];
  return (shortestArc((inherited * ma).normalized(), mb.normalized()) * inherited).normalized();
}

// A chain of character joints driven together (JointChain): indices, parent first, and per joint its
// share and Q_i, the product of the chain's rest local rotations up to and including joint i.
struct ResolvedChain {
  std::vector<size_t> joints;
  std::vector<double> shares;
  std::vector<Quatd> restUpTo;
  int parent = -1;  // the first joint's parent
};

std::vector<ResolvedChain> resolveChains(const std::vector<JointChain>& chains, const Skeleton& character,
                                         const JointMapping& map, const std::string& what) {
  std::vector<ResolvedChain> out;
  for (const JointChain& c : chains) {
    ResolvedChain r;
    std::string names;
    for (const auto& n : c.joints) names += (names.empty() ? "" : ", ") + n;
    Quatd q = Quatd::Identity();
    for (size_t i = 0; i < c.joints.size(); ++i) {
      const int j = character.find(c.joints[i]);
      if (j < 0)
        throw Error(what + ": joint map chain [" + names + "]: the character has no joint '" + c.joints[i] + "'");
      if (i > 0 && character.joints[size_t(j)].parent != int(r.joints.back()))
        throw Error(what + ": joint map chain [" + names + "]: '" + c.joints[i] + "' is not the child of '" +
                    c.joints[i - 1] + "' in the character");
      r.joints.push_back(size_t(j));
      r.shares.push_back(i < c.shares.size() ? double(c.shares[i]) : 1.0 / double(c.joints.size()));
      q = q * character.joints[size_t(j)].rest.rotation.cast<double>();
      r.restUpTo.push_back(q);
    }
    if (map.sourceOf[r.joints.back()] < 0)
      throw Error(what + ": joint map chain [" + names + "]: no clip joint drives its last joint '" + c.joints.back() +
                  "'");
    r.parent = character.joints[r.joints.front()].parent;
    out.push_back(std::move(r));
  }
  return out;
}

// D^t for a rotation D: the shortest-arc fraction t of it.
Quatd power(const Quatd& d, double t) {
  const Quatd s = d.w() < 0 ? Quatd(-d.w(), -d.x(), -d.y(), -d.z()) : d;
  return Quatd::Identity().slerp(t, s);
}

// Shares the rotation D that the chain's joints add to their rest rotations (in the frame of the
// chain's parent: global(last) = G_parent * D * Q_last) out along the chain: local_i = Q_{i-1}^-1 *
// D^{share_i} * Q_i. The product of the new locals is D * Q_last, so the last joint's global rotation,
// and every joint below it, is unchanged; D = identity gives the rest locals back.
void shareChain(const ResolvedChain& c, const std::vector<Quatd>& global, Pose& pose) {
  const Quatd parent = c.parent < 0 ? Quatd::Identity() : global[size_t(c.parent)];
  const Quatd d = (parent.conjugate() * global[c.joints.back()] * c.restUpTo.back().conjugate()).normalized();
  Quatd before = Quatd::Identity();
  for (size_t i = 0; i < c.joints.size(); ++i) {
    pose.local[c.joints[i]] = (before.conjugate() * power(d, c.shares[i]) * c.restUpTo[i]).normalized().cast<float>();
    before = c.restUpTo[i];
  }
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
    const bool inChain = std::any_of(
        options.jointMap.chains.begin(), options.jointMap.chains.end(),
        [&](const JointChain& c) { return std::find(c.joints.begin(), c.joints.end(), name) != c.joints.end(); });
    if (map.sourceOf[size_t(j)] < 0 && j != 0 && !inChain) unmatched.push_back(name);
  }
  if (!unmatched.empty()) {
    std::string list, clipNames;
    for (const auto& n : unmatched) list += (list.empty() ? "'" : ", '") + n + "'";
    for (size_t i = 0; i < clip.jointNames.size() && i < 12; ++i) clipNames += (i ? ", " : "") + clip.jointNames[i];
    throw Error(what + ": unknown joints: the clip has no joint for character joint(s) " + list + " (clip joints: " +
                clipNames + (clip.jointNames.size() > 12 ? ", ..." : "") + "); add pairs to the joint map");
  }

  const std::vector<ResolvedChain> chains = resolveChains(options.jointMap.chains, character, map, what);

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
    std::vector<Vec3d> dh, ds, oh, os;  // directions to the mapped children, and the offsets themselves
    std::vector<int> used;              // the character child each came from
    for (int c0 : children[h]) {
      // Zero-length bones (CMU's LHipJoint) say nothing: walk down to the first real bone.
      int c = c0;
      for (int depth = 0; depth < 4 && c >= 0 && map.sourceOf[size_t(c)] >= 0; ++depth) {
        const Vec3d a = charPos(size_t(c)) - charPos(h), b = clipPos(map.sourceOf[size_t(c)]) - clipPos(s);
        if (a.norm() > 1e-6 && b.norm() > 1e-6 * std::max(1.0, b.norm())) {
          if (b.norm() > 0) {
            dh.push_back(a.normalized());
            ds.push_back(b.normalized());
            oh.push_back(a);
            os.push_back(b);
            used.push_back(c0);
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
    bool ambiguous = false;
    if (dh.size() >= 2) k = kabsch(dh, ds, ambiguous);
    if (ambiguous) k = agreedAlignment(used, dh, ds, oh, os, character, inherited);
    if (k)
      align[h] = *k;
    else if (!dh.empty())
      align[h] = shortestArc(inherited * dh[0], ds[0]) * inherited;
    else
      align[h] = inherited;
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
      if (s >= 0)
        global[h] = (g[size_t(s)].rotation.cast<double>() * constant[h]).normalized();
      else
        global[h] = (parent < 0 ? Quatd::Identity() : global[size_t(parent)]) *
                    character.joints[h].rest.rotation.cast<double>();
      const Quatd local = parent < 0 ? global[h] : global[size_t(parent)].conjugate() * global[h];
      pose.local[h] = local.normalized().cast<float>();
      if (!pose.local[h].coeffs().allFinite())
        throw Error(what + ", frame " + std::to_string(f) + ": non-finite rotation for joint '" +
                    character.joints[h].name + "'");
    }
    for (const ResolvedChain& c : chains) shareChain(c, global, pose);
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
