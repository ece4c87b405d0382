// Conformance of the deform kernel (shaders/deform.comp via gpu::DeformPass) to its CPU references:
// runtime::referencePcaReconstruct (skinning off) and runtime::referenceSkin (skinning on), on seeded
// random models (seed printed; SWISH_TEST_SEED overrides), odd sizes, many instances, NaN/Inf inputs
// and exactly representable inputs; and at quality levels (runtime/quality_levels.hpp): every level of
// the default ladder, and mixed per-instance levels in one dispatch. Every output is followed by guard
// words; every input is checked unchanged afterwards.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>

#include "support/error_message.hpp"
#include "support/gpu_buffers.hpp"
#include "support/gpu_compare.hpp"
#include "support/gpu_test.hpp"
#include "support/random_model.hpp"
#include "support/seeded_test.hpp"
#include "swish/gpu/deform_pass.hpp"
#include "swish/runtime/quality_levels.hpp"
#include "swish/runtime/reference_pca.hpp"
#include "swish/runtime/reference_skinning.hpp"

namespace swish {
namespace {

using test::CheckedInput;
using test::GuardedOutput;

struct DeformCase {
  uint32_t vertices, components, influences, instances;
};
// Readable parameters in test names and JUnit reports.
void PrintTo(const DeformCase& c, std::ostream* os) {
  *os << c.vertices << " vertices, K " << c.components << ", " << c.influences << " influences, " << c.instances
      << " instances";
}

struct DeformInputs {
  Model model;
  std::vector<float> weights;   // instances x K
  std::vector<Mat4f> matrices;  // instances x joints
  uint32_t instances = 0;
  std::vector<uint32_t> components;  // per instance: its quality level's k (empty: K for all)
  // Per instance: how many leading components the reference reads.
  uint32_t componentsOf(uint32_t i) const {
    return components.empty() ? uint32_t(model.meshComponents()) : components[i];
  }
};

DeformInputs randomInputs(uint64_t seed, const DeformCase& c) {
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.vertices = c.vertices;
  spec.meshComponents = c.components;
  spec.influences = c.influences;
  spec.normalMaps = 0;
  DeformInputs in;
  in.model = test::makeRandomModel(rng, spec);
  in.instances = c.instances;
  for (uint32_t i = 0; i < c.instances * c.components; ++i) in.weights.push_back(float(rng.normal(0, 2)));
  for (uint32_t i = 0; i < c.instances; ++i) {
    Pose pose = test::makeRandomPose(rng, in.model.skeleton);
    pose.rootTranslation = Vec3f(rng.uniformf(-2, 2), rng.uniformf(0, 1), rng.uniformf(-2, 2));
    const auto m = in.model.skeleton.skinningMatrices(pose);
    in.matrices.insert(in.matrices.end(), m.begin(), m.end());
  }
  return in;
}

struct GpuDeformResult {
  std::vector<float> positions;
  std::vector<std::string> problems;  // guard or input violations
};

// basisTexels: the pass reads the basis as texels (deform_basis_texels.comp) where the device's
// maxTexelBufferElements allows, else through its address (deform.comp).
// With per-instance components: the kernel with bands (DeformPass::packLevels), and `poisonUnreadGroups`
// writes NaN into every packed weight group beyond the instance's band (zero up to there, as packWeights
// leaves them): the kernel must not read them.
GpuDeformResult runDeform(gpu::Context& ctx, const DeformInputs& in, bool skinning, bool basisTexels,
                          bool poisonUnreadGroups = false) {
  const Model& m = in.model;
  const uint32_t n = uint32_t(m.gameMesh.vertexCount()), k = uint32_t(m.meshComponents());
  const std::vector<uint32_t> joints(m.gameMesh.skin.joints.begin(), m.gameMesh.skin.joints.end());
  CheckedInput mean(ctx, std::span<const float>(m.meshPca.mean.data(), 3 * n), "mean");
  CheckedInput basis(ctx, std::span<const float>(m.meshPca.basis.data(), size_t(m.meshPca.basis.size())), "basis");
  std::vector<float> weightRows(gpu::DeformPass::weightsBytes(in.instances, k) / sizeof(float));
  gpu::DeformPass::packWeights(in.weights.data(), in.instances, k, in.components,
                               weightRows.data());  // the kernel's padded rows
  const gpu::DeformPass::Levels levels = gpu::DeformPass::packLevels(in.components, k);
  const uint32_t k4 = gpu::DeformPass::paddedComponents(k);
  if (poisonUnreadGroups && !in.components.empty())
    for (uint32_t i = 0; i < in.instances; ++i)
      std::fill(weightRows.begin() + i * k4 + 4 * levels.groups[i], weightRows.begin() + (i + 1) * k4,
                std::numeric_limits<float>::quiet_NaN());
  CheckedInput weights(ctx, std::span<const float>(weightRows), "weights");
  std::vector<uint32_t> order = levels.order;
  if (order.empty()) order.push_back(0);  // (a buffer of 1 word: unread without levels)
  CheckedInput instanceOrder(ctx, std::span<const uint32_t>(order), "instance order");
  std::vector<float> matrixRows(in.matrices.size() * 12);
  gpu::DeformPass::packSkinMatrices(in.matrices.data(), in.matrices.size(), matrixRows.data());  // the kernel's layout
  CheckedInput matrices(ctx, std::span<const float>(matrixRows), "skin matrices");
  CheckedInput skinJoints(ctx, std::span<const uint32_t>(joints), "skin joints");
  CheckedInput skinWeights(ctx, std::span<const float>(m.gameMesh.skin.weights), "skin weights");
  GuardedOutput out(ctx, size_t(in.instances) * n * 3 * sizeof(float), "deformed positions");

  const uint64_t basisFloats = uint64_t(m.meshPca.basis.size());
  const gpu::DeformPass pass(ctx, k, uint32_t(m.gameMesh.skin.influences), skinning, basisTexels ? basisFloats : 0);
  const uint64_t limit = ctx.properties().limits.maxTexelBufferElements;
  EXPECT_EQ(pass.basisTexels(), basisTexels && basisFloats <= limit);  // (no anchor sets: no anchor texels)
  gpu::DeformPass::Args a;
  a.mean = mean.address();
  a.basis = basis.address();
  const gpu::DescriptorBinding instanceInputs =
      pass.bindInstanceInputs(ctx, weights.buffer(), matrices.buffer(), &basis.buffer(), nullptr);
  a.instanceInputs = instanceInputs.get();
  a.skinJoints = skinJoints.address();
  a.skinWeights = skinWeights.address();
  a.positionsOut = out.address();
  a.vertexCount = n;
  a.instanceCount = in.instances;
  a.jointCount = uint32_t(m.skeleton.size());
  if (!in.components.empty()) {
    a.instanceOrder = instanceOrder.address();
    a.bandEnd = levels.bandEnd;
    a.maxGroups = levels.maxGroups;
  }
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, a); });

  GpuDeformResult r;
  r.positions = out.read<float>(ctx);
  for (const CheckedInput* c : {&mean, &basis, &weights, &instanceOrder, &matrices, &skinJoints, &skinWeights})
    if (auto s = c->unchanged(ctx); !s.empty()) r.problems.push_back(s);
  if (auto s = out.guardsIntact(ctx); !s.empty()) r.problems.push_back(s);
  return r;
}

