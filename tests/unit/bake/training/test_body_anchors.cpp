// The body anchors of the run-time push-out and the penetration measure: bake::fitBodyAnchors and
// bake::calibrateBodyAnchors on a box body (known weights and normals), the analytic capsule character
// (exact distances, support/cloth_fixture.hpp) and the embedded default character;
// runtime::referencePushOut on hand-made anchors; bake::measurePenetration.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/cloth_fixture.hpp"
#include "swish/bake/character/default_character.hpp"
#include "swish/bake/cloth/body_collider.hpp"
#include "swish/bake/report/penetration.hpp"
#include "swish/bake/training/body_anchor_fit.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/reference_push_out.hpp"

namespace swish {
namespace {

std::vector<Mat4f> identities(size_t joints) { return std::vector<Mat4f>(joints, Mat4f::Identity()); }

// The capsule character's garment moved `up` along the axis (kept on the cylinder) and `off` from the
// (analytic) skin: cloth slid over the body.
Points3f slidOnCapsule(const Character& ch, const test::CapsuleSpec& spec, float up, float off) {
  Points3f g = ch.garment.positions;
  for (Eigen::Index v = 0; v < g.rows(); ++v) {
    const Vec3f p = g.row(v).transpose();
    const Vec3f radial = Vec3f(p.x(), 0.f, p.z()).normalized();
    const float y = std::clamp(p.y() + up, spec.axisLow, spec.axisHigh);
    g.row(v) = (radial * (spec.radius + off) + Vec3f(0.f, y, 0.f)).transpose();
  }
  return g;
}

float weightSum(const BodyAnchor& a) { return a.weights[0] + a.weights[1] + a.weights[2] + a.weights[3]; }

TEST(Penetration, CountsAndDepthOnAnAnalyticBody) {
  const test::CapsuleSpec spec;
  const Character ch = test::capsuleCharacter(spec);
  bake::BodyCollider collider(ch.body, 0.05f);
  collider.pose(identities(ch.skeleton.size()));
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

// A closed box [-0.1, 0.1]^3 (outward winding) on a chain of 8 joints; corner c is skinned 0.6 to joint
// c and 0.4 to joint c + 1 (mod 8), so a point on a face mixes up to six joints and the fit must keep
// four.
struct BoxBody {
  Skeleton skeleton;
  Mesh body;
};
BoxBody boxBody() {
  BoxBody b;
  for (int j = 0; j < 8; ++j)
    b.skeleton.joints.push_back(
        {std::string(1, char('a' + j)), j - 1, {Quatf::Identity(), Vec3f(0, j ? 0.01f : 0.f, 0)}});
  b.skeleton.computeInverseBindFromRest();
  Mesh& m = b.body;
  m.positions.resize(8, 3);
  for (int c = 0; c < 8; ++c)
    m.positions.row(c) << (c & 1 ? 0.1f : -0.1f), (c & 2 ? 0.1f : -0.1f), (c & 4 ? 0.1f : -0.1f);
  // Faces as quads (counter-clockwise seen from outside), two triangles each.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  m.triangles.resize(12, 3);
  for (int f = 0; f < 6; ++f) {
    m.triangles.row(2 * f) << quads[f][0], quads[f][1], quads[f][2];
    m.triangles.row(2 * f + 1) << quads[f][0], quads[f][2], quads[f][3];
  }
  m.skin.influences = 2;
  for (uint16_t c = 0; c < 8; ++c) {
    m.skin.joints.insert(m.skin.joints.end(), {c, uint16_t((c + 1) % 8)});
    m.skin.weights.insert(m.skin.weights.end(), {0.6f, 0.4f});
  }
  return b;
}

Mesh pointsMesh(std::initializer_list<Vec3f> pts) {
  Mesh g;
  g.positions.resize(Eigen::Index(pts.size()), 3);
  Eigen::Index i = 0;
  for (const Vec3f& p : pts) g.positions.row(i++) = p.transpose();
  return g;
}

TEST(BodyAnchorFit, BoxBodyPointsNormalsAndWeights) {
  const BoxBody box = boxBody();
  const Mesh garment = pointsMesh({
      Vec3f(0.12f, 0.12f, 0.12f),   // off corner 7: the corner itself
      Vec3f(0.f, 0.12f, 0.12f),     // off the edge between corners 6 and 7: its midpoint
      Vec3f(0.03f, 0.02f, 0.125f),  // off face z = +0.1
      Vec3f(0.f, 0.f, 0.2f),        // 10 cm off: beyond the 4 cm bound
      Vec3f(0.f, 0.f, 0.09f),       // inside the box, 1 cm under face z = +0.1
  });
  const bake::BodyAnchorFit fit = bake::fitBodyAnchors(box.body, box.skeleton, garment);
  ASSERT_EQ(fit.anchors.anchors.size(), 5u);
  EXPECT_EQ(fit.anchored, 4u);
  EXPECT_EQ(fit.tooFar, 1u);
  EXPECT_EQ(fit.insideAtRest, 1u);
  const auto& a = fit.anchors.anchors;

  // The corner: its own weights exactly (joint 7 at 0.6, joint 0 at 0.4), its normal pointing out.
  EXPECT_LT((a[0].position - Vec3f(0.1f, 0.1f, 0.1f)).norm(), 1e-6f);
  EXPECT_EQ(a[0].joints[0], 7);
  EXPECT_EQ(a[0].joints[1], 0);
  EXPECT_NEAR(a[0].weights[0], 0.6f, 1e-6f);
  EXPECT_NEAR(a[0].weights[1], 0.4f, 1e-6f);
  EXPECT_EQ(a[0].weights[2], 0.f);
  EXPECT_GT(a[0].normal.dot(Vec3f(1, 1, 1).normalized()), 0.9f);
  EXPECT_LT(a[0].radius, 0.005f) << "no ball of any size fits into a corner";

  // The edge midpoint: half of corner 6 (joints 6, 7) and half of corner 7 (joints 7, 0).
  EXPECT_LT((a[1].position - Vec3f(0.f, 0.1f, 0.1f)).norm(), 1e-6f);
  EXPECT_EQ(a[1].joints[0], 7);  // 0.5 * 0.4 + 0.5 * 0.6
  EXPECT_NEAR(a[1].weights[0], 0.5f, 1e-6f);
  EXPECT_NEAR(a[1].weights[1], 0.3f, 1e-6f);  // joint 6
  EXPECT_NEAR(a[1].weights[2], 0.2f, 1e-6f);  // joint 0
  EXPECT_EQ(a[1].joints[1], 6);
  EXPECT_EQ(a[1].joints[2], 0);

  // On the face: the closest point straight below, normal mostly +z, four weights summing to 1, largest
  // first (the corner-averaged vertex normals tilt it towards the corners).
  EXPECT_LT((a[2].position - Vec3f(0.03f, 0.02f, 0.1f)).norm(), 1e-6f);
  EXPECT_GT(a[2].normal.z(), 0.7f);
  // A face holds a large ball, if not the box's own 10 cm one: on so coarse a mesh the interpolated
  // normal leans towards the corners, and so does the ball.
  EXPECT_GT(a[2].radius, 0.01f);
  EXPECT_LE(a[2].radius, 0.101f) << "the box's own inscribed ball is the largest";
  for (int i = 0; i < 4; ++i) EXPECT_GT(a[2].weights[size_t(i)], 0.f) << i;
  for (int i = 0; i < 3; ++i) EXPECT_GE(a[2].weights[size_t(i)], a[2].weights[size_t(i + 1)]) << i;

  EXPECT_FALSE(a[3].present());
  EXPECT_EQ(a[3].position, Vec3f::Zero());

  // Inside: anchored on the nearest face, its normal out of the box, so the vertex is behind its plane.
  EXPECT_LT((a[4].position - Vec3f(0.f, 0.f, 0.1f)).norm(), 1e-6f);
  EXPECT_GT(a[4].normal.z(), 0.7f);

  for (const BodyAnchor& an : a) {
    if (!an.present()) continue;
    EXPECT_NEAR(an.normal.norm(), 1.f, 1e-5f);
    EXPECT_NEAR(weightSum(an), 1.f, 1e-5f);
    EXPECT_EQ(an.clearance, fit.anchors.margin);
  }
  EXPECT_NO_THROW(bake::fitBodyAnchors(box.body, box.skeleton, garment, {0.2f, 0.001f}));
  EXPECT_THROW(bake::fitBodyAnchors(box.body, box.skeleton, garment, {-1.f, 0.002f}), Error);
  EXPECT_THROW(bake::fitBodyAnchors(box.body, box.skeleton, garment, {0.04f, 0.5f}), Error);
}

// Anchors on the garment vertex's own joints (BodyAnchorFitSettings::garmentJoints, bake::onGarmentJoints):
// the box's corner 7 (body joints 7 at 0.6, 0 at 0.4) under a vertex skinned to 7 and 3 keeps joint 7
// alone; the edge midpoint (7 at 0.5, 6 at 0.3, 0 at 0.2) under a vertex skinned to 6 and 7 drops joint
// 0 and renormalises the rest in rank order; a face point (joints of corners 4-7 and 0) under a vertex
// skinned to 1 and 2 keeps none, and its anchor is removed. With the setting off the body's skin stays.
TEST(BodyAnchorFit, AnchorsOnTheGarmentVertexsJoints) {
  const BoxBody box = boxBody();
  Mesh garment = pointsMesh({Vec3f(0.12f, 0.12f, 0.12f), Vec3f(0.f, 0.12f, 0.12f), Vec3f(0.03f, 0.02f, 0.125f)});
  garment.skin.influences = 2;
  garment.skin.joints = {7, 3, 6, 7, 1, 2};
  garment.skin.weights = {0.5f, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f};
  bake::BodyAnchorFitSettings off;
  off.garmentJoints = false;
  const bake::BodyAnchorFit body = bake::fitBodyAnchors(box.body, box.skeleton, garment, off);
  const bake::BodyAnchorFit fit = bake::fitBodyAnchors(box.body, box.skeleton, garment);
  ASSERT_EQ(body.anchored, 3u);
  EXPECT_EQ(body.garmentJointsChanged, 0u);
  EXPECT_EQ(body.anchors.anchors[1].joints[2], 0);  // the body's skin: joint 0 kept with the setting off
  const auto& a = fit.anchors.anchors;
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[0].joints[0], 7);
  EXPECT_NEAR(a[0].weights[0], 1.f, 1e-6f);
  EXPECT_EQ(a[0].weights[1], 0.f);
  EXPECT_EQ(a[1].joints[0], 7);
  EXPECT_EQ(a[1].joints[1], 6);
  EXPECT_NEAR(a[1].weights[0], 0.625f, 1e-6f);
  EXPECT_NEAR(a[1].weights[1], 0.375f, 1e-6f);
  EXPECT_EQ(a[1].weights[2], 0.f);
  EXPECT_FALSE(a[2].present());
  // Everything else about the anchors is the fit's.
  for (size_t v = 0; v < 2; ++v) {
    EXPECT_EQ(a[v].position, body.anchors.anchors[v].position) << v;
    EXPECT_EQ(a[v].radius, body.anchors.anchors[v].radius) << v;
  }
  EXPECT_EQ(fit.anchored, 2u);
  EXPECT_EQ(fit.garmentJointsChanged, 3u);
  EXPECT_EQ(fit.garmentJointsDropped, 6u);  // one, one, and the face point's four
  EXPECT_EQ(fit.garmentJointsRemoved, 1u);
  EXPECT_NEAR(fit.garmentJointsMaxDropped, 0.4f, 1e-6f);
  EXPECT_EQ(bake::toJson(fit)["garment_joints"]["anchors_removed"], 1u);
}

// The counts follow the anchors onGarmentJoints removes: a slide anchor left with none of its garment
// vertex's joints is no longer counted among the slide anchors, a second anchor on another part (not a
// slide one) that goes leaves the slide count alone, and a slide anchor that keeps a joint stays counted.
TEST(BodyAnchorFit, RemovedSlideAnchorsLeaveTheSlideCount) {
  auto on = [](uint16_t joint) {
    BodyAnchor a;
    a.radius = 0.05f;
    a.joints[0] = joint;
    a.weights[0] = 1.f;
    return a;
  };
  bake::BodyAnchorFit fit;
  fit.anchors.anchors = {on(1), on(1), on(1)};
  fit.anchors.second = {on(5), on(1), on(6)};  // a slide anchor off the garment's joints, one on them, another part's
  fit.anchored = 3;
  fit.secondAnchored = 3;
  fit.slideAnchored = 2;
  fit.isSlide = {1, 1, 0};
  SkinWeights skin;
  skin.influences = 1;
  skin.joints = {1, 1, 1};
  skin.weights = {1.f, 1.f, 1.f};
  bake::onGarmentJoints(fit, skin);
  EXPECT_FALSE(fit.anchors.second[0].present());
  EXPECT_TRUE(fit.anchors.second[1].present());
  EXPECT_FALSE(fit.anchors.second[2].present());
  EXPECT_EQ(fit.anchored, 3u);
  EXPECT_EQ(fit.secondAnchored, 1u);
  EXPECT_EQ(fit.slideAnchored, 1u);
  EXPECT_EQ(fit.garmentJointsRemoved, 2u);
}

// Two boxes side by side, 5 cm apart (x in [-0.1, 0.1] and [0.15, 0.35]), the second skinned to the
// first's joints shifted by 4: two parts. A vertex between them gets its nearest box as its anchor and
// the other as its second; a vertex with the other box beyond the bound gets none; with the second
// anchors off there are none. At run time the second anchor pushes out of the second box a vertex its
// first anchor leaves inside it.
TEST(BodyAnchorFit, SecondAnchorOnTheOtherPart) {
  BoxBody two = boxBody();
  const Mesh one = two.body;
  Mesh& m = two.body;
  m.positions.conservativeResize(16, 3);
  m.positions.bottomRows(8) = one.positions;
  m.positions.bottomRows(8).col(0).array() += 0.25f;
  m.triangles.conservativeResize(24, 3);
  m.triangles.bottomRows(12) = one.triangles.array() + 8;
  for (size_t c = 0; c < 8; ++c) {
    m.skin.joints.insert(m.skin.joints.end(), {uint16_t((c + 4) % 8), uint16_t((c + 5) % 8)});
    m.skin.weights.insert(m.skin.weights.end(), {0.6f, 0.4f});
  }
  const Mesh garment = pointsMesh({
      Vec3f(0.12f, 0.f, 0.f),   // 2 cm off the first box, 3 cm off the second
      Vec3f(0.135f, 0.f, 0.f),  // 1.5 cm off the second, 3.5 cm off the first
      Vec3f(-0.12f, 0.f, 0.f),  // the second box 27 cm away
  });
  const bake::BodyAnchorFit fit = bake::fitBodyAnchors(m, two.skeleton, garment);
  EXPECT_EQ(fit.anchored, 3u);
  EXPECT_EQ(fit.secondAnchored, 2u);
  ASSERT_EQ(fit.anchors.second.size(), 3u);
  EXPECT_EQ(fit.anchors.slots(), 2u);
  const auto& a = fit.anchors.anchors;
  const auto& b = fit.anchors.second;
  EXPECT_LT((a[0].position - Vec3f(0.1f, 0.f, 0.f)).norm(), 1e-6f);
  EXPECT_GT(a[0].normal.x(), 0.98f);  // (the corner-averaged normals lean a little on so coarse a mesh)
  EXPECT_LT((b[0].position - Vec3f(0.15f, 0.f, 0.f)).norm(), 1e-6f);
  EXPECT_LT(b[0].normal.x(), -0.98f) << "the second box's face looks back at the first";
  EXPECT_GT(b[0].radius, 0.05f) << "the middle of a face holds a large ball";
  EXPECT_LE(b[0].radius, 0.101f);
  EXPECT_EQ(b[0].clearance, fit.anchors.margin);
  EXPECT_NEAR(weightSum(b[0]), 1.f, 1e-5f);
  EXPECT_LT((a[1].position - Vec3f(0.15f, 0.f, 0.f)).norm(), 1e-6f);  // the nearer box first
  EXPECT_LT((b[1].position - Vec3f(0.1f, 0.f, 0.f)).norm(), 1e-6f);
  EXPECT_TRUE(a[2].present());
  EXPECT_FALSE(b[2].present());

  // The vertex between the boxes moved 12.5 mm into the second box: its own anchor (the first box) leaves
  // it there; the second pushes it out to 2 mm off the second box's ball, i.e. off its face.
  Points3f x(3, 3);
  x << 0.1625f, 0.f, 0.f, 0.135f, 0.f, 0.f, -0.12f, 0.f, 0.f;
  Points3f pushed = x;
  EXPECT_EQ(runtime::referencePushOut(pushed, fit.anchors, identities(two.skeleton.size())), 1u);
  EXPECT_NEAR(pushed(0, 0), 0.15f - fit.anchors.margin, 2e-3f);
  EXPECT_EQ(pushed.bottomRows(2), x.bottomRows(2));
  BodyAnchors firstOnly = fit.anchors;
  firstOnly.second.clear();
  pushed = x;
  EXPECT_EQ(runtime::referencePushOut(pushed, firstOnly, identities(two.skeleton.size())), 0u);

  bake::BodyAnchorFitSettings off;
  off.secondAnchors = false;
  const bake::BodyAnchorFit single = bake::fitBodyAnchors(m, two.skeleton, garment, off);
  EXPECT_TRUE(single.anchors.second.empty());
  EXPECT_EQ(single.secondAnchored, 0u);
  EXPECT_EQ(single.anchors.slots(), 1u);

  // Calibration, second anchors after the first: vertex 0's truth lies 12.5 mm inside the second box in
  // both poses, as does the network's vertex, so pushing it out would only add error: its second
  // anchor's clearance goes down to where it pushes nothing; vertex 1's truth is outside its second
  // ball (the first box), so that one keeps its margin.
  Points3f truth = x;
  truth(1, 0) = 0.14f;
  const std::vector<bake::BodyAnchorCalibrationPose> poses = {{identities(two.skeleton.size()), &truth, &x},
                                                              {identities(two.skeleton.size()), &truth, &x}};
  BodyAnchors calibrated = fit.anchors;
  const bake::BodyAnchorCalibration c = bake::calibrateBodyAnchors(calibrated, poses);
  EXPECT_LT(calibrated.second[0].clearance, -0.012f);
  EXPECT_EQ(calibrated.second[1].clearance, fit.anchors.margin);
  EXPECT_EQ(c.secondDropped, 0u);
  EXPECT_LE(c.meanMmWith, c.meanMmWithout + 1e-9);
  pushed = x;
  runtime::referencePushOut(pushed, calibrated, identities(two.skeleton.size()));
  EXPECT_EQ(pushed.row(0), x.row(0)) << "calibrated not to push against the truth";
  // The first anchors only: the second keep the margin, and push.
  BodyAnchors firstCalibrated = fit.anchors;
  bake::BodyAnchorCalibrationSettings firstOnlySettings;
  firstOnlySettings.second = false;
  const bake::BodyAnchorCalibration c1 = bake::calibrateBodyAnchors(firstCalibrated, poses, firstOnlySettings);
  EXPECT_EQ(firstCalibrated.second[0].clearance, fit.anchors.margin);
  EXPECT_GT(c1.meanMmWith, c1.meanMmWithout) << "pushed against the truth";
  EXPECT_GT(c1.pushedShare, 0.0);
}

// Cloth that slides over the body: the capsule's garment in a pose where it has slid 10 cm up and lies
// 4 mm off the skin. Each vertex's first ball (centred on the axis at its rest height) misses the skin
// there by 3.4 cm, so the push-out cannot keep the slid cloth out of the body; the slide anchor, the
// ball under where the cloth slid to, does. Cloth that touches the skin where it sat at rest, or that
// does not touch it at all, gets none.
TEST(BodyAnchorFit, SlideAnchorsCoverTheSkinTheClothSlidOnto) {
  const test::CapsuleSpec spec;
  const Character ch = test::capsuleCharacter(spec);
  const std::vector<Mat4f> rest = identities(ch.skeleton.size());
  auto onSkin = [&](float up, float off) { return slidOnCapsule(ch, spec, up, off); };
  const Points3f slid = onSkin(0.1f, 0.004f), unslid = onSkin(0.f, 0.004f), away = onSkin(0.1f, 0.03f);
  const bake::BodyAnchorFit plain = bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment);
  EXPECT_EQ(plain.slideAnchored, 0u);
  EXPECT_TRUE(plain.anchors.second.empty()) << "a one-part body has no other part";
  const bake::BodyAnchorFit none =
      bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment, {}, {{rest, &unslid}, {rest, &away}});
  EXPECT_EQ(none.slideAnchored, 0u);
  EXPECT_EQ(none.slidePoses, 2u);
  const bake::BodyAnchorFit fit =
      bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment, {}, {{rest, &unslid}, {rest, &slid}, {rest, &away}});
  EXPECT_EQ(fit.slideAnchored, ch.garment.vertexCount());
  EXPECT_EQ(fit.secondAnchored, fit.slideAnchored);
  ASSERT_EQ(fit.anchors.second.size(), ch.garment.vertexCount());
  for (size_t v = 0; v < ch.garment.vertexCount(); ++v) {
    const BodyAnchor& a = fit.anchors.anchors[v];
    const BodyAnchor& b = fit.anchors.second[v];
    ASSERT_TRUE(b.present()) << v;
    const float want = std::min(a.position.y() + 0.1f, spec.axisHigh);
    EXPECT_NEAR(b.position.y(), want, 0.012f) << v << ": where the cloth slid to";
    EXPECT_NEAR(test::capsuleSignedDistance(spec, b.position), 0.f, 0.001f) << v;
    EXPECT_NEAR(b.radius, spec.radius, 0.003f) << v;
  }
  // The slid cloth 3 mm under the skin: the first balls leave it there, the slide anchors push it out.
  const Points3f inside = onSkin(0.1f, -0.003f);
  bake::BodyCollider collider(ch.body, 0.05f);
  collider.pose(rest);
  const uint32_t before = bake::measurePenetration(collider, inside).inside;
  EXPECT_GT(before, uint32_t(inside.rows()) * 9 / 10);
  Points3f p = inside;
  runtime::referencePushOut(p, plain.anchors, rest);
  EXPECT_GT(bake::measurePenetration(collider, p).inside, uint32_t(inside.rows()) * 9 / 10);
  p = inside;
  runtime::referencePushOut(p, fit.anchors, rest);
  EXPECT_EQ(bake::measurePenetration(collider, p).inside, 0u);
  // A pose whose sizes do not fit is named.
  const std::vector<Mat4f> short_(1, Mat4f::Identity());
  try {
    bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment, {}, {{rest, &slid}, {short_, &slid}});
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("slide pose 1 has 1 skinning matrices"), std::string::npos) << e.what();
  }
}

