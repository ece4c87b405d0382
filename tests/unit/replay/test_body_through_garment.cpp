// Body through the garment, measured on a picture (replay/body_through_garment.hpp): a capsule "torso" in
// a tube "shirt" seen from the front. Nothing shows at rest; cloth sunk into the body shows; skin that a
// slid garment uncovers, and a limb in front of the shirt, do not count.
#include <gtest/gtest.h>

#include "support/cloth_fixture.hpp"
#include "support/error_message.hpp"
#include "swish/render/preview_camera.hpp"
#include "swish/replay/body_through_garment.hpp"

using namespace swish;
using namespace swish::replay;

namespace {

constexpr uint32_t kWidth = 120, kHeight = 160;

api::Mat4 frontCamera() {
  render::PreviewCamera cam;
  cam.eye = {0.f, 0.35f, 2.f};
  cam.target = {0.f, 0.35f, 0.f};
  return render::viewProjection(cam, float(kWidth) / float(kHeight));
}

// The torso with a thin "forearm" held 8 cm in front of the shirt, across the chest.
Mesh torsoAndForearm(const test::CapsuleSpec& spec) {
  Mesh body = test::capsuleBody(spec);
  test::CapsuleSpec arm;
  arm.radius = 0.03f;
  arm.axisLow = 0.25f, arm.axisHigh = 0.45f;
  arm.around = 12, arm.rows = 6;
  arm.offset = Vec3f(0.f, 0.f, spec.radius + spec.gap + 0.08f + arm.radius);
  const Mesh forearm = test::capsuleBody(arm);
  const Eigen::Index n = body.positions.rows(), t = body.triangles.rows();
  body.positions.conservativeResize(n + forearm.positions.rows(), 3);
  body.positions.bottomRows(forearm.positions.rows()) = forearm.positions;
  body.triangles.conservativeResize(t + forearm.triangles.rows(), 3);
  body.triangles.bottomRows(forearm.triangles.rows()) = forearm.triangles.array() + uint32_t(n);
  return body;
}

}  // namespace

TEST(BodyThroughGarment, NothingAtRestClothSunkIntoTheBodyShowsSlidClothDoesNot) {
  const test::CapsuleSpec spec;
  const Mesh body = torsoAndForearm(spec);
  const Mesh shirt = test::tubeGarment(spec);
  const BodyThroughGarmentMeter meter(body.positions, body.triangles, shirt.positions, shirt.triangles);
  // The torso's middle is covered; its caps (beyond the tube), the forearm and the skin within 3 cm of
  // the tube's open ends are not.
  EXPECT_GT(meter.coveredTriangles(), 200u);
  EXPECT_LT(meter.coveredTriangles(), size_t(body.triangles.rows()) / 2);
  for (Eigen::Index t = test::capsuleBody(spec).triangles.rows(); t < body.triangles.rows(); ++t)
    EXPECT_FALSE(meter.covered()[size_t(t)]) << "forearm triangle " << t;

  const api::Mat4 vp = frontCamera();
  const BodyThroughGarment rest = meter.measure(body.positions, shirt.positions, vp, kWidth, kHeight);
  EXPECT_EQ(rest.pixels, 0u);  // the forearm in front of the shirt is drawn, and is not skin under it
  EXPECT_GT(rest.garmentPixels, 1000u);

  // A band of the shirt (y 0.3-0.4) sunk 2 cm into the torso: the torso is drawn there.
  Points3f sunk = shirt.positions;
  for (Eigen::Index v = 0; v < sunk.rows(); ++v)
    if (sunk(v, 1) > 0.3f && sunk(v, 1) < 0.4f) {
      const Vec2f xz(sunk(v, 0), sunk(v, 2));
      const Vec2f in = xz.normalized() * (spec.radius - 0.02f);
      sunk(v, 0) = in.x(), sunk(v, 2) = in.y();
    }
  const BodyThroughGarment through = meter.measure(body.positions, sunk, vp, kWidth, kHeight);
  EXPECT_GT(through.pixels, 100u);
  EXPECT_GT(through.share(), 0.02);
  EXPECT_LT(through.pixels, rest.garmentPixels / 4);  // a band, not the whole shirt

  // The whole shirt slid 30 cm down: the chest is bare, but nothing went through the cloth.
  Points3f slid = shirt.positions;
  slid.col(1).array() -= 0.3f;
  EXPECT_EQ(meter.measure(body.positions, slid, vp, kWidth, kHeight).pixels, 0u);

  // Deterministic.
  EXPECT_EQ(meter.measure(body.positions, sunk, vp, kWidth, kHeight).pixels, through.pixels);
}