std::vector<float> referencePositions(const DeformInputs& in, bool skinning) {
  const Model& m = in.model;
  const size_t k = size_t(m.meshComponents()), j = m.skeleton.size();
  std::vector<float> out;
  for (uint32_t i = 0; i < in.instances; ++i) {
    Points3f p =
        runtime::referencePcaReconstruct(m.meshPca, std::span(in.weights).subspan(i * k, k), in.componentsOf(i));
    if (skinning)
      p = runtime::referenceSkin(p, m.gameMesh.skin,
                                 std::vector<Mat4f>(in.matrices.begin() + i * j, in.matrices.begin() + (i + 1) * j));
    out.insert(out.end(), p.data(), p.data() + p.size());
  }
  return out;
}

// PCA tolerance: the reference sums K products onto the mean in float. A device may contract each
// multiply-add into an FMA or reorder nothing else, so each of the K additions can round differently:
// the error is bounded by (K + 1) * eps * (|mean| + sum_k |basis_k * w_k|) (the standard gamma_K bound
// of a length-K reduction), evaluated per element from the inputs. At a quality level of k_i < K the
// sum has k_i terms (the kernel's further terms of the instance's last group add exact zeros), so
// the bound is over those: a kernel that read weights beyond k_i would exceed it.
std::function<double(size_t)> pcaTolerance(const DeformInputs& in) {
  const Model& m = in.model;
  const size_t k = size_t(m.meshComponents()), rows = size_t(m.meshPca.mean.size());
  auto bound = std::make_shared<std::vector<double>>(in.instances * rows);
  for (uint32_t i = 0; i < in.instances; ++i)
    for (size_t r = 0; r < rows; ++r) {
      const size_t ki = in.componentsOf(i);
      double mag = std::abs(double(m.meshPca.mean[Eigen::Index(r)]));
      for (size_t c = 0; c < ki; ++c)
        mag += std::abs(double(m.meshPca.basis(Eigen::Index(r), Eigen::Index(c))) * in.weights[i * k + c]);
      (*bound)[i * rows + r] = double(ki + 1) * FLT_EPSILON * mag;
    }
  return [bound](size_t e) { return (*bound)[e]; };
}