// Cloth that slides to two places: once 10 cm up (the largest miss, which the slide anchor takes) and,
// in three poses, 4.5 cm down, where both the first ball and the slide anchor's miss the skin by 8 mm.
// The cover anchor, the third set, is the ball under the frequent slide: with it the cloth slid down
// and 3 mm under the skin is pushed out; without it (the first two sets) it stays inside.
TEST(BodyAnchorFit, CoverAnchorsHoldTheFrequentSlideTheSlideAnchorLeaves) {
  const test::CapsuleSpec spec;
  const Character ch = test::capsuleCharacter(spec);
  const std::vector<Mat4f> rest = identities(ch.skeleton.size());
  auto onSkin = [&](float up, float off) { return slidOnCapsule(ch, spec, up, off); };
  const Points3f up = onSkin(0.1f, 0.004f), down = onSkin(-0.045f, 0.004f);
  const std::vector<bake::BodyAnchorSlidePose> poses = {{rest, &up}, {rest, &down}, {rest, &down}, {rest, &down}};
  const bake::BodyAnchorFit fit = bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment, {}, poses);
  const size_t n = ch.garment.vertexCount();
  EXPECT_EQ(fit.slideAnchored, n);
  EXPECT_EQ(fit.coverAnchored, n);
  EXPECT_EQ(fit.coverMisses, 3 * n) << "the three poses slid down, each vertex";
  EXPECT_EQ(fit.coverCovered, 3 * n);
  ASSERT_EQ(fit.anchors.slots(), 3u);
  ASSERT_EQ(fit.anchors.third.size(), n);
  for (size_t v = 0; v < n; ++v) {
    const BodyAnchor& a = fit.anchors.anchors[v];
    const BodyAnchor& b = fit.anchors.second[v];
    const BodyAnchor& c = fit.anchors.third[v];
    ASSERT_TRUE(c.present()) << v;
    EXPECT_NEAR(b.position.y(), std::min(a.position.y() + 0.1f, spec.axisHigh), 0.012f) << v << ": the largest miss";
    EXPECT_NEAR(c.position.y(), a.position.y() - 0.045f, 0.012f) << v << ": the frequent slide";
    EXPECT_NEAR(test::capsuleSignedDistance(spec, c.position), 0.f, 0.001f) << v;
    EXPECT_NEAR(c.radius, spec.radius, 0.003f) << v;
  }
  // Off: the first two sets only, as format 1.4 had them.
  bake::BodyAnchorFitSettings off;
  off.coverAnchors = false;
  const bake::BodyAnchorFit two = bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment, off, poses);
  EXPECT_EQ(two.anchors.slots(), 2u);
  EXPECT_EQ(two.coverAnchored, 0u);
  for (size_t v = 0; v < n; ++v) EXPECT_EQ(two.anchors.second[v].position, fit.anchors.second[v].position) << v;
  // The cloth slid down and 3 mm under the skin: the first two sets leave it there, the third pushes it out.
  const Points3f inside = onSkin(-0.045f, -0.003f);
  bake::BodyCollider collider(ch.body, 0.05f);
  collider.pose(rest);
  EXPECT_GT(bake::measurePenetration(collider, inside).inside, uint32_t(n) * 9 / 10);
  Points3f p = inside;
  runtime::referencePushOut(p, two.anchors, rest);
  EXPECT_GT(bake::measurePenetration(collider, p).inside, uint32_t(n) * 9 / 10);
  p = inside;
  runtime::referencePushOut(p, fit.anchors, rest);
  EXPECT_EQ(bake::measurePenetration(collider, p).inside, 0u);
  // Calibrated like the other sets: against a truth that lies inside there, pushing would move the
  // network's garment away from it, so the third set's clearances go down (or the anchors are dropped).
  BodyAnchors calibrated = fit.anchors;
  const bake::BodyAnchorCalibration cal = bake::calibrateBodyAnchors(calibrated, {{rest, &inside, &inside}});
  EXPECT_EQ(cal.meanMmWith, cal.meanMmWithout) << "no vertex moved away from the truth";
  size_t thirdChanged = 0;
  for (size_t v = 0; v < n; ++v)
    thirdChanged += !calibrated.third[v].present() || calibrated.third[v].clearance < fit.anchors.margin ? 1 : 0;
  EXPECT_EQ(thirdChanged, n);
}

