// The headless preview renderer on a host-made device (lavapipe here), validation layers on:
//  - known frames render, with the jersey and the mannequin where they should be;
//  - the jersey's silhouette equals the projection of the CPU-reference mesh (IoU >= 0.97);
//  - switching the normal map off changes the shading inside the jersey only.
//
// Why IoU >= 0.97: both masks rasterise the same triangles with the same projection and no MSAA; the
// GPU vertices match the CPU reference to ~1e-5 relative (the deform conformance tolerance), far below
// a pixel, so only pixels whose centres fall within rounding of a silhouette edge can disagree
// (Vulkan's top-left tie rule vs. the inclusive edge test here). For this jersey the silhouette
// covers ~10^4 pixels with a perimeter of ~10^3, so even one disagreement in ten edge pixels keeps IoU
// above 0.99; 0.97 leaves margin for drivers, while a misplaced, mis-skinned or mis-projected jersey
// (a shift of two pixels already costs ~0.1) fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <vector>

#include "support/api_host_fixture.hpp"
#include "support/temp_dir.hpp"
#include "swish/core/rng.hpp"
#include "swish/io/png.hpp"
#include "swish/render/body_from_character.hpp"
#include "swish/render/contact_sheet.hpp"
#include "swish/render/preview_renderer.hpp"
#include "swish/runtime/frame_evaluator.hpp"
#include "swish/runtime/reference_frame.hpp"