// Skinning tolerance, absolute + relative: on top of the PCA error, the blend of up to 8 matrices and
// the 3x3 product + translation add about 16 roundings. 2 um + 1e-5 relative (~80 float ulps of the
// position) admits FMA-contracting drivers, while any wrong joint, weight, matrix or instance moves
// a vertex by millimetres or more and fails.
double skinTolerance(float reference) { return 2e-6 + 1e-5 * std::abs(double(reference)); }

std::string caseName(const ::testing::TestParamInfo<DeformCase>& info) {
  const auto& c = info.param;
  return "V" + std::to_string(c.vertices) + "_K" + std::to_string(c.components) + "_Inf" +
         std::to_string(c.influences) + "_I" + std::to_string(c.instances);
}

class DeformConformance : public test::GpuTest, public ::testing::WithParamInterface<DeformCase> {};

TEST_P(DeformConformance, PcaReconstructionMatchesReference) {
  SWISH_TEST_SEED_SCOPE(seed, 0xDEF0 + GetParam().vertices);
  const DeformInputs in = randomInputs(seed, GetParam());
  for (const bool basisTexels : {false, true}) {
    SCOPED_TRACE(basisTexels ? "basis as texels" : "basis through its address");
    const auto gpu = runDeform(ctx(), in, false, basisTexels);
    for (const auto& p : gpu.problems) ADD_FAILURE() << p;
    test::CompareReport rep;
    EXPECT_TRUE(test::matchesReference("pre-skinning positions", gpu.positions, referencePositions(in, false),
                                       pcaTolerance(in), &rep));
    std::printf("max |gpu - reference| = %.3g m over %zu values\n", rep.maxAbsError, rep.compared);
  }
}

TEST_P(DeformConformance, SkinnedPositionsMatchReference) {
  SWISH_TEST_SEED_SCOPE(seed, 0x5C1 + GetParam().vertices);
  const DeformInputs in = randomInputs(seed, GetParam());
  const auto ref = referencePositions(in, true);
  for (const bool basisTexels : {false, true}) {
    SCOPED_TRACE(basisTexels ? "basis as texels" : "basis through its address");
    const auto gpu = runDeform(ctx(), in, true, basisTexels);
    for (const auto& p : gpu.problems) ADD_FAILURE() << p;
    test::CompareReport rep;
    EXPECT_TRUE(test::matchesReference(
        "skinned positions", gpu.positions, ref, [&](size_t e) { return skinTolerance(ref[e]); }, &rep));
    std::printf("max |gpu - reference| = %.3g m over %zu values\n", rep.maxAbsError, rep.compared);
  }
}