// On the analytic capsule body every garment vertex (a tube 12 mm off it) is anchored on the surface
// straight under it, with the radial normal and the body's own weights there.
TEST(BodyAnchorFit, AnalyticCapsule) {
  const test::CapsuleSpec spec;
  const Character ch = test::capsuleCharacter(spec);
  const bake::BodyAnchorFit fit = bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment);
  EXPECT_EQ(fit.anchored, ch.garment.vertexCount());
  EXPECT_EQ(fit.insideAtRest, 0u);
  EXPECT_EQ(fit.withinMargin, 0u);
  EXPECT_NEAR(fit.medianMm, 1000.0 * spec.gap, 1.0);
  for (size_t v = 0; v < ch.garment.vertexCount(); ++v) {
    const BodyAnchor& a = fit.anchors.anchors[v];
    ASSERT_TRUE(a.present()) << v;
    // The tessellated surface lies within r (1 - cos(pi / 32)) = 0.6 mm inside the analytic one.
    EXPECT_NEAR(test::capsuleSignedDistance(spec, a.position), 0.f, 0.001f) << v;
    const Vec3f radial = Vec3f(a.position.x(), 0.f, a.position.z()).normalized();
    EXPECT_GT(a.normal.dot(radial), 0.995f) << v;
    EXPECT_NEAR(a.radius, spec.radius, 0.003f) << v << ": the ball inscribed in a capsule is its radius";
    EXPECT_NEAR(weightSum(a), 1.f, 1e-5f) << v;
    uint16_t joints[4];
    float weights[4];
    test::capsuleWeights(a.position.y(), joints, weights);
    float dominant = 0.f;  // the body's weight of the anchor's first joint, by the analytic rule
    for (int i = 0; i < 4; ++i)
      if (joints[i] == a.joints[0]) dominant += weights[i];
    EXPECT_NEAR(a.weights[0], dominant, 0.08f) << v << " at y " << a.position.y();
  }
  const bake::BodyAnchorFit again = bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment);
  for (size_t v = 0; v < ch.garment.vertexCount(); ++v) {
    EXPECT_EQ(again.anchors.anchors[v].position, fit.anchors.anchors[v].position);
    EXPECT_EQ(again.anchors.anchors[v].weights, fit.anchors.anchors[v].weights);
  }

  // The garment pushed 3 cm into the body comes back out, its margin off the (tessellated) surface,
  // and the garment at rest is left alone.
  bake::BodyCollider collider(ch.body, 0.05f);
  collider.pose(identities(ch.skeleton.size()));
  Points3f inside = ch.garment.positions;
  for (Eigen::Index v = 0; v < inside.rows(); ++v) {
    const Vec3f p = inside.row(v).transpose();
    inside.row(v) = (p - Vec3f(p.x(), 0, p.z()).normalized() * (spec.gap + 0.03f)).transpose();
  }
  EXPECT_EQ(bake::measurePenetration(collider, inside).inside, inside.rows());
  Points3f pushed = inside;
  EXPECT_EQ(runtime::referencePushOut(pushed, fit.anchors, identities(ch.skeleton.size())), size_t(inside.rows()));
  const bake::PenetrationStats after = bake::measurePenetration(collider, pushed);
  EXPECT_EQ(after.inside, 0u);
  Points3f rest = ch.garment.positions;
  EXPECT_EQ(runtime::referencePushOut(rest, fit.anchors, identities(ch.skeleton.size())), 0u);
  EXPECT_EQ(rest, ch.garment.positions);
}

