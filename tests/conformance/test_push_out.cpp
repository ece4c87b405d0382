// Conformance of the push-out step of the deform kernel (shaders/deform.glsl, the body-proxy capsules
// of Model::bodyProxy) to its CPU reference runtime::referencePushOut, on seeded random models with
// random capsules over the mesh (seed printed; SWISH_TEST_SEED overrides): the kernel deforms,
// skins and then pushes, and must match referencePcaReconstruct -> referenceSkin -> poseBodyProxy ->
// referencePushOut. Outputs are followed by guard words; inputs are checked unchanged.
#include <cfloat>
#include <cmath>
#include <cstdio>

#include "support/gpu_buffers.hpp"
#include "support/gpu_compare.hpp"
#include "support/gpu_test.hpp"
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
  uint32_t vertices, capsules, instances;
};
void PrintTo(const PushCase& c, std::ostream* os) {
  *os << c.vertices << " vertices, " << c.capsules << " capsules, " << c.instances << " instances";
}

struct PushInputs {
  Model model;
  std::vector<float> weights;   // instances x K
  std::vector<Mat4f> matrices;  // instances x joints
  std::vector<float> posed;     // instances x capsules x 8
  uint32_t instances = 0;
};

PushInputs randomInputs(uint64_t seed, const PushCase& c) {
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.vertices = c.vertices;
  spec.meshComponents = 5;
  spec.normalMaps = 0;
  spec.bodyCapsules = c.capsules;
  PushInputs in;
  in.model = test::makeRandomModel(rng, spec);
  in.instances = c.instances;
  for (uint32_t i = 0; i < c.instances * 5; ++i) in.weights.push_back(float(rng.normal(0, 2)));
  const size_t j = in.model.skeleton.size();
  for (uint32_t i = 0; i < c.instances; ++i) {
    // Small rotations keep the posed capsules over the skinned mesh, so that many vertices are pushed.
    Pose pose = test::makeRandomPose(rng, in.model.skeleton, 0.15f);
    pose.rootTranslation = Vec3f(rng.uniformf(-2, 2), rng.uniformf(0, 1), rng.uniformf(-2, 2));
    const auto m = in.model.skeleton.skinningMatrices(pose);
    in.matrices.insert(in.matrices.end(), m.begin(), m.end());
    runtime::poseBodyProxy(in.model.bodyProxy, std::span(in.matrices).subspan(i * j, j), in.posed);
  }
  return in;
}

// The reference, and per output element how much a device's rounding of the skinned position can be
// amplified by the pushes it goes through: a push projects the vertex radially onto the capsule, which
// scales the tangential part of an input error by r / |e| (>= 1 inside), and keeps it otherwise.
struct Reference {
  std::vector<float> positions;
  std::vector<double> amplification;
  size_t moved = 0;
};

Reference reference(const PushInputs& in, bool pushOut) {
  const Model& m = in.model;
  const size_t k = size_t(m.meshComponents()), j = m.skeleton.size(), c = m.bodyProxy.capsules.size();
  Reference r;
  for (uint32_t i = 0; i < in.instances; ++i) {
    Points3f p = runtime::referenceSkin(
        runtime::referencePcaReconstruct(m.meshPca, std::span(in.weights).subspan(i * k, k)), m.gameMesh.skin,
        std::vector<Mat4f>(in.matrices.begin() + i * j, in.matrices.begin() + (i + 1) * j));
    const std::span<const float> posed = std::span(in.posed).subspan(i * c * 8, c * 8);
    for (Eigen::Index v = 0; v < p.rows(); ++v) {
      double amp = 1;
      Points3f one = p.row(v);
      for (size_t q = 0; pushOut && q < c; ++q) {
        const float* cap = posed.data() + q * 8;
        const Vec3f a(cap[0], cap[1], cap[2]), d(cap[4], cap[5], cap[6]);
        const Vec3f x = one.row(0).transpose();
        const float t = std::clamp((x - a).dot(d) * cap[7], 0.f, 1.f);
        const double dist = (x - (a + d * t)).norm();
        if (dist < cap[3] && dist > 0) amp *= double(cap[3]) / dist;
        runtime::referencePushOut(one, posed.subspan(q * 8, 8));  // one capsule at a time, as the kernel
      }
      for (int a = 0; a < 3; ++a) r.amplification.push_back(amp);
    }
    if (pushOut) r.moved += runtime::referencePushOut(p, posed);
    r.positions.insert(r.positions.end(), p.data(), p.data() + p.size());
  }
  return r;
}