// Odd sizes: 1 vertex, a prime count, a large prime count; 1, 3 and 22 instances; K = 1, 5, 30;
// the 64-component case runs 150 instances through one dispatch.
INSTANTIATE_TEST_SUITE_P(Sizes, DeformConformance,
                         ::testing::Values(DeformCase{1, 1, 1, 1}, DeformCase{7, 5, 4, 3}, DeformCase{997, 30, 4, 22},
                                           DeformCase{997, 7, 8, 5}, DeformCase{100003, 2, 4, 2},
                                           DeformCase{97, 64, 3, 150}),
                         caseName);

class DeformSpecialValues : public test::GpuTest {};

// NaN/Inf placement: each poisoned input must reach exactly the outputs the reference says it reaches.
TEST_F(DeformSpecialValues, NanAndInfReachExactlyTheReferenceOutputs) {
  SWISH_TEST_SEED_SCOPE(seed, 0xBAD);
  DeformInputs in = randomInputs(seed, {61, 6, 4, 4});
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  in.model.meshPca.basis(3 * 17 + 1, 2) = nan;                    // vertex 17 (y), every instance
  in.weights[2 * 6 + 4] = nan;                                    // instance 2, every vertex
  const uint16_t joint = in.model.gameMesh.skin.joints[5 * 4];    // a joint vertex 5 uses
  in.matrices[3 * in.model.skeleton.size() + joint](0, 3) = inf;  // instance 3's translation x of that joint
  in.model.gameMesh.skin.weights[9 * 4 + 1] = 0.f;                // a zero weight: skipped, so...
  in.matrices[1 * in.model.skeleton.size() + in.model.gameMesh.skin.joints[9 * 4 + 1]](1, 1) =
      nan;  // ...no NaN unless used
  const auto ref = referencePositions(in, true);
  for (const bool basisTexels : {false, true}) {
    SCOPED_TRACE(basisTexels ? "basis as texels" : "basis through its address");
    const auto gpu = runDeform(ctx(), in, true, basisTexels);
    for (const auto& p : gpu.problems) ADD_FAILURE() << p;
    test::CompareReport rep;
    EXPECT_TRUE(test::matchesReference(
        "skinned positions with NaN/Inf inputs", gpu.positions, ref, [&](size_t e) { return skinTolerance(ref[e]); },
        &rep));
    // The poison must be neither absent nor everywhere, or the test would prove nothing.
    EXPECT_GT(rep.nonFinite, 61u * 3);
    EXPECT_LT(rep.nonFinite, ref.size());
  }
}