// The embedded default character: every jersey vertex anchored (the jersey sits within the bound), on
// the body's surface, normals out of the body, none inside at rest.
TEST(BodyAnchorFit, DefaultCharacter) {
  const Character ch = bake::makeDefaultCharacter();
  const bake::BodyAnchorFit fit = bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment);
  EXPECT_EQ(fit.anchored, ch.garment.vertexCount());
  EXPECT_EQ(fit.insideAtRest, 0u);
  EXPECT_LT(fit.maxMm, 40.f);
  bake::BodyCollider collider(ch.body, 0.05f);
  collider.pose(identities(ch.skeleton.size()));
  for (size_t v = 0; v < ch.garment.vertexCount(); v += 7) {
    const BodyAnchor& a = fit.anchors.anchors[v];
    const bake::BodyCollider::Hit on = collider.closest(a.position, 0.01f);
    ASSERT_TRUE(on.found) << v;
    EXPECT_NEAR(on.signedDistance, 0.f, 1e-4f) << v;
    const bake::BodyCollider::Hit out = collider.closest(a.position + 0.003f * a.normal, 0.01f);
    EXPECT_TRUE(!out.found || out.signedDistance > 0.f) << v << ": the normal points into the body";
    EXPECT_GE(a.radius, kMinAnchorRadius) << v;
    EXPECT_LE(a.radius, 0.3f) << v;
    // The ball lies inside the body: its centre is at least (nearly) its radius deep.
    const bake::BodyCollider::Hit centre = collider.closest(a.centre(), a.radius + 0.01f);
    ASSERT_TRUE(centre.found) << v;
    EXPECT_LE(centre.signedDistance, -a.radius + 0.0011f) << v;
  }
  Points3f rest = ch.garment.positions;
  EXPECT_EQ(runtime::referencePushOut(rest, fit.anchors, identities(ch.skeleton.size())), 0u);
}

