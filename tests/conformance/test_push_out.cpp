// Conformance of the push-out step of the deform kernel (shaders/deform.glsl: each vertex kept outside
// its body anchors' balls, Model::bodyAnchors, one set, two or three) to its CPU reference
// runtime::referencePushOut, on seeded random models with random anchors (seed printed;
// SWISH_TEST_SEED overrides): the kernel deforms, skins and then pushes, and must match
// referencePcaReconstruct -> referenceSkin -> referencePushOut. Outputs are followed by guard words;
// inputs are checked unchanged.
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <limits>

#include "support/gpu_buffers.hpp"
#include "support/gpu_compare.hpp"
#include "support/gpu_test.hpp"
#include "support/push_out_tolerance.hpp"
#include "support/random_model.hpp"
#include "support/seeded_test.hpp"
#include "swish/gpu/deform_pass.hpp"
#include "swish/runtime/reference_pca.hpp"
#include "swish/runtime/reference_push_out.hpp"
#include "swish/runtime/reference_skinning.hpp"

namespace swish {
namespace {

using test::CheckedInput;
using test::GuardedOutput;

struct PushCase {
  uint32_t vertices, influences, instances;
  uint32_t sets = 1;  // anchor sets: 1, 2 (BodyAnchors::second too) or 3 (and BodyAnchors::third)
  // Influences the anchors keep (the rest zeroed, the kept renormalised; the fit gives at most three).
  uint32_t anchorInfluences = 4;
  // Every anchor influence on one of the vertex's own skin joints, as most of a fitted model's are: the
  // push-out table then has no extra joints (DeformPass::anchorExtraJointsOf 0). Otherwise the random
  // anchors' later influences are on random joints, and the table has up to 3 per set.
  bool onSkinJoints = false;
};
void PrintTo(const PushCase& c, std::ostream* os) {
  *os << c.vertices << " vertices, " << c.influences << " influences, " << c.instances << " instances"
      << ", " << c.sets << " anchor set" << (c.sets > 1 ? "s" : "") << ", " << c.anchorInfluences
      << " anchor influences" << (c.onSkinJoints ? " on the skin's joints" : "");
}

struct PushInputs {
  Model model;
  std::vector<float> weights;   // instances x K
  std::vector<Mat4f> matrices;  // instances x joints
  uint32_t instances = 0;
};

PushInputs randomInputs(uint64_t seed, const PushCase& c) {
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.vertices = c.vertices;
  spec.influences = c.influences;
  spec.meshComponents = 5;
  spec.normalMaps = 0;
  spec.bodyAnchors = true;
  spec.secondAnchors = c.sets >= 2;
  spec.thirdAnchors = c.sets >= 3;
  PushInputs in;
  in.model = test::makeRandomModel(rng, spec);
  const SkinWeights& skin = in.model.gameMesh.skin;
  for (uint32_t s = 0; c.onSkinJoints && s < in.model.bodyAnchors.slots(); ++s)
    for (size_t v = 0; v < skin.vertexCount(); ++v)
      for (size_t i = 0; i < size_t(kAnchorInfluences); ++i)
        in.model.bodyAnchors.slot(s)[v].joints[i] =
            skin.joints[v * size_t(skin.influences) + (i + s) % size_t(skin.influences)];
  for (uint32_t s = 0; c.anchorInfluences < uint32_t(kAnchorInfluences) && s < in.model.bodyAnchors.slots(); ++s)
    for (BodyAnchor& a : in.model.bodyAnchors.slot(s)) {
      if (!a.present()) continue;
      for (uint32_t i = c.anchorInfluences; i < uint32_t(kAnchorInfluences); ++i) a.weights[i] = 0.f;
      float sum = 0.f;
      for (const float w : a.weights) sum += w;
      if (!(sum > 0.f)) a.weights[0] = sum = 1.f;
      for (float& w : a.weights) w /= sum;
    }
  in.instances = c.instances;
  for (uint32_t i = 0; i < c.instances * 5; ++i) in.weights.push_back(float(rng.normal(0, 2)));
  for (uint32_t i = 0; i < c.instances; ++i) {
    Pose pose = test::makeRandomPose(rng, in.model.skeleton, 0.15f);
    pose.rootTranslation = Vec3f(rng.uniformf(-2, 2), rng.uniformf(0, 1), rng.uniformf(-2, 2));
    const auto m = in.model.skeleton.skinningMatrices(pose);
    in.matrices.insert(in.matrices.end(), m.begin(), m.end());
  }
  return in;
}

// The reference positions, and per output element the tolerance of a device's rounding (see tolerance()).
struct Reference {
  std::vector<float> positions;
  std::vector<double> tolerance;
  size_t moved = 0;
};

// The tolerance of each pushed coordinate: support/push_out_tolerance.hpp derives it.
Reference reference(const PushInputs& in, bool pushOut) {
  const Model& m = in.model;
  const size_t k = size_t(m.meshComponents()), j = m.skeleton.size();
  Reference r;
  for (uint32_t i = 0; i < in.instances; ++i) {
    const std::span<const Mat4f> mats = std::span(in.matrices).subspan(i * j, j);
    Points3f p =
        runtime::referenceSkin(runtime::referencePcaReconstruct(m.meshPca, std::span(in.weights).subspan(i * k, k)),
                               m.gameMesh.skin, std::vector<Mat4f>(mats.begin(), mats.end()));
    const std::vector<double> tol = test::pushOutTolerance(m.bodyAnchors, pushOut ? m.bodyAnchors.slots() : 0, mats, p);
    r.tolerance.insert(r.tolerance.end(), tol.begin(), tol.end());
    if (pushOut) r.moved += runtime::referencePushOut(p, m.bodyAnchors, mats);
    r.positions.insert(r.positions.end(), p.data(), p.data() + p.size());
  }
  return r;
}

struct GpuResult {
  std::vector<float> positions;
  std::vector<std::string> problems;
};

// modelTexels: the kernel that reads the basis and the anchors as texels (deform_basis_texels.comp, as
// FrameRecorder runs it where the device allows), else the one reading them through their addresses
// (deform.comp).
GpuResult runDeform(gpu::Context& ctx, const PushInputs& in, bool pushOut, bool modelTexels = true) {
  const Model& m = in.model;
  const uint32_t n = uint32_t(m.gameMesh.vertexCount()), k = uint32_t(m.meshComponents());
  const std::vector<uint32_t> joints(m.gameMesh.skin.joints.begin(), m.gameMesh.skin.joints.end());
  CheckedInput mean(ctx, std::span<const float>(m.meshPca.mean.data(), 3 * n), "mean");
  CheckedInput basis(ctx, std::span<const float>(m.meshPca.basis.data(), size_t(m.meshPca.basis.size())), "basis");
  std::vector<float> weightRows(gpu::DeformPass::weightsBytes(in.instances, k) / sizeof(float));
  gpu::DeformPass::packWeights(in.weights.data(), in.instances, k, weightRows.data());
  CheckedInput weights(ctx, std::span<const float>(weightRows), "weights");
  std::vector<float> matrixRows(in.matrices.size() * 12);
  gpu::DeformPass::packSkinMatrices(in.matrices.data(), in.matrices.size(), matrixRows.data());
  CheckedInput matrices(ctx, std::span<const float>(matrixRows), "skin matrices");
  CheckedInput skinJoints(ctx, std::span<const uint32_t>(joints), "skin joints");
  CheckedInput skinWeights(ctx, std::span<const float>(m.gameMesh.skin.weights), "skin weights");
  const std::vector<uint32_t> anchorWords =
      gpu::DeformPass::packAnchors(m.bodyAnchors, m.gameMesh.skin, uint32_t(m.skeleton.size()));
  CheckedInput anchors(ctx, std::span<const uint32_t>(anchorWords), "body anchors");
  GuardedOutput out(ctx, size_t(in.instances) * n * 3 * sizeof(float), "deformed positions");

  const uint32_t extra = gpu::DeformPass::anchorExtraJointsOf(m.bodyAnchors, m.gameMesh.skin);
  const gpu::DeformPass pass(ctx, k, uint32_t(m.gameMesh.skin.influences), true,
                             modelTexels ? uint64_t(m.meshPca.basis.size()) : 0, m.bodyAnchors.slots(), extra,
                             gpu::DeformPass::anchorsSkipZeroWeights(extra, m.gameMesh.skin));
  EXPECT_EQ(pass.basisTexels(), modelTexels) << "this device cannot hold the test's basis and anchors as texels";
  gpu::DeformPass::Args a;
  a.mean = mean.address();
  a.basis = basis.address();
  const gpu::DescriptorBinding instanceInputs =
      pass.bindInstanceInputs(ctx, weights.buffer(), matrices.buffer(), &basis.buffer(), &anchors.buffer());
  a.instanceInputs = instanceInputs.get();
  a.skinJoints = skinJoints.address();
  a.skinWeights = skinWeights.address();
  a.positionsOut = out.address();
  a.vertexCount = n;
  a.instanceCount = in.instances;
  a.jointCount = uint32_t(m.skeleton.size());
  if (pushOut) a.anchors = anchors.address();
  a.anchorSlots = m.bodyAnchors.slots();
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, a); });

  GpuResult r;
  r.positions = out.read<float>(ctx);
  for (const CheckedInput* c : {&mean, &basis, &weights, &matrices, &skinJoints, &skinWeights, &anchors})
    if (auto s = c->unchanged(ctx); !s.empty()) r.problems.push_back(s);
  if (auto s = out.guardsIntact(ctx); !s.empty()) r.problems.push_back(s);
  return r;
}

