#include "swish/bake/limb_clearance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "swish/bake/body_collider.hpp"
#include "swish/core/error.hpp"
#include "swish/core/skinning.hpp"

namespace swish::bake {
namespace {

// Farthest a limb vertex is looked for inside the trunk (m); deeper is beyond any pose we meet.
constexpr float kSearch = 0.25f;
// Grid cell of the trunk collider (m).
constexpr float kCell = 0.05f;
// A limb this little inside its clearance is left alone (m).
constexpr float kTolerance = 0.001f;

int depthOf(const Skeleton& s, int j) {
  int d = 0;
  while (s.joints[size_t(j)].parent >= 0) j = s.joints[size_t(j)].parent, ++d;
  return d;
}

}  // namespace

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
  body_.validate(what, skeleton_.size());
  if (body_.skin.vertexCount() != body_.vertexCount()) throw Error(what + " has no skin weights: limbs cannot be posed");
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
    const Vec3f head = g[size_t(limb.rootJoint)].translation;
    for (uint32_t v = 0; v < body_.vertexCount(); ++v) {
      if (part[v] != p) continue;
      const Vec3f x = body_.positions.row(v);
      if ((x - head).norm() <= settings_.rootRadius) continue;
      const BodyCollider::Hit hit = trunkCollider.closest(x, kSearch);
      const float d = hit.found ? hit.signedDistance : std::numeric_limits<float>::infinity();
      if (!(d > 0.f)) continue;  // inside the trunk at rest: the part's root, meant to overlap
      limb.vertices.push_back(v);
      limb.restDistance.push_back(d);
    }
    if (!limb.vertices.empty()) limbs_.push_back(std::move(limb));
  }
}

std::vector<LimbCorrection> LimbClearance::apply(Pose& pose) const {
  std::vector<LimbCorrection> out;
  if (limbs_.empty() || pose.local.size() != skeleton_.size() || !pose.rootTranslation.allFinite()) return out;
  for (const Quatf& q : pose.local)
    if (!q.coeffs().allFinite() || !(q.norm() > 0.f)) return out;
  // Measured with the root at rest, as the solver simulates it (the shape ignores the root).
  Pose p = pose;
  p.local[0] = skeleton_.joints[0].rest.rotation;
  p.rootTranslation = skeleton_.joints[0].rest.translation;

  // The trunk is posed once: turning a limb moves only the few trunk vertices its blends reach, near
  // its root, where nothing is checked.
  BodyCollider trunk = *trunk_;
  trunk.pose(skeleton_.skinningMatrices(p));
  for (const Limb& limb : limbs_) {
    // How far the limb is inside its clearance, the trunk's outward direction there and the centre of
    // the offending vertices.
    Vec3f push = Vec3f::Zero(), centre = Vec3f::Zero();
    auto measure = [&] {
      const std::vector<Mat4f> m = skeleton_.skinningMatrices(p);
      float worst = 0.f, total = 0.f;
      push.setZero();
      centre.setZero();
      for (size_t i = 0; i < limb.vertices.size(); ++i) {
        const uint32_t v = limb.vertices[i];
        const Mat4f b = blendedSkinMatrix(body_.skin, v, m);
        const Vec3f x = b.topLeftCorner<3, 3>() * body_.positions.row(v).transpose() + b.topRightCorner<3, 1>();
        const float want = std::min(settings_.clearance, limb.restDistance[i]);
        const BodyCollider::Hit hit = trunk.closest(x, want + kSearch);
        if (!hit.found) continue;
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
    Vec3f axis = (centre - head).cross(push);
    LimbCorrection c{skeleton_.joints[size_t(j)].name, 0.f, before, before};
    if (!(axis.norm() > 1e-9f)) {  // pushed straight along the limb: no rotation helps
      out.push_back(c);
      continue;
    }
    axis.normalize();
    const Quatf global = g[size_t(j)].rotation, parentInv = g[size_t(parent)].rotation.conjugate();
    // The smallest whole number of degrees that clears the limb: 5-degree steps, then bisection.
    int tried = 0;  // the turn p holds
    auto depthAt = [&](int degrees) {
      tried = degrees;
      const Quatf turn(Eigen::AngleAxisf(float(degrees) * float(M_PI) / 180.f, axis));
      p.local[size_t(j)] = (parentInv * turn * global).normalized();
      return measure();
    };
    const int most = int(settings_.maxDegrees);
    int lo = 0, hi = 0;
    float after = before;
    while (after > kTolerance && hi < most) {
      lo = hi;
      hi = std::min(most, hi + 5);
      after = depthAt(hi);
    }
    while (after <= kTolerance && hi - lo > 1) {
      const int mid = (lo + hi) / 2;
      const float d = depthAt(mid);
      if (d <= kTolerance) hi = mid, after = d;
      else lo = mid;
    }
    const int degrees = hi;
    if (tried != degrees) after = depthAt(degrees);
    pose.local[size_t(j)] = p.local[size_t(j)];
    c.degrees = float(degrees);
    c.depthAfter = after > kTolerance ? after : 0.f;
    out.push_back(c);
  }
  return out;
}

}  // namespace swish::bake