// The default jersey's rest game mesh already cuts a few millimetres under the shoulder tops (its long
// triangles there are chords of the rounded shoulder). That skin is under the garment all the same, and
// when it shows the measure counts it: a shirt whose band is sunk 5 mm under the skin at rest.
TEST(BodyThroughGarment, SkinTheRestGarmentCutsUnderIsCoveredAndCounts) {
  const test::CapsuleSpec spec;
  const Mesh body = test::capsuleBody(spec);
  Mesh shirt = test::tubeGarment(spec);
  auto sinkBand = [&](Points3f p, float depth) {
    for (Eigen::Index v = 0; v < p.rows(); ++v)
      if (p(v, 1) > 0.3f && p(v, 1) < 0.4f) {
        const Vec2f in = Vec2f(p(v, 0), p(v, 2)).normalized() * (spec.radius - depth);
        p(v, 0) = in.x(), p(v, 2) = in.y();
      }
    return p;
  };
  const BodyThroughGarmentMeter plain(body.positions, body.triangles, shirt.positions, shirt.triangles);
  shirt.positions = sinkBand(shirt.positions, 0.005f);
  const BodyThroughGarmentMeter sunkAtRest(body.positions, body.triangles, shirt.positions, shirt.triangles);
  // The band's skin is covered as where the shirt lies outside the body.
  EXPECT_EQ(sunkAtRest.coveredTriangles(), plain.coveredTriangles());
  const BodyThroughGarment shows = sunkAtRest.measure(body.positions, shirt.positions, frontCamera(), kWidth, kHeight);
  EXPECT_GT(shows.pixels, 100u);
  // Cloth 2 cm under the skin at rest is not taken for covering (a limb under a hem, say): beyond 1.5 cm.
  const Points3f deep = sinkBand(test::tubeGarment(spec).positions, 0.02f);
  const BodyThroughGarmentMeter deepAtRest(body.positions, body.triangles, deep, shirt.triangles);
  EXPECT_LT(deepAtRest.coveredTriangles(), plain.coveredTriangles());
}

TEST(BodyThroughGarment, BadInputIsAClearError) {
  const test::CapsuleSpec spec;
  const Mesh body = test::capsuleBody(spec), shirt = test::tubeGarment(spec);
  EXPECT_NE(test::errorOf([&] {
              BodyThroughGarmentMeter(body.positions, body.triangles, shirt.positions, shirt.triangles, 0.f);
            }).find("reach must be a positive"),
            std::string::npos);
  const BodyThroughGarmentMeter meter(body.positions, body.triangles, shirt.positions, shirt.triangles);
  const Points3f fewer = shirt.positions.topRows(10);
  EXPECT_NE(test::errorOf([&] {
              meter.measure(body.positions, fewer, frontCamera(), kWidth, kHeight);
            }).find("the posed body has"),
            std::string::npos);
  api::Mat4 zero{};
  EXPECT_NE(test::errorOf([&] {
              meter.measure(body.positions, shirt.positions, zero, kWidth, kHeight);
            }).find("not invertible"),
            std::string::npos);
  Points3f nan = shirt.positions;
  nan(3, 1) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(meter.measure(body.positions, nan, frontCamera(), kWidth, kHeight), Error);
}