// Small integers and binary fractions: every sum and product is exact in float, so GPU and reference
// must agree bit for bit (tolerance 0).
TEST_F(DeformSpecialValues, ExactlyRepresentableInputsGiveExactResults) {
  Rng rng(test::testSeed(0xE8AC7));
  DeformInputs in = randomInputs(7, {40, 3, 2, 3});
  Model& m = in.model;
  for (Eigen::Index i = 0; i < m.meshPca.mean.size(); ++i) m.meshPca.mean[i] = float(int(rng.below(64)) - 32);
  for (Eigen::Index i = 0; i < m.meshPca.basis.size(); ++i)
    m.meshPca.basis.data()[i] = float(int(rng.below(16)) - 8) * 0.25f;
  for (auto& w : in.weights) w = float(int(rng.below(8)) - 4) * 0.5f;
  for (size_t v = 0; v < m.gameMesh.vertexCount(); ++v) {
    m.gameMesh.skin.weights[2 * v] = (v % 3 == 0) ? 1.f : 0.5f;
    m.gameMesh.skin.weights[2 * v + 1] = (v % 3 == 0) ? 0.f : 0.5f;
  }
  for (auto& mat : in.matrices) {  // signed axis permutations with integer translations
    const int axis = int(rng.below(3));
    mat = Mat4f::Zero();
    for (int r = 0; r < 3; ++r) mat(r, (r + axis) % 3) = rng.below(2) ? 1.f : -1.f;
    mat(3, 3) = 1.f;
    for (int r = 0; r < 3; ++r) mat(r, 3) = float(int(rng.below(20)) - 10);
  }
  // Also at quality levels (k = 0..3 per instance): the zero weights that pad an instance's last group
  // must add exactly nothing, so the result is the reference's shorter sum bit for bit.
  for (const bool levels : {false, true}) {
    in.components.clear();
    if (levels) in.components = {2, 0, 1};
    for (bool skinning : {false, true})
      for (const bool basisTexels : {false, true}) {
        SCOPED_TRACE(std::string(basisTexels ? "basis as texels" : "basis through its address") +
                     (levels ? ", levels 2 0 1" : ""));
        const auto gpu = runDeform(ctx(), in, skinning, basisTexels, levels);
        for (const auto& p : gpu.problems) ADD_FAILURE() << p;
        EXPECT_TRUE(test::matchesReference(skinning ? "skinned positions" : "PCA positions", gpu.positions,
                                           referencePositions(in, skinning), [](size_t) { return 0.0; }));
      }
  }
}

// Quality levels: instance i reads its first k_i components only.

// Garbage where each instance's level ends: NaN, Inf and huge values in every weight from k_i on, in the
// weights the CPU hands over (as FrameKernelInputs::meshWeights may hold the network's full output).
// The reference ignores them by definition; on the GPU packWeights must zero them up to the groups of
// the instance's band, and runDeform's poisonUnreadGroups puts NaN in the groups beyond, which the
// kernel must not read. Any of them reaching a sum makes that output NaN or huge: a failure.
void poisonWeightsBeyondLevels(DeformInputs& in, Rng& rng) {
  const uint32_t k = uint32_t(in.model.meshComponents());
  const float garbage[] = {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(),
                           -std::numeric_limits<float>::infinity(), 1e30f, -3e37f};
  for (uint32_t i = 0; i < in.instances; ++i)
    for (uint32_t c = in.componentsOf(i); c < k; ++c) in.weights[size_t(i) * k + c] = garbage[rng.below(5)];
}

// Both forms of the basis, PCA alone (the derived bound, over each instance's own k_i terms) and
// skinned (skinTolerance).
void expectLevelsMatchReference(gpu::Context& ctx, const DeformInputs& in) {
  const auto pcaRef = referencePositions(in, false), skinnedRef = referencePositions(in, true);
  const auto pcaBound = pcaTolerance(in);
  for (const bool basisTexels : {false, true}) {
    SCOPED_TRACE(basisTexels ? "basis as texels" : "basis through its address");
    const auto pca = runDeform(ctx, in, false, basisTexels, true);
    for (const auto& p : pca.problems) ADD_FAILURE() << p;
    test::CompareReport rep;
    EXPECT_TRUE(test::matchesReference("pre-skinning positions", pca.positions, pcaRef, pcaBound, &rep));
    EXPECT_EQ(rep.nonFinite, 0u);
    const auto skinned = runDeform(ctx, in, true, basisTexels, true);
    for (const auto& p : skinned.problems) ADD_FAILURE() << p;
    test::CompareReport srep;
    EXPECT_TRUE(test::matchesReference(
        "skinned positions", skinned.positions, skinnedRef, [&](size_t e) { return skinTolerance(skinnedRef[e]); },
        &srep));
    std::printf("max |gpu - reference| = %.3g m (PCA), %.3g m (skinned) over %zu values\n", rep.maxAbsError,
                srep.maxAbsError, srep.compared);
  }
}

class DeformLevels : public test::GpuTest {};