// Calibration: each anchor keeps the highest clearance at which pushing the network's garment does not
// take that vertex further from the truth over the poses; an anchor whose ball the network and the
// truth both go nearly through to the centre is dropped.
TEST(BodyAnchorFit, CalibrationKeepsTheErrorAndPushesWhereItHelps) {
  const test::CapsuleSpec spec;
  const Character ch = test::capsuleCharacter(spec);
  bake::BodyAnchorFit fit = bake::fitBodyAnchors(ch.body, ch.skeleton, ch.garment);
  fit.anchors.anchors[2].radius = 0.01f;
  const auto& an = fit.anchors.anchors;
  // Distances off the ball (mm, along the normal through the anchor: as the plane's) of the network's vertex and of the
  // truth, per vertex and pose.
  struct Pair {
    float predicted, truth;
  };
  const Pair table[4][2] = {
      {{-10.f, 5.f}, {-10.f, 5.f}},          // the network deep, the truth outside: pushing helps, margin kept
      {{-10.5f, -10.5f}, {-10.5f, -10.5f}},  // the network on the truth: the first clearance below, -11 mm
      {{-9.7f, -9.7f}, {-9.7f, -9.7f}},      // near the centre of a 1 cm ball: no clearance above -1 cm qualifies
      {{-20.f, 1.f}, {-15.f, -15.f}},        // helps 21 mm in one pose, hurts 17 in the other: margin kept
  };
  std::vector<Points3f> truth(2, ch.garment.positions), predicted(2, ch.garment.positions);
  std::vector<bake::BodyAnchorCalibrationPose> poses(2);
  for (size_t p = 0; p < 2; ++p) {
    for (int v = 0; v < 4; ++v) {
      const BodyAnchor& a = an[size_t(v)];
      predicted[p].row(v) = (a.position + 0.001f * table[v][p].predicted * a.normal).transpose();
      truth[p].row(v) = (a.position + 0.001f * table[v][p].truth * a.normal).transpose();
    }
    poses[p] = {identities(ch.skeleton.size()), &truth[p], &predicted[p]};
  }
  BodyAnchors anchors = fit.anchors;
  const bake::BodyAnchorCalibration c = bake::calibrateBodyAnchors(anchors, poses);
  EXPECT_EQ(c.poses, 2u);
  EXPECT_EQ(anchors.anchors[0].clearance, fit.anchors.margin);
  EXPECT_NEAR(anchors.anchors[1].clearance, -0.011f, 1e-6f);
  EXPECT_FALSE(anchors.anchors[2].present());
  EXPECT_EQ(anchors.anchors[3].clearance, fit.anchors.margin);
  for (size_t v = 4; v < anchors.anchors.size(); ++v) EXPECT_EQ(anchors.anchors[v].clearance, fit.anchors.margin);
  EXPECT_EQ(c.lowered, 1u);
  EXPECT_EQ(c.dropped, 1u);
  EXPECT_LT(c.meanMmWith, c.meanMmWithout);
  // The calibrated push-out on those poses: each vertex's summed distance to the truth no larger.
  std::vector<double> before(4, 0.0), after(4, 0.0);
  for (size_t p = 0; p < 2; ++p) {
    Points3f x = predicted[p];
    runtime::referencePushOut(x, anchors, poses[p].skinMatrices);
    for (int v = 0; v < 4; ++v) {
      before[size_t(v)] += (predicted[p].row(v) - truth[p].row(v)).norm();
      after[size_t(v)] += (x.row(v) - truth[p].row(v)).norm();
    }
  }
  for (int v = 0; v < 4; ++v) EXPECT_LE(after[size_t(v)], before[size_t(v)] + 1e-6) << v;
  EXPECT_LT(after[0], before[0] - 0.02);

  // With a tolerance, an anchor keeps a clearance whose push adds at most that much mean distance per
  // pose: vertex 1's push to clearance c adds c + 10.5 mm in each pose, so 13 mm keeps the 2 mm margin
  // and 5 mm stops at -6 mm (4.5 mm added; -5 would add 5.5).
  for (const auto& [tolMm, expected] : {std::pair{13.f, fit.anchors.margin}, std::pair{5.f, -0.006f}}) {
    BodyAnchors tolerant = fit.anchors;
    bake::BodyAnchorCalibrationSettings ts;
    ts.tolerance = tolMm / 1000.f;
    bake::calibrateBodyAnchors(tolerant, poses, ts);
    EXPECT_NEAR(tolerant.anchors[1].clearance, expected, 1e-6f) << tolMm;
  }
  EXPECT_THROW(bake::calibrateBodyAnchors(anchors, poses, {0.001f, -1.f}), Error);
  EXPECT_THROW(bake::calibrateBodyAnchors(anchors, {{identities(4), &truth[0], nullptr}}), Error);
  const Points3f tooShort = ch.garment.positions.topRows(3);
  EXPECT_THROW(bake::calibrateBodyAnchors(anchors, {{identities(4), &tooShort, &tooShort}}), Error);
}

