// The body proxy of the run-time push-out and the penetration measure: bake::fitBodyProxy,
// bake::measurePenetration and runtime::referencePushOut on the analytic capsule character (exact
// distances, test_cloth_fixture.hpp) and on the embedded default character.
#include <gtest/gtest.h>

#include <cmath>

#include "support/cloth_fixture.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/cloth/body_collider.hpp"
#include "swish/bake/report/penetration.hpp"
#include "swish/bake/training/body_proxy_fit.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/reference_push_out.hpp"

namespace swish {
namespace {

// Points on a capsule's surface (rings along it and its two caps).
std::vector<Vec3f> capsuleSurface(const BodyCapsule& c) {
  std::vector<Vec3f> out;
  Vec3f u = c.b - c.a;
  const float len = u.norm();
  u = len > 0 ? Vec3f(u / len) : Vec3f::UnitY();
  const Vec3f v = (std::abs(u.x()) < 0.9f ? Vec3f::UnitX() : Vec3f::UnitY()).cross(u).normalized(), w = u.cross(v);
  for (int i = 0; i <= 10; ++i)
    for (int k = 0; k < 36; ++k) {
      const float t = 2.f * float(M_PI) * float(k) / 36.f;
      out.push_back(c.a + u * (len * float(i) / 10.f) + (v * std::cos(t) + w * std::sin(t)) * c.radius);
    }
  out.push_back(c.a - u * c.radius);
  out.push_back(c.b + u * c.radius);
  return out;
}

std::vector<float> restPosed(const BodyProxy& p, size_t joints) {
  std::vector<float> posed;
  runtime::poseBodyProxy(p, std::vector<Mat4f>(joints, Mat4f::Identity()), posed);
  return posed;
}

TEST(Penetration, CountsAndDepthOnAnAnalyticBody) {
  const test::CapsuleSpec spec;
  const Character ch = test::capsuleCharacter(spec);
  bake::BodyCollider collider(ch.body, 0.05f);
  collider.pose(std::vector<Mat4f>(ch.skeleton.size(), Mat4f::Identity()));
  Points3f p(4, 3);
  p.row(0) << 0.f, 0.35f, spec.radius - 0.001f;  // 1 mm inside: inside, not visible
  p.row(1) << 0.f, 0.35f, spec.radius - 0.010f;  // 10 mm inside: visible
  p.row(2) << 0.f, 0.35f, spec.radius + 0.005f;  // outside
  p.row(3) << spec.radius - 0.004f, 0.5f, 0.f;   // 4 mm inside: visible
  const bake::PenetrationStats s = bake::measurePenetration(collider, p);
  EXPECT_EQ(s.vertices, 4u);
  EXPECT_EQ(s.inside, 3u);
  EXPECT_EQ(s.visible, 2u);
  // The tessellated surface lies inside the analytic one by at most r (1 - cos(pi / 32)) = 0.6 mm.
  EXPECT_NEAR(s.deepestMm, 10.0, 0.7);
  bake::PenetrationPool pool;
  pool.add(s);
  pool.add({});
  EXPECT_EQ(pool.frames, 2u);
  EXPECT_EQ(pool.framesVisible, 1u);
  EXPECT_NEAR(pool.deepestPercentileMm(0.5), 0.0, 1e-12);
  EXPECT_NEAR(pool.deepestPercentileMm(1.0), s.deepestMm, 1e-12);
}

TEST(PushOutReference, KnownAnswers) {
  BodyProxy proxy;
  proxy.capsules = {{0, Vec3f(0, 1, 0), Vec3f(0.2f, 1, 0), 0.05f}, {0, Vec3f(1, 1, 1), Vec3f(1, 1, 1), 0.1f}};
  Points3f p(4, 3);
  p.row(0) << 0.1f, 1.01f, 0.f;  // in capsule 0: to y = 1.05
  p.row(1) << 1.f, 1.f, 1.05f;   // in sphere 1: to z = 1.1
  p.row(2) << 0.1f, 1.f, 0.f;    // on the axis: stays
  p.row(3) << 0.5f, 0.5f, 0.5f;  // outside both
  const Points3f before = p;
  EXPECT_EQ(runtime::referencePushOut(p, restPosed(proxy, 1)), 2u);
  EXPECT_NEAR(p(0, 1), 1.05f, 1e-6f);
  EXPECT_NEAR(p(0, 0), 0.1f, 1e-6f);
  EXPECT_NEAR(p(1, 2), 1.1f, 1e-6f);
  EXPECT_EQ(p.row(2), before.row(2));
  EXPECT_EQ(p.row(3), before.row(3));
  // Posing moves the capsule with its joint: translated by +1 in x, vertex 0 is outside it now.
  std::vector<float> posed;
  Mat4f m = Mat4f::Identity();
  m(0, 3) = 1.f;
  runtime::poseBodyProxy(proxy, std::vector<Mat4f>{m}, posed);
  Points3f q = before.topRows(1);
  EXPECT_EQ(runtime::referencePushOut(q, std::span<const float>(posed).first(8)), 0u);
  EXPECT_THROW(runtime::poseBodyProxy(proxy, std::vector<Mat4f>{}, posed), Error);
}

// On the analytic capsule body the fit is one tight capsule per joint segment, inside the body, and the
// garment at rest (outside the body) is left alone by the push-out.
TEST(BodyProxyFit, InsideTheAnalyticBodyAndTight) {
  const test::CapsuleSpec spec;
  const Character ch = test::capsuleCharacter(spec);
  const bake::BodyProxyFit fit = bake::fitBodyProxy(ch.body, ch.skeleton, &ch.garment);
  ASSERT_FALSE(fit.proxy.empty());
  EXPECT_LE(fit.proxy.capsules.size(), kMaxBodyCapsules);
  EXPECT_LE(fit.worstOutsideMm, 1000.f * bake::kInsideTolerance);
  float widest = 0;
  for (const BodyCapsule& c : fit.proxy.capsules) {
    widest = std::max(widest, c.radius);
    for (const Vec3f& p : capsuleSurface(c)) ASSERT_LE(test::capsuleSignedDistance(spec, p), 0.001f) << p.transpose();
  }
  EXPECT_GT(widest, 0.95f * spec.radius) << "a capsule in a capsule fits within a few millimetres";
  Points3f garment = ch.garment.positions;
  EXPECT_EQ(runtime::referencePushOut(garment, restPosed(fit.proxy, ch.skeleton.size())), 0u);
}

// Garment pushed 3 cm into the analytic body: the push-out brings it back to within the proxy's gap
// to the real surface, and the measure sees the difference.
TEST(BodyProxyFit, PushOutRemovesDeepPenetration) {
  const test::CapsuleSpec spec;
  const Character ch = test::capsuleCharacter(spec);
  const bake::BodyProxyFit fit = bake::fitBodyProxy(ch.body, ch.skeleton, &ch.garment);
  bake::BodyCollider collider(ch.body, 0.05f);
  collider.pose(std::vector<Mat4f>(ch.skeleton.size(), Mat4f::Identity()));
  Points3f inside = ch.garment.positions;
  for (Eigen::Index v = 0; v < inside.rows(); ++v) {
    const Vec3f p = inside.row(v).transpose();
    Vec3f radial(p.x(), 0, p.z());
    inside.row(v) = (p - radial.normalized() * (spec.gap + 0.03f)).transpose();
  }
  const bake::PenetrationStats before = bake::measurePenetration(collider, inside);
  EXPECT_EQ(before.inside, before.vertices);
  EXPECT_NEAR(before.deepestMm, 30.0, 1.0);
  Points3f pushed = inside;
  EXPECT_EQ(runtime::referencePushOut(pushed, restPosed(fit.proxy, ch.skeleton.size())), size_t(inside.rows()));
  const bake::PenetrationStats after = bake::measurePenetration(collider, pushed);
  EXPECT_LT(after.deepestMm, 1000.0 * (spec.radius - 0.95f * spec.radius) + 1.0);
  EXPECT_EQ(after.visible, 0u);
}

// The embedded default character: capsules on the trunk and both arms, inside the body (the collider's
// signed distance, the union of the mannequin's parts), none touching the jersey at rest, deterministic.
TEST(BodyProxyFit, DefaultCharacter) {
  const Character ch = bake::makeDefaultCharacter();
  const bake::BodyProxyFit fit = bake::fitBodyProxy(ch.body, ch.skeleton, &ch.garment);
  ASSERT_FALSE(fit.proxy.empty());
  for (const char* joint : {"Spine", "Spine1", "LeftArm", "RightArm", "LeftForeArm", "RightForeArm"})
    EXPECT_NE(std::find(fit.capsuleJoints.begin(), fit.capsuleJoints.end(), joint), fit.capsuleJoints.end()) << joint;
  for (const char* joint : {"LeftToeBase", "RightFoot"})
    EXPECT_EQ(std::find(fit.capsuleJoints.begin(), fit.capsuleJoints.end(), joint), fit.capsuleJoints.end())
        << joint << " is out of the garment's reach";
  bake::BodyCollider collider(ch.body, 0.05f);
  collider.pose(std::vector<Mat4f>(ch.skeleton.size(), Mat4f::Identity()));
  for (size_t c = 0; c < fit.proxy.capsules.size(); ++c)
    for (const Vec3f& p : capsuleSurface(fit.proxy.capsules[c])) {
      const bake::BodyCollider::Hit h = collider.closest(p, 0.2f);
      ASSERT_TRUE(h.found) << fit.capsuleJoints[c];
      ASSERT_LE(h.signedDistance, 0.001f) << fit.capsuleJoints[c] << " at " << p.transpose();
    }
  Points3f garment = ch.garment.positions;
  EXPECT_EQ(runtime::referencePushOut(garment, restPosed(fit.proxy, ch.skeleton.size())), 0u);
  const bake::BodyProxyFit again = bake::fitBodyProxy(ch.body, ch.skeleton, &ch.garment);
  ASSERT_EQ(again.proxy.capsules.size(), fit.proxy.capsules.size());
  for (size_t c = 0; c < fit.proxy.capsules.size(); ++c) {
    EXPECT_EQ(again.proxy.capsules[c].a, fit.proxy.capsules[c].a);
    EXPECT_EQ(again.proxy.capsules[c].b, fit.proxy.capsules[c].b);
    EXPECT_EQ(again.proxy.capsules[c].radius, fit.proxy.capsules[c].radius);
  }
}

}  // namespace
}  // namespace swish