std::string caseName(const ::testing::TestParamInfo<PushCase>& info) {
  const auto& c = info.param;
  return "V" + std::to_string(c.vertices) + "_I" + std::to_string(c.influences) + "_N" + std::to_string(c.instances) +
         (c.sets > 1 ? "_Sets" + std::to_string(c.sets) : "") +
         (c.anchorInfluences < 4 ? "_Anchor" + std::to_string(c.anchorInfluences) : "") +
         (c.onSkinJoints ? "_OnSkin" : "");
}

class PushOutConformance : public test::GpuTest, public ::testing::WithParamInterface<PushCase> {};

TEST_P(PushOutConformance, PushedPositionsMatchReference) {
  SWISH_TEST_SEED_SCOPE(seed, 0x9054 + GetParam().vertices + GetParam().influences);
  const PushInputs in = randomInputs(seed, GetParam());
  const Reference ref = reference(in, true);
  const Reference unpushed = reference(in, false);
  // Not vacuous: a fair share of the vertices must have been moved, and moved by more than rounding.
  const size_t total = size_t(in.instances) * in.model.gameMesh.vertexCount();
  double largest = 0;
  for (size_t e = 0; e < ref.positions.size(); ++e)
    largest = std::max(largest, double(std::abs(ref.positions[e] - unpushed.positions[e])));
  if (total >= 100) {  // the 1-vertex case may well stay on the outer side of its plane
    EXPECT_GE(ref.moved * 10, total) << ref.moved << " of " << total << " vertices pushed";
    EXPECT_LE(ref.moved * 10, total * 9) << ref.moved << " of " << total << " vertices pushed: some must stay";
    EXPECT_GT(largest, 1e-3) << "the pushes move vertices by millimetres at least";
  }

  // The push-out table: none beyond the skin's joints where the anchors are on them; else some (the
  // random anchors' later influences are on random joints), at most every influence of every set.
  const uint32_t extra = gpu::DeformPass::anchorExtraJointsOf(in.model.bodyAnchors, in.model.gameMesh.skin);
  if (GetParam().onSkinJoints) {
    EXPECT_EQ(extra, 0u);
  } else if (in.model.gameMesh.vertexCount() > 1 && GetParam().anchorInfluences > 1) {  // (the first is the skin's)
    EXPECT_GT(extra, 0u);
  }
  EXPECT_LE(extra, GetParam().sets * GetParam().anchorInfluences);
  // The random skin weights are all non-zero: the blends may add zero weights unguarded exactly where no
  // vertex needs an extra joint (deform.glsl), and a zero skin weight anywhere takes the guard back.
  const bool skip = gpu::DeformPass::anchorsSkipZeroWeights(extra, in.model.gameMesh.skin);
  EXPECT_EQ(skip, extra > 0);
  SkinWeights zeroed = in.model.gameMesh.skin;
  zeroed.weights.back() = 0.f;
  EXPECT_TRUE(gpu::DeformPass::anchorsSkipZeroWeights(extra, zeroed));
  std::printf("push-out table: %u joints beyond the skin's; zero weights %s\n", extra,
              skip ? "skipped" : "added unguarded");
  for (const bool texels : {true, false}) {
    SCOPED_TRACE(texels ? "basis and anchors as texels" : "basis and anchors through their addresses");
    const auto gpu = runDeform(ctx(), in, true, texels);
    for (const auto& p : gpu.problems) ADD_FAILURE() << p;
    test::CompareReport rep;
    EXPECT_TRUE(test::matchesReference(
        "pushed positions", gpu.positions, ref.positions, [&](size_t e) { return ref.tolerance[e]; }, &rep));
    std::printf(
        "%s: %zu of %zu vertices pushed (largest move %.3g m); max |gpu - reference| = %.3g m over %zu values\n",
        texels ? "texels" : "addresses", ref.moved, total, largest, rep.maxAbsError, rep.compared);
  }
}