namespace swish {
namespace {

// A pose of the model's skeleton: spine and arm joints turned by the given angles (radians).
Pose bentPose(const Skeleton& sk, float spine, float arms) {
  Pose p = sk.restPose();
  auto turn = [&](const char* name, const Vec3f& axis, float angle) {
    const int j = sk.find(name);
    if (j >= 0) p.local[j] = (Quatf(Eigen::AngleAxisf(angle, axis.normalized())) * p.local[j]).normalized();
  };
  turn("LowerBack", Vec3f(1, 0, 0.3f), spine);
  turn("Spine1", Vec3f(0.2f, 1, 0), spine * 0.8f);
  turn("LeftArm", Vec3f(0, 0, 1), arms);
  turn("RightArm", Vec3f(0, 0, 1), -arms);
  return p;
}

struct ApiPose {
  std::vector<api::Quat> rotations;
  api::CharacterPose pose;
};
ApiPose toApi(const Pose& p) {
  ApiPose a;
  for (const Quatf& q : p.local) a.rotations.push_back({q.x(), q.y(), q.z(), q.w()});
  a.pose.localRotations = a.rotations;
  a.pose.rootTranslation = std::array<float, 3>{p.rootTranslation.x(), p.rootTranslation.y(), p.rootTranslation.z()};
  a.pose.dtSeconds = 1.f / 30.f;
  return a;
}

// Inclusive point-in-triangle test at pixel centres: the CPU rasterisation of a mesh's silhouette.
std::vector<uint8_t> rasterMask(const Points3f& positions, const Triangles& tris, const api::Mat4& vp, uint32_t w,
                                uint32_t h) {
  std::vector<uint8_t> mask(size_t(w) * h, 0);
  std::vector<std::array<float, 3>> px(size_t(positions.rows()));
  for (Eigen::Index v = 0; v < positions.rows(); ++v)
    px[v] = render::projectToPixel(vp, {positions(v, 0), positions(v, 1), positions(v, 2)}, w, h);
  for (Eigen::Index t = 0; t < tris.rows(); ++t) {
    const auto &a = px[tris(t, 0)], &b = px[tris(t, 1)], &c = px[tris(t, 2)];
    if (a[2] <= 0 || b[2] <= 0 || c[2] <= 0) continue;
    const float area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (area == 0) continue;
    const int x0 = std::max(0, int(std::floor(std::min({a[0], b[0], c[0]})))),
              x1 = std::min(int(w) - 1, int(std::ceil(std::max({a[0], b[0], c[0]}))));
    const int y0 = std::max(0, int(std::floor(std::min({a[1], b[1], c[1]})))),
              y1 = std::min(int(h) - 1, int(std::ceil(std::max({a[1], b[1], c[1]}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const float X = x + 0.5f, Y = y + 0.5f;
        const float e0 = ((b[0] - a[0]) * (Y - a[1]) - (b[1] - a[1]) * (X - a[0])) / area;
        const float e1 = ((c[0] - b[0]) * (Y - b[1]) - (c[1] - b[1]) * (X - b[0])) / area;
        const float e2 = ((a[0] - c[0]) * (Y - c[1]) - (a[1] - c[1]) * (X - c[0])) / area;
        if (e0 >= 0 && e1 >= 0 && e2 >= 0) mask[size_t(y) * w + x] = 1;
      }
  }
  return mask;
}

// Pixel (x, y) of panel `panel` of a side-by-side image.
const uint8_t* pixel(const render::PreviewImage& img, uint32_t panelWidth, uint32_t panel, uint32_t x, uint32_t y) {
  return &img.rgba[(size_t(y) * img.width + panel * panelWidth + x) * 4];
}

class PreviewRender : public ::testing::Test {
 protected:
  void SetUp() override {
    device_ = test::makeHostDeviceOrSkip();
    if (!device_) {
      if (!HasFailure()) GTEST_SKIP() << "no usable Vulkan device";
      return;
    }
    model_ = test::standInJersey();
    runtime_.emplace(api::Runtime::adopt(device_->handles()));
    apiModel_.emplace(runtime_->loadModelFromMemory(serializeModel(model_), "stand-in jersey"));
  }
  void TearDown() override {
    if (device_) test::expectNoValidationMessages(*device_);
  }
  std::unique_ptr<render::HostDevice> device_;
  Model model_;
  std::optional<api::Runtime> runtime_;
  std::optional<api::Model> apiModel_;
};

TEST_F(PreviewRender, KnownFramesDrawTheJerseyOnTheMannequin) {
  render::PreviewOptions o;
  o.width = 160;
  o.height = 200;
  std::string why;
  o.body = render::bodyFromCharacter(test::defaultCharacter(), apiModel_->info(), why);
  ASSERT_TRUE(o.body.has_value()) << why;
  render::PreviewRenderer preview(*device_, *runtime_, *apiModel_, o);
  ASSERT_TRUE(preview.drawsBody());
  std::vector<render::PreviewImage> frames;
  for (int f = 0; f < 3; ++f) {
    const ApiPose p = toApi(bentPose(model_.skeleton, 0.15f * f, 0.3f * f));
    frames.push_back(preview.render(p.pose, {{true, true}, {true, false}}));
    const render::PreviewImage& img = frames.back();
    ASSERT_EQ(img.width, 2 * o.width);
    size_t withBody = 0, jerseyOnly = 0;
    for (uint32_t y = 0; y < o.height; ++y)
      for (uint32_t x = 0; x < o.width; ++x) {
        withBody += pixel(img, o.width, 0, x, y)[3] > 0;
        jerseyOnly += pixel(img, o.width, 1, x, y)[3] > 0;
      }
    // The camera frames the whole mannequin: it covers a good part of the view, but not all of it,
    // and the jersey is a clear part of it.
    const double total = double(o.width) * o.height;
    EXPECT_GT(withBody / total, 0.10) << "frame " << f;
    EXPECT_LT(withBody / total, 0.80) << "frame " << f;
    EXPECT_GT(jerseyOnly, withBody / 10) << "frame " << f;
    EXPECT_LT(jerseyOnly, withBody) << "frame " << f;
    // Where the jersey's centroid projects, the image shows the jersey: red-dominant.
    const api::DeformedMesh jersey = preview.lastJersey();
    render::Vec3 centroid{0, 0, 0};
    for (size_t v = 0; v < jersey.positions.size(); ++v)
      centroid[v % 3] += jersey.positions[v] / float(jersey.positions.size() / 3);
    const auto at = render::projectToPixel(preview.viewProjection(), centroid, o.width, o.height);
    ASSERT_TRUE(at[0] >= 0 && at[0] < o.width && at[1] >= 0 && at[1] < o.height);
    const uint8_t* c = pixel(img, o.width, 0, uint32_t(at[0]), uint32_t(at[1]));
    EXPECT_GT(c[3], 0);
    EXPECT_GT(int(c[0]), int(c[1]) + 30) << "jersey colour expected at the torso";
    EXPECT_TRUE(preview.lastReport().warnings.empty());
  }
  // A contact sheet of the three frames: 3 thumbnails side by side, written atomically as PNG.
  const auto sheet = render::makeContactSheet(frames, {3, 80, 4});
  EXPECT_EQ(sheet.width, 3 * 80 + 4 * 4);
  const test::TempDir tmp("test_contact_sheet");
  const auto path = tmp / "contact_sheet.png";
  render::writeContactSheet(frames, path, {3, 80, 4});
  const io::PngImage back = io::readPng(path);
  EXPECT_EQ(back.width, sheet.width);
  EXPECT_EQ(back.height, sheet.height);
}

TEST_F(PreviewRender, JerseySilhouetteMatchesTheCpuReferenceProjection) {
  render::PreviewOptions o;
  o.width = 192;
  o.height = 192;
  render::PreviewRenderer preview(*device_, *runtime_, *apiModel_, o);  // no body: the jersey alone
  EXPECT_FALSE(preview.drawsBody());
  const Pose pose = bentPose(model_.skeleton, 0.3f, 0.5f);
  const ApiPose p = toApi(pose);
  const auto img = preview.render(p.pose, {{true, false}});

  // The CPU reference of the same frame: network -> weights, skinning matrices of the pose.
  runtime::FrameEvaluator evaluator(model_, 1);
  const auto& out = evaluator.evaluate(std::span<const Pose>(&pose, 1), 1.f / 30.f);
  runtime::FrameKernelInputs in;
  in.instanceCount = 1;
  in.meshWeights = out.meshWeights;
  in.skinMatrices = model_.skeleton.skinningMatrices(pose);
  const auto ref = runtime::referenceFrame(model_, in);
  const auto cpuMask =
      rasterMask(ref.positions[0], model_.gameMesh.triangles, preview.viewProjection(), o.width, o.height);

  size_t inter = 0, uni = 0, gpuCount = 0;
  for (uint32_t y = 0; y < o.height; ++y)
    for (uint32_t x = 0; x < o.width; ++x) {
      const bool g = img.alpha(x, y) > 0, c = cpuMask[size_t(y) * o.width + x] != 0;
      inter += g && c;
      uni += g || c;
      gpuCount += g;
    }
  ASSERT_GT(gpuCount, size_t(o.width) * o.height / 20) << "the jersey should fill a good part of the frame";
  const double iou = double(inter) / double(uni);
  std::printf("jersey silhouette: %zu GPU pixels, IoU with the CPU reference %.4f\n", gpuCount, iou);
  EXPECT_GE(iou, 0.97);
}

TEST_F(PreviewRender, NormalMapOffChangesShadingInsideTheJerseyOnly) {
  ASSERT_TRUE(apiModel_->info().hasNormalMaps);
  render::PreviewOptions o;
  o.width = 160;
  o.height = 200;
  std::string why;
  o.body = render::bodyFromCharacter(test::defaultCharacter(), apiModel_->info(), why);
  ASSERT_TRUE(o.body.has_value()) << why;
  render::PreviewRenderer preview(*device_, *runtime_, *apiModel_, o);
  const ApiPose p = toApi(bentPose(model_.skeleton, 0.2f, 0.4f));
  // Panels: map on + body, map off + body, jersey alone (its mask), all of one swish frame.
  const auto img = preview.render(p.pose, {{true, true}, {false, true}, {true, false}});
  size_t jersey = 0, changedInside = 0, changedOutside = 0;
  for (uint32_t y = 0; y < o.height; ++y)
    for (uint32_t x = 0; x < o.width; ++x) {
      const uint8_t* on = pixel(img, o.width, 0, x, y);
      const uint8_t* off = pixel(img, o.width, 1, x, y);
      const bool inJersey = pixel(img, o.width, 2, x, y)[3] > 0;
      const bool changed =
          std::abs(on[0] - off[0]) + std::abs(on[1] - off[1]) + std::abs(on[2] - off[2]) > 0 || on[3] != off[3];
      // Outside the jersey only the body and the background are drawn, by the same draws in both panels,
      // but at another viewport offset (the panels sit side by side): Vulkan does not make attribute
      // interpolation invariant under a viewport translation, and an NVIDIA H100 shaded one body pixel
      // (of 32000) 1 step darker in one panel. One step per channel is that rounding; the normal map's
      // own effect is far larger.
      const bool changedBeyondRounding = std::abs(on[0] - off[0]) > 1 || std::abs(on[1] - off[1]) > 1 ||
                                         std::abs(on[2] - off[2]) > 1 || on[3] != off[3];
      jersey += inJersey;
      (inJersey ? changedInside : changedOutside) += inJersey ? changed : changedBeyondRounding;
      if (changed && !inJersey)
        std::printf("changed outside the jersey at (%u, %u): map on %d %d %d %d, off %d %d %d %d\n", x, y, on[0], on[1],
                    on[2], on[3], off[0], off[1], off[2], off[3]);
    }
  std::printf("jersey pixels %zu, changed by the normal map: %zu inside, %zu outside\n", jersey, changedInside,
              changedOutside);
  EXPECT_EQ(changedOutside, 0u) << "the normal map must not change anything outside the jersey";
  // The stand-in's wrinkle maps tilt normals over most of the garment: most visible jersey pixels
  // shade differently (a map that failed to bind, or was all zeros, would change none).
  EXPECT_GT(double(changedInside), 0.3 * double(jersey));
}

TEST_F(PreviewRender, BadBodyIsRejectedWithAReason) {
  render::PreviewOptions o;
  render::BodyMesh body;
  body.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  body.triangles = {0, 1, 5};
  body.influences = 1;
  body.joints = {0, 0, 0};
  body.weights = {1, 1, 1};
  o.body = body;
  try {
    render::PreviewRenderer preview(*device_, *runtime_, *apiModel_, o);
    FAIL() << "expected an error";
  } catch (const api::Error& e) {
    EXPECT_EQ(e.code(), api::ErrorCode::InvalidArgument);
    EXPECT_NE(std::string(e.what()).find("triangle index 5"), std::string::npos) << e.what();
  }
}

// The model's covered-triangle list leaves those triangles out of the body the preview draws, keeps the
// others in order, and is refused for another body (a different triangle count).
TEST(PreviewBody, HidesTheModelsCoveredTriangles) {
  render::BodyMesh body;
  body.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  body.triangles = {0, 1, 2, 1, 3, 2, 0, 2, 3, 0, 1, 3};
  api::ModelInfo info;
  EXPECT_EQ(body.hideCovered(info), 0u);  // no list: nothing hidden
  EXPECT_EQ(body.triangles.size(), 12u);
  info.coveredBodyOf = 4;
  info.coveredBodyTriangles = {1, 3};
  render::BodyMesh other = body;
  EXPECT_EQ(body.hideCovered(info), 2u);
  EXPECT_EQ(body.triangles, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  info.coveredBodyOf = 5;
  try {
    other.hideCovered(info);
    FAIL() << "a list for another body was accepted";
  } catch (const api::Error& e) {
    EXPECT_NE(std::string(e.what()).find("for a body of 5 triangles, this one has 4"), std::string::npos) << e.what();
  }
  info.coveredBodyOf = 4;
  info.coveredBodyTriangles = {0, 1, 2, 3};
  EXPECT_THROW(other.hideCovered(info), api::Error);  // nothing left to draw
}

}  // namespace
}  // namespace swish