// Every level of runtime::defaultLadder of a K = 30 model (30, 15, 7, 3 and 0 components: odd k, k not
// a multiple of 4, the mean shape), all 22 instances at that level in one dispatch: each level is one
// band of the kernel (8, 4, 2, 1, 0 groups), the others empty.
TEST_F(DeformLevels, EveryLevelOfTheDefaultLadderMatchesReference) {
  SWISH_TEST_SEED_SCOPE(seed, 0x1AD0);
  const DeformInputs base = randomInputs(seed, {997, 30, 4, 22});
  Rng rng(seed + 1);
  const runtime::QualityLadder ladder = runtime::defaultLadder(base.model);
  std::vector<uint32_t> ks;
  for (const auto& level : ladder.levels) ks.push_back(level.meshComponents);
  EXPECT_EQ(ks, (std::vector<uint32_t>{30, 15, 7, 3, 0})) << "the ladder this test was written for";
  EXPECT_EQ(gpu::DeformPass::bandsOf(30), (std::vector<uint32_t>{8, 4, 2, 1, 0}));
  for (const auto& level : ladder.levels) {
    SCOPED_TRACE("level " + level.name);
    DeformInputs in = base;
    in.components.assign(in.instances, level.meshComponents);
    poisonWeightsBeyondLevels(in, rng);
    expectLevelsMatchReference(ctx(), in);
  }
}

// Mixed levels in one dispatch: every k from 0 to K = 30 at least once in 37 instances (every place in
// a group where a level can end, whole groups, every band, instances below their band's groups), in a
// shuffled order; then a frame whose levels all end well below K (bands 0 and 1 empty, maxGroups 2 of
// 8: the basis beyond is not loaded), and one of only k = 0 and 1 (the two narrowest bands).
TEST_F(DeformLevels, MixedLevelsInOneDispatchMatchReference) {
  SWISH_TEST_SEED_SCOPE(seed, 0x313ED);
  const DeformInputs base = randomInputs(seed, {613, 30, 4, 37});
  Rng rng(seed + 1);
  std::vector<uint32_t> all;
  for (uint32_t k = 0; k <= 30; ++k) all.push_back(k);
  while (all.size() < base.instances) all.push_back(uint32_t(rng.below(31)));
  for (size_t i = all.size(); i > 1; --i) std::swap(all[i - 1], all[rng.below(i)]);
  std::vector<uint32_t> low(base.instances), lowest(base.instances);
  for (auto& k : low) k = uint32_t(rng.below(9));  // 0..8: at most 2 groups
  low[5] = 8;
  for (auto& k : lowest) k = uint32_t(rng.below(2));
  for (const auto& [name, components] :
       {std::pair<const char*, std::vector<uint32_t>>{"0..30", all}, {"0..17", low}, {"0..1", lowest}}) {
    SCOPED_TRACE(std::string("levels ") + name);
    DeformInputs in = base;
    in.components = components;
    poisonWeightsBeyondLevels(in, rng);
    expectLevelsMatchReference(ctx(), in);
  }
}

// The bands: the narrowest that holds each instance's groups, instances in order within a band.
TEST_F(DeformLevels, InstancesGoToTheNarrowestBandThatHoldsTheirComponents) {
  EXPECT_EQ(gpu::DeformPass::bandsOf(128), (std::vector<uint32_t>{32, 16, 8, 4, 0}));
  EXPECT_EQ(gpu::DeformPass::bandsOf(6), (std::vector<uint32_t>{2, 1, 0}));
  EXPECT_EQ(gpu::DeformPass::bandsOf(1), (std::vector<uint32_t>{1, 0}));
  const auto l = gpu::DeformPass::packLevels(std::vector<uint32_t>{128, 0, 20, 64, 65, 16, 1, 33, 0}, 128);
  EXPECT_EQ(l.groups, (std::vector<uint32_t>{32, 0, 8, 16, 32, 4, 4, 16, 0}));
  EXPECT_EQ(l.order, (std::vector<uint32_t>{0, 4, 3, 7, 2, 5, 6, 1, 8}));
  EXPECT_EQ(l.bandEnd, (std::array<uint32_t, 4>{2, 4, 5, 7}));
  EXPECT_EQ(l.maxGroups, 32u);
  EXPECT_EQ(gpu::DeformPass::packLevels(std::vector<uint32_t>{0, 3}, 128).maxGroups, 4u);
  const auto small = gpu::DeformPass::packLevels(std::vector<uint32_t>{0, 6, 3}, 6);  // bands 2, 1, 0
  EXPECT_EQ(small.order, (std::vector<uint32_t>{1, 2, 0}));
  EXPECT_EQ(small.bandEnd, (std::array<uint32_t, 4>{1, 2, 3, 3}));
}