// The reference on hand-made anchors: a ball of 5 cm touching z = 0 from below at (0, 1, 0). A vertex
// inside lands on the sphere of radius + clearance along the radius, one outside stays, the ball rides
// its joints, and the push is continuous and never pulls a vertex in.
TEST(PushOutReference, KnownAnswersAndContinuity) {
  BodyAnchors anchors;
  BodyAnchor a;
  a.position = Vec3f(0, 1, 0);
  a.normal = Vec3f(0, 0, 1);
  a.radius = 0.05f;
  a.clearance = 0.002f;
  a.joints = {0, 1, 0, 0};
  a.weights = {0.5f, 0.5f, 0.f, 0.f};
  EXPECT_LT((a.centre() - Vec3f(0, 1, -0.05f)).norm(), 1e-7f);
  anchors.anchors = {a, a, BodyAnchor{}};
  anchors.anchors[1].clearance = -0.01f;  // calibrated: kept 1 cm inside the ball only
  Points3f p(3, 3);
  p.row(0) << 0.f, 1.f, -0.03f;   // 2 cm above the centre: to z = -0.05 + 0.052
  p.row(1) << 0.f, 1.f, -0.005f;  // 4.5 cm from the centre, but its reach is 4 cm: stays
  p.row(2) << 0.f, 1.f, -0.05f;   // no anchor: stays
  std::vector<Mat4f> mats = identities(2);
  Points3f q = p;
  EXPECT_EQ(runtime::referencePushOut(q, anchors, mats), 1u);
  EXPECT_NEAR(q(0, 2), 0.002f, 1e-7f);
  EXPECT_EQ(q(0, 0), p(0, 0));
  EXPECT_EQ(q(0, 1), p(0, 1));
  EXPECT_EQ(q.row(1), p.row(1));
  EXPECT_EQ(q.row(2), p.row(2));

  // Joint 1 moved 4 cm along +x: the blended centre (half of it) 2 cm; the vertex lands on the moved
  // sphere, on the ray from the centre through it.
  mats[1](0, 3) = 0.04f;
  const Vec3f c = runtime::skinAnchorCentre(a, mats);
  EXPECT_LT((c - Vec3f(0.02f, 1, -0.05f)).norm(), 1e-6f);
  q = p;
  runtime::referencePushOut(q, anchors, mats);
  const Vec3f moved = q.row(0).transpose(), before = p.row(0).transpose();
  EXPECT_NEAR((moved - c).norm(), a.reach(), 1e-6f);
  EXPECT_LT((moved - c).normalized().cross((before - c).normalized()).norm(), 1e-5f);
  // Joint 1 turned 90 degrees about x: the centre is the blend of (0, 1, -0.05) and its turn (0, 0.05, 1).
  mats[1] = Mat4f::Identity();
  mats[1].topLeftCorner<3, 3>() = Eigen::AngleAxisf(float(M_PI / 2), Vec3f::UnitX()).toRotationMatrix();
  EXPECT_LT((runtime::skinAnchorCentre(a, mats) - Vec3f(0, 0.525f, 0.475f)).norm(), 1e-6f);

  // Continuity along the radius: the output never moves backwards and never jumps.
  mats = identities(2);
  Points3f prev(1, 3);
  for (int s = 0; s <= 400; ++s) {
    Points3f x(1, 3);
    x << 0.f, 1.f, -0.04f + 0.00015f * float(s);
    Points3f y = x;
    runtime::referencePushOut(y, BodyAnchors{0.002f, {a}, {}, {}}, mats);
    EXPECT_GE(y(0, 2), x(0, 2) - 1e-7f);
    EXPECT_GE(y(0, 2), 0.002f - 1e-6f);
    if (s > 0) {
      EXPECT_LE(std::abs(y(0, 2) - prev(0, 2)), 0.00015f + 1e-6f) << s;
    }
    prev = y;
  }
  // On the centre there is no direction: the vertex stays.
  Points3f centre(1, 3);
  centre << 0.f, 1.f, -0.05f;
  EXPECT_EQ(runtime::referencePushOut(centre, BodyAnchors{0.002f, {a}, {}, {}}, mats), 0u);

  // Errors: anchors for another vertex count, a weighted joint without a matrix.
  Points3f two = p.topRows(2);
  EXPECT_THROW(runtime::referencePushOut(two, anchors, mats), Error);
  EXPECT_THROW(runtime::referencePushOut(q, anchors, identities(1)), Error);
  // A NaN matrix gives the anchor no centre: the vertex stays.
  std::vector<Mat4f> nan = identities(2);
  nan[1].setConstant(std::numeric_limits<float>::quiet_NaN());
  q = p;
  EXPECT_EQ(runtime::referencePushOut(q, anchors, nan), 0u);
  EXPECT_EQ(q, p);
  EXPECT_EQ(runtime::referencePushOut(q, BodyAnchors{}, mats), 0u);
}

}  // namespace
}  // namespace swish