struct GpuResult {
  std::vector<float> positions;
  std::vector<std::string> problems;
};

GpuResult runDeform(gpu::Context& ctx, const PushInputs& in, bool pushOut) {
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
  CheckedInput capsules(ctx, std::span<const float>(in.posed), "posed capsules");
  GuardedOutput out(ctx, size_t(in.instances) * n * 3 * sizeof(float), "deformed positions");

  const gpu::DeformPass pass(ctx, k, uint32_t(m.gameMesh.skin.influences), true, uint64_t(m.meshPca.basis.size()));
  gpu::DeformPass::Args a;
  a.mean = mean.address();
  a.basis = basis.address();
  const gpu::DescriptorBinding instanceInputs =
      pass.bindInstanceInputs(ctx, weights.buffer(), matrices.buffer(), &basis.buffer());
  a.instanceInputs = instanceInputs.get();
  a.skinJoints = skinJoints.address();
  a.skinWeights = skinWeights.address();
  a.positionsOut = out.address();
  a.vertexCount = n;
  a.instanceCount = in.instances;
  a.jointCount = uint32_t(m.skeleton.size());
  if (pushOut) {
    a.capsules = capsules.address();
    a.capsuleCount = uint32_t(m.bodyProxy.capsules.size());
  }
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, a); });

  GpuResult r;
  r.positions = out.read<float>(ctx);
  for (const CheckedInput* c : {&mean, &basis, &weights, &matrices, &skinJoints, &skinWeights, &capsules})
    if (auto s = c->unchanged(ctx); !s.empty()) r.problems.push_back(s);
  if (auto s = out.guardsIntact(ctx); !s.empty()) r.problems.push_back(s);
  return r;
}

// Tolerance: the skinned position's own (test_deform.cpp: 2 um + 1e-5 relative, FMA-contracting
// devices included) times the amplification of the pushes it went through (see Reference), plus the
// push's own roundings: a dozen float operations on coordinates of a few metres and a sqrt that Vulkan
// lets a device compute to a few ulps: 1e-5 relative to the coordinate again.
double tolerance(const Reference& r, size_t e) {
  const double x = std::abs(double(r.positions[e]));
  return (2e-6 + 1e-5 * x) * r.amplification[e] + 1e-5 * x;
}

std::string caseName(const ::testing::TestParamInfo<PushCase>& info) {
  const auto& c = info.param;
  return "V" + std::to_string(c.vertices) + "_C" + std::to_string(c.capsules) + "_I" + std::to_string(c.instances);
}

class PushOutConformance : public test::GpuTest, public ::testing::WithParamInterface<PushCase> {};

TEST_P(PushOutConformance, PushedPositionsMatchReference) {
  SWISH_TEST_SEED_SCOPE(seed, 0x9054 + GetParam().vertices + GetParam().capsules);
  const PushInputs in = randomInputs(seed, GetParam());
  const Reference ref = reference(in, true);
  const Reference unpushed = reference(in, false);
  // Not vacuous: a fair share of the vertices must have been moved, and moved by more than rounding.
  const size_t total = size_t(in.instances) * in.model.gameMesh.vertexCount();
  double largest = 0;
  for (size_t e = 0; e < ref.positions.size(); ++e)
    largest = std::max(largest, double(std::abs(ref.positions[e] - unpushed.positions[e])));
  if (total >= 100) {  // the 1-vertex case may well miss its one capsule
    EXPECT_GE(ref.moved * 20, total) << ref.moved << " of " << total << " vertices pushed";
    EXPECT_GT(largest, 1e-3) << "the pushes move vertices by millimetres at least";
  }

  const auto gpu = runDeform(ctx(), in, true);
  for (const auto& p : gpu.problems) ADD_FAILURE() << p;
  test::CompareReport rep;
  EXPECT_TRUE(test::matchesReference(
      "pushed positions", gpu.positions, ref.positions, [&](size_t e) { return tolerance(ref, e); }, &rep));
  std::printf("%zu of %zu vertices pushed (largest move %.3g m); max |gpu - reference| = %.3g m over %zu values\n",
              ref.moved, total, largest, rep.maxAbsError, rep.compared);
}