// No anchor buffer (a frame with the push-out off) is the plain deform.
TEST_P(PushOutConformance, OffIsThePlainDeform) {
  SWISH_TEST_SEED_SCOPE(seed, 0x0FF + GetParam().vertices);
  const PushInputs in = randomInputs(seed, GetParam());
  const auto gpu = runDeform(ctx(), in, false);
  for (const auto& p : gpu.problems) ADD_FAILURE() << p;
  const Reference ref = reference(in, false);
  EXPECT_TRUE(test::matchesReference("unpushed positions", gpu.positions, ref.positions,
                                     [&](size_t e) { return ref.tolerance[e]; }));
}

// 1 vertex; a prime vertex count with the 22 instances of the default scene; 1 and 8 skin influences
// (the anchors have 4 whatever the garment has); one anchor set, two and three; anchors of 3, 2 and 1
// influences; anchors on the skin's own joints only (a push-out table without extra joints).
INSTANTIATE_TEST_SUITE_P(Sizes, PushOutConformance,
                         ::testing::Values(PushCase{1, 4, 1}, PushCase{97, 1, 3}, PushCase{997, 4, 22},
                                           PushCase{401, 8, 4}, PushCase{1, 4, 1, 2}, PushCase{97, 1, 3, 2},
                                           PushCase{997, 4, 22, 2}, PushCase{1, 4, 1, 3}, PushCase{97, 1, 3, 3},
                                           PushCase{997, 4, 22, 3}, PushCase{401, 8, 4, 3}, PushCase{997, 4, 22, 3, 3},
                                           PushCase{401, 8, 4, 3, 2}, PushCase{97, 1, 3, 2, 1},
                                           PushCase{997, 4, 22, 3, 3, true}, PushCase{97, 1, 3, 3, 4, true}),
                         caseName);