// Levels the kernel cannot honour are refused, naming the instance.
TEST_F(DeformLevels, BadLevelsAreRejectedWithAReason) {
  const std::vector<float> w(2 * 6, 1.f);
  std::vector<float> rows(2 * 8);
  EXPECT_NE(test::errorOf([&] {
              gpu::DeformPass::packWeights(w.data(), 2, 6, std::vector<uint32_t>{3, 7}, rows.data());
            }).find("instance 1 reads 7 mesh components"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] {
              gpu::DeformPass::packWeights(w.data(), 2, 6, std::vector<uint32_t>{3}, rows.data());
            }).find("1 per-instance component counts for 2 instances"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] {
              gpu::DeformPass::packLevels(std::vector<uint32_t>{9, 0}, 6);
            }).find("instance 0 reads 9"),
            std::string::npos);
  const gpu::DeformPass pass(ctx(), 6, 4);
  gpu::DeformPass::Args a;
  a.vertexCount = 1;
  a.instanceCount = 2;
  a.instanceInputs = VkDescriptorSet(uintptr_t(1));  // never used: record throws first
  a.instanceOrder = 4096;
  a.maxGroups = 3;  // 6 components are 2 groups
  VkCommandBuffer cmd = ctx().beginOneTime();
  EXPECT_NE(test::errorOf([&] { pass.record(cmd, a); }).find("maxGroups 3 beyond the 2 weight groups"),
            std::string::npos);
  a.maxGroups = 2;
  a.bandEnd = {2, 1, 2, 2};
  EXPECT_NE(test::errorOf([&] { pass.record(cmd, a); }).find("band 1 ends at 1, out of order"), std::string::npos);
  a.bandEnd = {0, 3, 3, 3};
  EXPECT_NE(test::errorOf([&] { pass.record(cmd, a); }).find("band 1 ends at 3"), std::string::npos);
  // The push-out's code is only in the pipelines made for it: a pass made for no anchor sets (or for
  // fewer than the frame asks) refuses a frame with them, and one without skinning takes none.
  a.instanceOrder = 0;
  a.anchors = 4096;
  a.anchorSlots = 1;
  EXPECT_NE(test::errorOf([&] { pass.record(cmd, a); }).find("made without the push-out"), std::string::npos);
  const gpu::DeformPass twoSets(ctx(), 6, 4, true, 0, 2);
  a.anchorSlots = 3;
  EXPECT_NE(test::errorOf([&] { twoSets.record(cmd, a); }).find("3 body anchor sets, made for 1 to 2"),
            std::string::npos);
  ctx().abandonOneTime(cmd);
  EXPECT_NE(test::errorOf([&] { gpu::DeformPass(ctx(), 6, 4, true, 0, 4); }).find("4 body anchor sets"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] { gpu::DeformPass(ctx(), 6, 4, false, 0, 1); }).find("the push-out follows the skinning"),
            std::string::npos);
  // The push-out table: at most every influence of every set beyond the skin's joints, and none
  // without anchor sets.
  EXPECT_NE(test::errorOf([&] {
              gpu::DeformPass(ctx(), 6, 4, true, 0, 3, 13);
            }).find("13 push-out table joints beyond the skin's; supported: 0..12"),
            std::string::npos);
  EXPECT_NE(test::errorOf([&] { gpu::DeformPass(ctx(), 6, 4, true, 0, 0, 2); }).find("without anchor sets"),
            std::string::npos);
}

}  // namespace
}  // namespace swish