// capsuleCount 0 (a frame with the push-out off) is the plain deform, bit for bit the same as the
// kernel's output without a capsule buffer bound.
TEST_P(PushOutConformance, OffIsThePlainDeform) {
  SWISH_TEST_SEED_SCOPE(seed, 0x0FF + GetParam().vertices);
  const PushInputs in = randomInputs(seed, GetParam());
  const auto gpu = runDeform(ctx(), in, false);
  for (const auto& p : gpu.problems) ADD_FAILURE() << p;
  const Reference ref = reference(in, false);
  EXPECT_TRUE(test::matchesReference("unpushed positions", gpu.positions, ref.positions,
                                     [&](size_t e) { return 2e-6 + 1e-5 * std::abs(double(ref.positions[e])); }));
}

// 1 vertex and 1 capsule; a prime vertex count with the 22 instances of the default scene; the most
// capsules a model may hold.
INSTANTIATE_TEST_SUITE_P(Sizes, PushOutConformance,
                         ::testing::Values(PushCase{1, 1, 1}, PushCase{97, 7, 3}, PushCase{997, 24, 22},
                                           PushCase{401, uint32_t(kMaxBodyCapsules), 4}),
                         caseName);

class PushOutSpecialCases : public test::GpuTest {};

// Hand-made capsules with known answers: a vertex inside a capsule lands on its surface along the
// perpendicular from the axis, one beyond an end lands on the end's sphere, one outside stays, and one
// exactly on the axis stays (it has no outward direction).
TEST_F(PushOutSpecialCases, KnownAnswers) {
  PushInputs in = randomInputs(3, {4, 1, 1});
  Model& m = in.model;
  m.meshPca.basis.setZero();
  m.meshPca.mean << 0.01f, 1.f, 0.f,  // inside, 1 cm from the axis (y = 1, z = 0 ... x from 0 to 0.2)
      0.23f, 1.f, 0.02f,              // beyond end b, inside its sphere
      0.1f, 1.f, 0.3f,                // outside
      0.1f, 1.f, 0.f;                 // on the axis
  for (size_t v = 0; v < 4; ++v)
    for (int i = 0; i < m.gameMesh.skin.influences; ++i)
      m.gameMesh.skin.weights[v * size_t(m.gameMesh.skin.influences) + size_t(i)] = i == 0 ? 1.f : 0.f;
  m.meshPca.mean[1] = 1.01f;  // vertex 0 at (0.01, 1.01, 0): 1 cm above the axis
  std::fill(in.matrices.begin(), in.matrices.end(), Mat4f::Identity());
  m.bodyProxy.capsules = {{0, Vec3f(0.f, 1.f, 0.f), Vec3f(0.2f, 1.f, 0.f), 0.05f}};
  in.posed.clear();
  runtime::poseBodyProxy(m.bodyProxy, in.matrices, in.posed);
  const Reference ref = reference(in, true);
  const float e1 = std::sqrt(0.03f * 0.03f + 0.02f * 0.02f);  // vertex 1's distance from end b
  const std::vector<float> expected = {
      0.01f, 1.05f, 0.f, 0.2f + 0.03f * 0.05f / e1, 1.f, 0.02f * 0.05f / e1, 0.1f, 1.f, 0.3f, 0.1f, 1.f, 0.f};
  EXPECT_TRUE(
      test::matchesReference("reference on known answers", ref.positions, expected, [](size_t) { return 1e-6; }));
  EXPECT_EQ(ref.moved, 2u);
  const auto gpu = runDeform(ctx(), in, true);
  for (const auto& p : gpu.problems) ADD_FAILURE() << p;
  EXPECT_TRUE(test::matchesReference("kernel on known answers", gpu.positions, expected, [](size_t) { return 1e-6; }));
}

}  // namespace
}  // namespace swish