class PushOutSpecialCases : public test::GpuTest {};

// Hand-made anchors with known answers (identity skinning unless said): balls of 5 cm touching the
// plane z = 0 from below (centres at z = -0.05), clearance 2 mm: a vertex inside its ball lands on the
// sphere of 5.2 cm along the radius; one outside stays; one without an anchor stays; one whose anchor
// rides a translated joint follows the moved ball; one whose anchor's matrix is NaN stays (no centre),
// in the kernel as in the reference.
TEST_F(PushOutSpecialCases, KnownAnswers) {
  PushInputs in = randomInputs(3, {5, 4, 1});
  Model& m = in.model;
  m.meshPca.basis.setZero();
  m.meshPca.mean << 0.f, 1.f, -0.01f,  // 4 cm above its centre: to z = 2 mm
      0.1f, 1.f, 0.05f,                // 10 cm above: stays
      0.2f, 1.f, -0.05f,               // no anchor: stays
      0.3f, 1.f, 0.06f,                // anchor on joint 1, moved +10 cm in z (centre z = 0.05): to 0.102
      0.4f, 1.f, -0.05f;               // anchor on joint 2, whose matrix is NaN: stays
  for (size_t v = 0; v < 5; ++v)
    for (int i = 0; i < m.gameMesh.skin.influences; ++i) {
      m.gameMesh.skin.joints[v * size_t(m.gameMesh.skin.influences) + size_t(i)] = 0;
      m.gameMesh.skin.weights[v * size_t(m.gameMesh.skin.influences) + size_t(i)] = i == 0 ? 1.f : 0.f;
    }
  std::fill(in.matrices.begin(), in.matrices.end(), Mat4f::Identity());
  in.matrices[1](2, 3) = 0.1f;
  in.matrices[2].setConstant(std::numeric_limits<float>::quiet_NaN());
  auto anchor = [](float x, uint16_t joint) {
    BodyAnchor a;
    a.position = Vec3f(x, 1.f, 0.f);
    a.normal = Vec3f::UnitZ();
    a.radius = 0.05f;
    a.clearance = 0.002f;
    a.joints = {joint, 0, 0, 0};
    a.weights = {1.f, 0.f, 0.f, 0.f};
    return a;
  };
  m.bodyAnchors.margin = 0.002f;
  m.bodyAnchors.anchors = {anchor(0.f, 0), anchor(0.1f, 0), BodyAnchor{}, anchor(0.3f, 1), anchor(0.4f, 2)};
  const Reference ref = reference(in, true);
  const std::vector<float> expected = {0.f,    1.f,  0.002f, 0.1f,   1.f,  0.05f, 0.2f,  1.f,
                                       -0.05f, 0.3f, 1.f,    0.102f, 0.4f, 1.f,   -0.05f};
  // (0.05 + 0.052 and -0.05 + 0.052 round to within 1e-7 of the decimals above.)
  EXPECT_TRUE(
      test::matchesReference("reference on known answers", ref.positions, expected, [](size_t) { return 1e-6; }));
  EXPECT_EQ(ref.moved, 2u);
  // Both kernels (the anchors as texels and through their address) on every case.
  const auto kernelsMatch = [&](const char* what, const std::vector<float>& want) {
    for (const bool texels : {true, false}) {
      SCOPED_TRACE(texels ? "texels" : "addresses");
      const auto gpu = runDeform(ctx(), in, true, texels);
      for (const auto& p : gpu.problems) ADD_FAILURE() << p;
      EXPECT_TRUE(test::matchesReference(what, gpu.positions, want, [](size_t) { return 1e-6; }));
    }
  };
  kernelsMatch("kernel on known answers", expected);

  // A second anchor set, applied after the first: vertex 0's second ball (radius 4 cm, centre at z = 0.04,
  // reach 4.2 cm) holds where the first ball puts it (z = 0.002, 3.8 cm off its centre) but not where it
  // started (5 cm off), so the answer shows the order: pushed down to z = 0.04 - 0.042 = -0.002 (the
  // other order would leave it at 0.002). Vertex 1's second ball, on joint 1, moves it to 0.03 + 0.052.
  BodyAnchor second = anchor(0.f, 0);
  second.position = Vec3f(0.f, 1.f, 0.08f);
  second.radius = 0.04f;
  BodyAnchor riding = anchor(0.1f, 1);  // centre (0.1, 1, -0.07) at rest, 0.03 after the joint's move
  riding.position.z() = -0.02f;
  m.bodyAnchors.second = {second, riding, BodyAnchor{}, BodyAnchor{}, BodyAnchor{}};
  std::vector<float> expected2 = expected;
  expected2[2] = -0.002f;
  expected2[5] = 0.082f;
  const Reference ref2 = reference(in, true);
  EXPECT_TRUE(
      test::matchesReference("reference, two anchor sets", ref2.positions, expected2, [](size_t) { return 1e-6; }));
  EXPECT_EQ(ref2.moved, 3u);
  kernelsMatch("kernel, two anchor sets", expected2);

  // A third set, after the second: vertex 0's third ball (radius 3.1 cm, centre at z = -0.03, reach 3.3 cm)
  // takes it from the second's z = -0.002 (2.8 cm off its centre) up to -0.03 + 0.033 = 0.003. Applied
  // before the second it would be pushed down again to -0.002: the answer shows the order.
  BodyAnchor third = anchor(0.f, 0);
  third.position = Vec3f(0.f, 1.f, 0.001f);
  third.radius = 0.031f;
  m.bodyAnchors.third = {third, BodyAnchor{}, BodyAnchor{}, BodyAnchor{}, BodyAnchor{}};
  std::vector<float> expected3 = expected2;
  expected3[2] = 0.003f;
  const Reference ref3 = reference(in, true);
  EXPECT_TRUE(
      test::matchesReference("reference, three anchor sets", ref3.positions, expected3, [](size_t) { return 1e-6; }));
  EXPECT_EQ(ref3.moved, 3u);
  kernelsMatch("kernel, three anchor sets", expected3);
}

}  // namespace
}  // namespace swish
