#include "swish/bake/poses/limb_clearance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_set>

#include "swish/bake/cloth/body_collider.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rotation.hpp"
#include "swish/core/skinning.hpp"
#include "swish/io/joint_map.hpp"

namespace swish::bake {
namespace {

// Farthest a limb vertex is looked for inside the trunk (m); deeper is beyond any pose we meet.
constexpr float kSearch = 0.25f;
// Grid cell of the trunk collider (m).
constexpr float kCell = 0.05f;
// A limb this little inside its clearance is left alone (m).
constexpr float kTolerance = 0.001f;
// Spacing of the checked vertices of a one-surface body's limb regions (m): a little below the clearance.
constexpr float kRegionSpacing = 0.01f;
// Directions around a limb tried when the push's turn does not clear it (LimbClearanceSettings::turnSearch).
constexpr int kTurnDirections = 8;

// The smallest whole number of steps in [1, most] after which depthAt(steps) <= kTolerance, `before`
// being the depth at `from` (0, or where an earlier search with a smaller `most` ended without clearing:
// the strides then go on from there, as they would have from 0): 5-step strides, then bisection; `most`
// when none clears. `after` gets the depth at the answer, and p (which depthAt sets) is left holding the
// answer's pose. Shared by the limbs (steps: degrees) and the head (steps: percent of the way back to rest).
template <class DepthAt>
int smallestClearing(int most, float before, DepthAt&& depthAt, float& after, int from = 0) {
  int tried = 0;  // the steps the pose holds
  auto at = [&](int steps) {
    tried = steps;
    return depthAt(steps);
  };
  int lo = from, hi = from;
  after = before;
  while (after > kTolerance && hi < most) {
    lo = hi;
    hi = std::min(most, hi + 5);
    after = at(hi);
  }
  while (after <= kTolerance && hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    const float d = at(mid);
    if (d <= kTolerance)
      hi = mid, after = d;
    else
      lo = mid;
  }
  if (tried != hi) after = at(hi);
  return hi;
}

// Per triangle of `trunk` (rest positions of `body`): whether a corner or the centroid lies within
// `reach` of a vertex of `garment` (rest positions). Vertices sorted by height, so each point looks
// only at the band of garment vertices `reach` above and below it.
std::vector<char> trianglesNearGarment(const Points3f& body, const Triangles& trunk, const Points3f& garment,
                                       float reach) {
  std::vector<std::pair<float, uint32_t>> byY(size_t(garment.rows()));
  for (Eigen::Index v = 0; v < garment.rows(); ++v) byY[size_t(v)] = {garment(v, 1), uint32_t(v)};
  std::sort(byY.begin(), byY.end());
  auto near = [&](const Vec3f& p) {
    auto it = std::lower_bound(byY.begin(), byY.end(), std::make_pair(p.y() - reach, uint32_t(0)));
    for (; it != byY.end() && it->first <= p.y() + reach; ++it)
      if ((garment.row(it->second).transpose() - p).squaredNorm() <= reach * reach) return true;
    return false;
  };
  std::vector<char> out(size_t(trunk.rows()), 0);
  for (Eigen::Index t = 0; t < trunk.rows(); ++t) {
    const Vec3f a = body.row(trunk(t, 0)), b = body.row(trunk(t, 1)), c = body.row(trunk(t, 2));
    out[size_t(t)] = near(a) || near(b) || near(c) || near((a + b + c) / 3.f);
  }
  return out;
}

int depthOf(const Skeleton& s, int j) {
  int d = 0;
  while (s.joints[size_t(j)].parent >= 0) j = s.joints[size_t(j)].parent, ++d;
  return d;
}

// The head joint and its neck ancestors.
std::vector<int> neckChain(const Skeleton& skeleton) {
  // The head joint: the shallowest joint named "Head" or "...Head" (not the root).
  int headJoint = -1;
  for (int j = 1; j < int(skeleton.size()); ++j)
    if (io::normaliseJointName(skeleton.joints[size_t(j)].name).ends_with("head") &&
        (headJoint < 0 || depthOf(skeleton, j) < depthOf(skeleton, headJoint)))
      headJoint = j;
  if (headJoint < 0) return {};
  std::vector<int> chain = {headJoint};
  for (int a = skeleton.joints[size_t(headJoint)].parent;
       a > 0 && io::normaliseJointName(skeleton.joints[size_t(a)].name).find("neck") != std::string::npos;
       a = skeleton.joints[size_t(a)].parent)
    chain.push_back(a);
  return chain;
}

// The angle of the rotation between two orientations, degrees.
float angleDegrees(const Quatf& a, const Quatf& b) {
  return a.normalized().angularDistance(b.normalized()) * 180.f / float(M_PI);
}

}  // namespace

void LimbClearance::addLimb(Limb limb, const std::vector<uint32_t>& vertices, const BodyCollider& trunk,
                            const std::vector<RigidTransform>& restGlobal) {
  const Vec3f head = restGlobal[size_t(limb.rootJoint)].translation;
  for (const uint32_t v : vertices) {
    const Vec3f x = body_.positions.row(v);
    if ((x - head).norm() <= settings_.rootRadius) continue;
    const BodyCollider::Hit hit = trunk.closest(x, kSearch);
    const float d = hit.found ? hit.signedDistance : std::numeric_limits<float>::infinity();
    if (!(d > 0.f)) continue;  // inside the trunk at rest: the part's root, meant to overlap
    limb.vertices.push_back(v);
    limb.restDistance.push_back(d);
  }
  if (!limb.vertices.empty()) limbs_.push_back(std::move(limb));
}

LimbClearance::LimbClearance(const Character& ch, LimbClearanceSettings settings)
    : skeleton_(ch.skeleton), body_(ch.body), settings_(settings) {
  const std::string what = "body of character '" + ch.name + "'";
  auto check = [&](bool ok, const char* msg) {
    if (!ok) throw Error(std::string("limb clearance: ") + msg);
  };
  check(std::isfinite(settings_.clearance) && settings_.clearance >= 0.f && settings_.clearance < 0.2f,
        "clearance must be in [0, 0.2) m");
  check(std::isfinite(settings_.rootRadius) && settings_.rootRadius >= 0.f, "rootRadius must be >= 0");
  check(std::isfinite(settings_.maxDegrees) && settings_.maxDegrees > 0.f && settings_.maxDegrees <= 180.f,
        "maxDegrees must be in (0, 180]");
  check(std::isfinite(settings_.garmentReach) && settings_.garmentReach >= 0.f, "garmentReach must be >= 0");
  check(std::isfinite(settings_.neckRangeDegrees) && settings_.neckRangeDegrees >= 0.f &&
            settings_.neckRangeDegrees <= 720.f,
        "neckRangeDegrees must be in [0, 720]");
  neckChain_ = neckChain(skeleton_);
  body_.validate(what, skeleton_.size());
  if (body_.skin.vertexCount() != body_.vertexCount())
    throw Error(what + " has no skin weights: limbs cannot be posed");
  if (skeleton_.inverseBind.empty()) skeleton_.computeInverseBindFromRest();

  // Parts of the surface, seam copies welded (a glTF body is split at its UV seams, which are not
  // where its limbs begin); the trunk is the part with the most triangles.
  body_.triangles = trianglesWeldedByPosition(body_.positions, body_.triangles);
  const std::vector<uint32_t> part = connectedParts(body_.triangles, body_.vertexCount());
  std::vector<size_t> triangleCount(body_.vertexCount(), 0);
  for (Eigen::Index t = 0; t < body_.triangles.rows(); ++t) ++triangleCount[part[body_.triangles(t, 0)]];
  const uint32_t trunk = uint32_t(std::max_element(triangleCount.begin(), triangleCount.end()) - triangleCount.begin());
  Mesh trunkMesh = body_;
  std::vector<Eigen::Index> keep;
  for (Eigen::Index t = 0; t < body_.triangles.rows(); ++t)
    if (part[body_.triangles(t, 0)] == trunk) keep.push_back(t);
  trunkMesh.triangles.resize(Eigen::Index(keep.size()), 3);
  for (size_t i = 0; i < keep.size(); ++i) trunkMesh.triangles.row(Eigen::Index(i)) = body_.triangles.row(keep[i]);
  if (keep.size() == size_t(body_.triangles.rows())) {
    skipped_ = "the body is one connected mesh: no limbs to keep apart";
    if (settings_.oneSurfaceLimbs) setUpLimbRegions(ch);
    setUpHead();
    return;
  }
  // Inside and outside need a closed trunk: near the openings of an open one (a torso whose head and
  // hands are separate meshes) the sign of the distance means nothing.
  trunk_.emplace(trunkMesh, kCell, what + " (trunk)");
  if (trunk_->openEdges() > 0) {
    skipped_ = "the body's trunk is not a closed surface (" + std::to_string(trunk_->openEdges()) +
               " edges not shared by two triangles): inside and outside are undefined";
    return;
  }
  guarded_.assign(size_t(trunk_->triangles().rows()), 1);
  if (settings_.garmentReach > 0.f && ch.garment.vertexCount() > 0 && ch.garment.positions.allFinite())
    guarded_ = trianglesNearGarment(body_.positions, trunk_->triangles(), ch.garment.positions, settings_.garmentReach);
  const Pose rest = skeleton_.restPose();
  BodyCollider trunkCollider = *trunk_;
  trunkCollider.pose(skeleton_.skinningMatrices(rest));
  const auto g = skeleton_.globalTransforms(rest);
  const int n = body_.skin.influences;
  std::vector<uint32_t> parts;
  for (uint32_t v = 0; v < body_.vertexCount(); ++v)
    if (triangleCount[v] > 0 && v != trunk) parts.push_back(v);
  for (uint32_t p : parts) {
    // The root: the shallowest joint carrying a tenth of the part's skin weight (a blend that reaches
    // the neck from a shoulder must not make the shoulder the root of the head).
    Limb limb;
    std::vector<double> weightOf(skeleton_.size(), 0.0);
    double total = 0.0;
    for (uint32_t v = 0; v < body_.vertexCount(); ++v) {
      if (part[v] != p) continue;
      for (int k = 0; k < n; ++k) {
        weightOf[body_.skin.joints[size_t(v) * n + k]] += body_.skin.weights[size_t(v) * n + k];
        total += body_.skin.weights[size_t(v) * n + k];
      }
    }
    for (int j = 0; j < int(skeleton_.size()); ++j)
      if (weightOf[size_t(j)] >= 0.1 * total &&
          (limb.rootJoint < 0 || depthOf(skeleton_, j) < depthOf(skeleton_, limb.rootJoint)))
        limb.rootJoint = j;
    // A part that moves with the root of the skeleton cannot be rotated away from anything.
    if (limb.rootJoint <= 0) continue;
    std::vector<uint32_t> vertices;
    for (uint32_t v = 0; v < body_.vertexCount(); ++v)
      if (part[v] == p) vertices.push_back(v);
    addLimb(std::move(limb), vertices, trunkCollider, g);
  }
}

size_t LimbClearance::guardedTriangles() const { return size_t(std::count(guarded_.begin(), guarded_.end(), char(1))); }

std::vector<LimbCorrection> LimbClearance::apply(Pose& pose) const {
  std::vector<LimbCorrection> out;
  if (pose.local.size() != skeleton_.size() || !pose.rootTranslation.allFinite()) return out;
  for (const Quatf& q : pose.local)
    if (!q.coeffs().allFinite() || !(q.norm() > 0.f)) return out;
  // The neck within its range first: the head's position decides whether it is inside anything.
  if (std::optional<LimbCorrection> c = limitNeck(pose)) out.push_back(*c);
  if (limbs_.empty() && !head_) return out;  // no parts to keep apart, no head to check (skipped() says why)
  // Measured with the root at rest, as the solver simulates it (the shape ignores the root).
  Pose p = pose;
  p.local[0] = skeleton_.joints[0].rest.rotation;
  p.rootTranslation = skeleton_.joints[0].rest.translation;
  if (!limbs_.empty()) applyLimbs(pose, p, out);
  if (head_)
    if (std::optional<LimbCorrection> c = applyHead(pose, p)) out.push_back(*c);
  return out;
}

void LimbClearance::applyLimbs(Pose& pose, Pose& p, std::vector<LimbCorrection>& out) const {
  // The trunk of a body of parts is posed once: turning a limb moves only the few trunk vertices its
  // blends reach, near its root, where nothing is checked. A one-surface body's trunk blends into its
  // limbs (a MakeHuman side under the armpit is partly skinned to the arm), so it is posed again with the
  // limb at every turn tried: posed once, the arms it cleared were 2.5 mm inside again when checked anew.
  BodyCollider trunk = *trunk_;
  trunk.pose(skeleton_.skinningMatrices(p));
  for (const Limb& limb : limbs_) {
    // How far the limb is inside its clearance, the trunk's outward direction there and the centre of
    // the offending vertices.
    Vec3f push = Vec3f::Zero(), centre = Vec3f::Zero();
    auto measure = [&] {
      const std::vector<Mat4f> m = skeleton_.skinningMatrices(p);
      if (limbRegions_) trunk.pose(m);
      float worst = 0.f, total = 0.f;
      push.setZero();
      centre.setZero();
      for (size_t i = 0; i < limb.vertices.size(); ++i) {
        const uint32_t v = limb.vertices[i];
        const Mat4f b = blendedSkinMatrix(body_.skin, v, m);
        const Vec3f x = b.topLeftCorner<3, 3>() * body_.positions.row(v).transpose() + b.topRightCorner<3, 1>();
        const float want = std::min(settings_.clearance, limb.restDistance[i]);
        const BodyCollider::Hit hit = trunk.closest(x, want + kSearch);
        if (!hit.found || !guarded_[size_t(hit.triangle)]) continue;
        const float d = want - hit.signedDistance;
        if (!(d > 0.f)) continue;
        worst = std::max(worst, d);
        total += d;
        push += d * hit.normal;
        centre += d * x;
      }
      if (total > 0.f) centre /= total;
      return worst;
    };
    const float before = measure();
    if (before <= kTolerance) continue;
    const std::vector<RigidTransform> g = skeleton_.globalTransforms(p);
    const int j = limb.rootJoint, parent = skeleton_.joints[size_t(j)].parent;
    const Vec3f head = g[size_t(j)].translation;
    const Vec3f along = (centre - head).normalized();  // before any turn: the turns are about axes across it
    Vec3f axis = (centre - head).cross(push);
    LimbCorrection c{skeleton_.joints[size_t(j)].name, 0.f, before, before};
    if (!(axis.norm() > 1e-9f)) {  // pushed straight along the limb: no rotation helps
      out.push_back(c);
      continue;
    }
    axis.normalize();
    const Quatf global = g[size_t(j)].rotation, parentInv = g[size_t(parent)].rotation.conjugate();
    // The smallest whole number of degrees about `about` that clears the limb, searched from `from`
    // degrees, where the limb is `depthFrom` inside.
    auto clearingAbout = [&](const Vec3f& about, int most, float& after, int from, float depthFrom) {
      auto depthAt = [&](int degrees) {
        const Quatf turn(Eigen::AngleAxisf(float(degrees) * float(M_PI) / 180.f, about));
        p.local[size_t(j)] = (parentInv * turn * global).normalized();
        return measure();
      };
      return smallestClearing(most, depthFrom, depthAt, after, from);
    };
    float after = before;
    int degrees = clearingAbout(axis, int(settings_.maxDegrees), after, 0, before);
    if (after > kTolerance && settings_.turnSearch) {
      // The push's turn does not clear the limb within maxDegrees (a limb deep in the trunk: the
      // nearest surface's normals point up the chest). kTurnDirections directions around the limb,
      // the push's first (its search goes on from maxDegrees), each with its own smallest turn up to twice
      // maxDegrees: the one that clears with the fewest degrees wins (the earlier on a tie), or if none
      // clears the one that leaves the least.
      Vec3f bestAxis = axis;
      int bestDegrees = degrees;
      float bestAfter = after;
      for (int k = 0; k < kTurnDirections; ++k) {
        const Vec3f a = Eigen::AngleAxisf(2.f * float(M_PI) * float(k) / float(kTurnDirections), along) * axis;
        float afterK = before;
        const int degreesK = k == 0 ? clearingAbout(axis, 2 * int(settings_.maxDegrees), afterK, degrees, after)
                                    : clearingAbout(a, 2 * int(settings_.maxDegrees), afterK, 0, before);
        const bool clears = afterK <= kTolerance, bestClears = bestAfter <= kTolerance;
        if (clears ? !bestClears || degreesK < bestDegrees : !bestClears && afterK < bestAfter)
          bestAxis = a, bestDegrees = degreesK, bestAfter = afterK;
      }
      const Quatf turn(Eigen::AngleAxisf(float(bestDegrees) * float(M_PI) / 180.f, bestAxis));
      p.local[size_t(j)] = (parentInv * turn * global).normalized();
      if (limbRegions_) measure();  // the trunk posed with the chosen turn, for the limbs after this one
      degrees = bestDegrees;
      after = bestAfter;
    }
    pose.local[size_t(j)] = p.local[size_t(j)];
    c.degrees = float(degrees);
    c.depthAfter = after > kTolerance ? after : 0.f;
    out.push_back(c);
  }
}

std::optional<LimbCorrection> LimbClearance::limitNeck(Pose& pose) const {
  if (!(settings_.neckRangeDegrees > 0.f) || neckChain_.empty()) return std::nullopt;
  float total = 0.f;
  for (int j : neckChain_) total += angleDegrees(skeleton_.joints[size_t(j)].rest.rotation, pose.local[size_t(j)]);
  if (!(total > settings_.neckRangeDegrees)) return std::nullopt;
  const float keep = settings_.neckRangeDegrees / total;
  for (int j : neckChain_)
    pose.local[size_t(j)] = slerpShortest(skeleton_.joints[size_t(j)].rest.rotation, pose.local[size_t(j)], keep);
  LimbCorrection c{skeleton_.joints[size_t(neckChain_.front())].name, total - settings_.neckRangeDegrees, 0.f, 0.f};
  c.towardsRest = 1.f - keep;
  c.neckRange = true;
  return c;
}

void LimbClearance::skip(const std::string& why) { skipped_ += (skipped_.empty() ? "" : "; ") + why; }

void LimbClearance::setUpLimbRegions(const Character& ch) {
  const std::string what = "body of character '" + ch.name + "'";
  // The limb joints: per kind, the shallowest joint whose name ends so.
  std::vector<int> roots;
  for (const char* kind : {"leftarm", "rightarm", "leftupleg", "rightupleg"}) {
    int root = -1;
    for (int j = 1; j < int(skeleton_.size()); ++j)
      if (io::normaliseJointName(skeleton_.joints[size_t(j)].name).ends_with(kind) &&
          (root < 0 || depthOf(skeleton_, j) < depthOf(skeleton_, root)))
        root = j;
    if (root > 0) roots.push_back(root);
  }
  if (roots.empty()) {
    skip("no joint named ...LeftArm, ...RightArm, ...LeftUpLeg or ...RightUpLeg: no limb regions either");
    return;
  }
  // Per joint, the limb whose subtree holds it (-1: the trunk); per vertex, that of its strongest joint.
  std::vector<int> jointLimb(skeleton_.size(), -1);
  for (size_t j = 0; j < skeleton_.size(); ++j)
    for (int a = int(j); a >= 0 && jointLimb[j] < 0; a = skeleton_.joints[size_t(a)].parent)
      for (size_t r = 0; r < roots.size(); ++r)
        if (roots[r] == a) jointLimb[j] = int(r);
  std::vector<int> vertexLimb(body_.vertexCount());
  for (uint32_t v = 0; v < body_.vertexCount(); ++v) vertexLimb[v] = jointLimb[body_.skin.strongestJoint(v)];
  // The trunk: the triangles with no corner in a limb region.
  Mesh trunkMesh = body_;
  std::vector<Eigen::Index> keep;
  std::vector<std::vector<uint32_t>> regionVertices(roots.size());
  std::vector<char> used(body_.vertexCount(), 0);
  for (Eigen::Index t = 0; t < body_.triangles.rows(); ++t) {
    bool trunk = true;
    for (int c = 0; c < 3; ++c) {
      used[body_.triangles(t, c)] = 1;
      trunk = trunk && vertexLimb[body_.triangles(t, c)] < 0;
    }
    if (trunk) keep.push_back(t);
  }
  // One vertex per kRegionSpacing cell (the first by index): a realistic body's limbs hold thousands of
  // vertices (its fingers most), and a pose's check measures each of them several times.
  std::unordered_set<uint64_t> cells;
  for (uint32_t v = 0; v < body_.vertexCount(); ++v) {
    if (!used[v] || vertexLimb[v] < 0) continue;
    const Eigen::Vector3i c = (body_.positions.row(v).transpose() / kRegionSpacing).array().floor().cast<int>();
    const uint64_t key = (uint64_t(uint32_t(vertexLimb[v])) << 60) ^ (uint64_t(uint32_t(c.x()) & 0xFFFFF) << 40) ^
                         (uint64_t(uint32_t(c.y()) & 0xFFFFF) << 20) ^ uint64_t(uint32_t(c.z()) & 0xFFFFF);
    if (cells.insert(key).second) regionVertices[size_t(vertexLimb[v])].push_back(v);
  }
  if (keep.empty() || keep.size() == size_t(body_.triangles.rows())) {
    skip("the limb joints' skin regions leave no trunk, or no limb: no limb regions either");
    return;
  }
  trunkMesh.triangles.resize(Eigen::Index(keep.size()), 3);
  for (size_t i = 0; i < keep.size(); ++i) trunkMesh.triangles.row(Eigen::Index(i)) = body_.triangles.row(keep[i]);
  trunk_.emplace(trunkMesh, kCell, what + " (without its limb regions)");
  // Kept clear: the trunk near the garment, away from the seams where the limb regions were cut off (an
  // open surface's sign means nothing at its openings).
  guarded_.assign(size_t(trunk_->triangles().rows()), 1);
  if (settings_.garmentReach > 0.f && ch.garment.vertexCount() > 0 && ch.garment.positions.allFinite())
    guarded_ = trianglesNearGarment(body_.positions, trunk_->triangles(), ch.garment.positions, settings_.garmentReach);
  size_t limbVertexCount = 0;
  for (const auto& r : regionVertices) limbVertexCount += r.size();
  Points3f limbPoints(Eigen::Index(limbVertexCount), 3);
  Eigen::Index k = 0;
  for (const auto& r : regionVertices)
    for (uint32_t v : r) limbPoints.row(k++) = body_.positions.row(v);
  const std::vector<char> seam =
      trianglesNearGarment(body_.positions, trunk_->triangles(), limbPoints, settings_.seamBorder);
  for (size_t t = 0; t < guarded_.size(); ++t)
    if (seam[t]) guarded_[t] = 0;
  const Pose rest = skeleton_.restPose();
  BodyCollider trunkCollider = *trunk_;
  trunkCollider.pose(skeleton_.skinningMatrices(rest));
  const auto g = skeleton_.globalTransforms(rest);
  for (size_t r = 0; r < roots.size(); ++r) {
    Limb limb;
    limb.rootJoint = roots[r];
    addLimb(std::move(limb), regionVertices[r], trunkCollider, g);
  }
  if (limbs_.empty()) {
    skip("no vertex of the limb regions lies outside the trunk farther than rootRadius from its root joint");
    trunk_.reset();
    return;
  }
  limbRegions_ = true;
  skipped_.clear();
}

void LimbClearance::setUpHead() {
  const std::string what = "body";
  if (neckChain_.empty()) {
    skip("no joint named 'Head': the head is not checked either");
    return;
  }
  Head h;
  const int headJoint = neckChain_.front();
  std::vector<char> inHead(skeleton_.size(), 0);
  for (size_t j = 0; j < skeleton_.size(); ++j)
    for (int a = int(j); a >= 0; a = skeleton_.joints[size_t(a)].parent)
      if (a == headJoint) {
        inHead[j] = 1;
        break;
      }
  // Head vertices: dominant skin joint in the head joint's subtree.
  std::vector<char> isHead(body_.vertexCount(), 0);
  for (uint32_t v = 0; v < body_.vertexCount(); ++v) isHead[v] = inHead[body_.skin.strongestJoint(v)];
  // The rest of the body: the triangles with fewer than two head vertices.
  Mesh others = body_;
  std::vector<Eigen::Index> keep;
  for (Eigen::Index t = 0; t < body_.triangles.rows(); ++t) {
    const int heads = isHead[body_.triangles(t, 0)] + isHead[body_.triangles(t, 1)] + isHead[body_.triangles(t, 2)];
    if (heads < 2) keep.push_back(t);
  }
  if (keep.size() == size_t(body_.triangles.rows()) || keep.empty()) {
    skip("the head has no triangles of its own: it is not checked");
    return;
  }
  others.triangles.resize(Eigen::Index(keep.size()), 3);
  for (size_t i = 0; i < keep.size(); ++i) others.triangles.row(Eigen::Index(i)) = body_.triangles.row(keep[i]);
  h.whole.emplace(body_, kCell, what);
  if (h.whole->openEdges() > 0) {
    skip("the body is not a closed surface (" + std::to_string(h.whole->openEdges()) +
         " open edges): the head is not checked");
    return;
  }
  h.rest.emplace(others, kCell, what + " (without the head)");
  const Pose rest = skeleton_.restPose();
  const std::vector<Mat4f> m = skeleton_.skinningMatrices(rest);
  BodyCollider restPosed = *h.rest, wholePosed = *h.whole;
  restPosed.pose(m);
  wholePosed.pose(m);
  std::vector<char> used(body_.vertexCount(), 0);
  for (Eigen::Index t = 0; t < body_.triangles.rows(); ++t)
    for (int c = 0; c < 3; ++c) used[body_.triangles(t, c)] = 1;
  for (uint32_t v = 0; v < body_.vertexCount(); ++v) {
    if (!isHead[v] || !used[v]) continue;
    const Vec3f x = body_.positions.row(v);
    if (h.vertices.empty()) h.wholePart = wholePosed.closest(x, kCell).part;
    if (restPosed.closest(x, settings_.headBorder).found) continue;  // near the neck seam or the jaw
    h.vertices.push_back(v);
  }
  if (h.vertices.empty()) {
    skip("no head vertex lies " + std::to_string(settings_.headBorder) + " m from the rest of the body");
    return;
  }
  skipped_.clear();
  head_ = std::move(h);
}

std::optional<LimbCorrection> LimbClearance::applyHead(Pose& pose, Pose p) const {
  const Head& h = *head_;
  // How far the deepest checked head vertex is inside the rest of the body: the closest of the other
  // triangles (an open surface: its sign is trusted only where the whole body's winding number
  // confirms the vertex lies inside another layer of it, 1.5 against 0.5 on the surface alone).
  auto measure = [&] {
    const std::vector<Mat4f> m = skeleton_.skinningMatrices(p);
    BodyCollider others = *h.rest;
    others.pose(m);
    std::optional<BodyCollider> whole;
    float worst = 0.f;
    for (const uint32_t v : h.vertices) {
      const Mat4f b = blendedSkinMatrix(body_.skin, v, m);
      const Vec3f x = b.topLeftCorner<3, 3>() * body_.positions.row(v).transpose() + b.topRightCorner<3, 1>();
      const BodyCollider::Hit hit = others.closest(x, kSearch);
      if (!hit.found || !(-hit.signedDistance > std::max(worst, kTolerance))) continue;
      if (!whole) {
        whole.emplace(*h.whole);
        whole->pose(m);
      }
      if (whole->windingNumber(x, h.wholePart) < 1.f) continue;
      worst = -hit.signedDistance;
    }
    return worst;
  };
  const float before = measure();
  if (before <= kTolerance) return std::nullopt;
  const Pose recorded = p;
  // The head joint in the frame of its chain's parent, to tell how far the head turned.
  const int top = skeleton_.joints[size_t(neckChain_.back())].parent;
  auto headInChain = [&](const Pose& q) {
    const std::vector<RigidTransform> g = skeleton_.globalTransforms(q);
    return Quatf(g[size_t(top)].rotation.conjugate() * g[size_t(neckChain_.front())].rotation);
  };
  // The smallest whole percentage of the way back to rest that clears the head.
  auto depthAt = [&](int percent) {
    for (int j : neckChain_)
      p.local[size_t(j)] =
          slerpShortest(recorded.local[size_t(j)], skeleton_.joints[size_t(j)].rest.rotation, float(percent) / 100.f)
              .normalized();
    return measure();
  };
  float after = before;
  const int percent = smallestClearing(100, before, depthAt, after);
  for (int j : neckChain_) pose.local[size_t(j)] = p.local[size_t(j)];
  LimbCorrection c{skeleton_.joints[size_t(neckChain_.front())].name, 0.f, before, after > kTolerance ? after : 0.f,
                   float(percent) / 100.f};
  c.degrees = angleDegrees(headInChain(recorded), headInChain(p));
  c.head = true;
  return c;
}

}  // namespace swish::bake
