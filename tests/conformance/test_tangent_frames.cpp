// Conformance of the tangent-frames kernels (gpu::TangentFramesPass: the single-pass
// shaders/tangent_frames.comp, and the two-pass triangle_frames.comp + vertex_frames_gather.comp that
// the frame recorder uses) to runtime::referenceTangentFrames (core/mesh_frames.cpp, THE definition
// of normals and tangents):
// seeded random deformed meshes of odd sizes, several instances per dispatch, NaN placement,
// an exactly representable flat mesh, guard words and unchanged inputs.
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>

#include "support/gpu_buffers.hpp"
#include "support/gpu_compare.hpp"
#include "support/gpu_test.hpp"
#include "support/random_model.hpp"
#include "support/seeded_test.hpp"
#include "swish/core/error.hpp"
#include "swish/core/mesh_frames.hpp"
#include "swish/gpu/tangent_frames_pass.hpp"
#include "swish/runtime/reference_tangent_frames.hpp"

namespace swish {
namespace {

using test::CheckedInput;
using test::GuardedOutput;

// Normals and tangents are unit vectors built from sums of cross products of edge vectors. Edges are
// differences of nearby positions, which carry the absolute rounding of the positions (coordinates up
// to several metres, edges of 2 cm: up to ~300 eps relative per edge); a driver fusing multiply-adds
// or computing sqrt/division within Vulkan's ULP limits moves a unit vector by far less than 1e-4.
// A frame built from the wrong triangles, the wrong adjacency or the wrong instance is off by 1e-2
// or more. The bitangent sign w is compared the same way (it is exactly +-1 on both sides).
constexpr double kFrameTolerance = 1e-4;

struct FramesCase {
  uint32_t vertices, instances;
};
void PrintTo(const FramesCase& c, std::ostream* os) {
  *os << c.vertices << " vertices, " << c.instances << " instances";
}

struct Frames {
  std::vector<float> normals, tangents;
  std::vector<std::string> problems;
};

Frames runGpu(gpu::Context& ctx, const Model& m, const std::vector<float>& positions, uint32_t instances, bool hasUvs,
              bool twoPass, bool store64 = true) {
  const Mesh& g = m.gameMesh;
  const uint32_t n = uint32_t(g.vertexCount());
  const MeshFrameTopology topo = buildFrameTopology(g.triangles, g.positions);
  CheckedInput pos(ctx, std::span<const float>(positions), "positions");
  CheckedInput uvs(ctx, std::span<const float>(g.uvs.data(), size_t(g.uvs.size())), "uvs");
  CheckedInput tris(ctx, std::span<const uint32_t>(g.triangles.data(), size_t(g.triangles.size())), "triangles");
  CheckedInput nOff(ctx, std::span<const uint32_t>(topo.normalAdjacency.offsets), "normal offsets");
  CheckedInput nTri(ctx, std::span<const uint32_t>(topo.normalAdjacency.triangles), "normal triangles");
  CheckedInput tOff(ctx, std::span<const uint32_t>(topo.tangentAdjacency.offsets), "tangent offsets");
  CheckedInput tTri(ctx, std::span<const uint32_t>(topo.tangentAdjacency.triangles), "tangent triangles");
  const std::vector<uint32_t> frameTriangles = gpu::TangentFramesPass::frameTriangles(topo);
  CheckedInput fTri(ctx, std::span<const uint32_t>(frameTriangles), "flagged triangles");
  GuardedOutput normals(ctx, size_t(instances) * n * 3 * 4, "normals");
  GuardedOutput tangents(ctx, size_t(instances) * n * 4 * 4, "tangents");
  const uint32_t triangles = uint32_t(g.triangles.rows());
  GuardedOutput terms(ctx, std::max<size_t>(16, gpu::TangentFramesPass::triangleTermsBytes(triangles, instances)),
                      "triangle terms");
  const gpu::TangentFramesPass pass(ctx, store64);
  gpu::DescriptorBinding twoPassBinding;
  if (twoPass) {
    gpu::TangentFramesPass::TwoPassBuffers b;
    b.positions = &pos.buffer();
    b.triangleTerms = &terms.buffer();
    b.normalOffsets = &nOff.buffer();
    b.frameTriangles = &fTri.buffer();
    b.normalsOut = &normals.buffer();
    b.tangentsOut = &tangents.buffer();
    twoPassBinding = pass.bindTwoPass(ctx, b);
  }
  gpu::TangentFramesPass::Args a;
  a.positions = pos.address();
  a.uvs = uvs.address();
  a.triangles = tris.address();
  a.normalOffsets = nOff.address();
  a.normalTriangles = nTri.address();
  a.tangentOffsets = tOff.address();
  a.tangentTriangles = tTri.address();
  a.normalsOut = normals.address();
  a.tangentsOut = tangents.address();
  a.vertexCount = n;
  a.instanceCount = instances;
  a.hasUvs = hasUvs;
  a.twoPass = twoPassBinding.get();
  a.triangleCount = triangles;
  ctx.submitAndWait([&](VkCommandBuffer cmd) { pass.record(cmd, a); });
  Frames f;
  f.normals = normals.read<float>(ctx);
  f.tangents = tangents.read<float>(ctx);
  for (const CheckedInput* c : {&pos, &uvs, &tris, &nOff, &nTri, &tOff, &tTri, &fTri})
    if (auto s = c->unchanged(ctx); !s.empty()) f.problems.push_back(s);
  for (const GuardedOutput* o : {&normals, &tangents, &terms})
    if (auto s = o->guardsIntact(ctx); !s.empty()) f.problems.push_back(s);
  return f;
}

Frames runReference(const Model& m, const std::vector<float>& positions, uint32_t instances, bool hasUvs = true) {
  const Mesh& g = m.gameMesh;
  const Eigen::Index n = Eigen::Index(g.vertexCount());
  const MeshFrameTopology topo = buildFrameTopology(g.triangles, g.positions);
  Mesh rest = g;
  if (!hasUvs) rest.uvs.resize(0, 2);
  Frames f;
  for (uint32_t i = 0; i < instances; ++i) {
    const Points3f p = Eigen::Map<const Points3f>(positions.data() + size_t(i) * n * 3, n, 3);
    const auto r = runtime::referenceTangentFrames(p, rest, topo);
    f.normals.insert(f.normals.end(), r.normals.data(), r.normals.data() + r.normals.size());
    f.tangents.insert(f.tangents.end(), r.tangents.data(), r.tangents.data() + r.tangents.size());
  }
  return f;
}

// Deformed copies of the rest mesh: a random rigid-ish bend plus per-vertex noise per instance.
std::vector<float> deformedPositions(Rng& rng, const Model& m, uint32_t instances) {
  std::vector<float> out;
  for (uint32_t i = 0; i < instances; ++i) {
    const Quatf q(
        Eigen::AngleAxisf(rng.uniformf(-1, 1), Vec3f(rng.uniformf(-1, 1), 1, rng.uniformf(-1, 1)).normalized()));
    const Vec3f t(rng.uniformf(-3, 3), rng.uniformf(-1, 1), rng.uniformf(-3, 3));
    for (Eigen::Index v = 0; v < m.gameMesh.positions.rows(); ++v) {
      Vec3f p = q * Vec3f(m.gameMesh.positions.row(v).transpose()) + t;
      p += Vec3f(rng.uniformf(-.003f, .003f), rng.uniformf(-.003f, .003f), rng.uniformf(-.003f, .003f));
      out.insert(out.end(), {p.x(), p.y(), p.z()});
    }
  }
  return out;
}

void expectMatch(const Frames& gpu, const Frames& ref, test::CompareReport* nrep = nullptr) {
  for (const auto& p : gpu.problems) ADD_FAILURE() << p;
  test::CompareReport tr;
  EXPECT_TRUE(test::matchesReference(
      "normals", gpu.normals, ref.normals, [](size_t) { return kFrameTolerance; }, nrep));
  EXPECT_TRUE(test::matchesReference(
      "tangents", gpu.tangents, ref.tangents, [](size_t) { return kFrameTolerance; }, &tr));
  std::printf("max |gpu - reference|: tangents %.3g\n", tr.maxAbsError);
}

class TangentFramesConformance : public test::GpuTest, public ::testing::WithParamInterface<FramesCase> {};

TEST_P(TangentFramesConformance, MatchReference) {
  SWISH_TEST_SEED_SCOPE(seed, 0xF4A3 + GetParam().vertices);
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.vertices = GetParam().vertices;
  spec.normalMaps = 0;
  const Model m = test::makeRandomModel(rng, spec);
  const auto pos = deformedPositions(rng, m, GetParam().instances);
  const Frames ref = runReference(m, pos, GetParam().instances);
  const Frames one = runGpu(ctx(), m, pos, GetParam().instances, true, false);
  const Frames two = runGpu(ctx(), m, pos, GetParam().instances, true, true);
  for (const Frames* gpu : {&one, &two}) {
    SCOPED_TRACE(gpu == &two ? "two passes" : "one pass");
    test::CompareReport rep;
    expectMatch(*gpu, ref, &rep);
    std::printf("%s: max |gpu - reference|: normals %.3g over %zu values\n", gpu == &two ? "two passes" : "one pass",
                rep.maxAbsError, rep.compared);
  }
  // Same per-triangle values, same sums in the same order: the two paths agree bit for bit, and the
  // two-pass kernels storing 32-bit floats agree with those storing 64-bit words (two, where the device
  // has shaderInt64).
  EXPECT_TRUE(test::matchesReference("two-pass normals", two.normals, one.normals, [](size_t) { return 0.0; }));
  EXPECT_TRUE(test::matchesReference("two-pass tangents", two.tangents, one.tangents, [](size_t) { return 0.0; }));
  const Frames two32 = runGpu(ctx(), m, pos, GetParam().instances, true, true, false);
  for (const auto& p : two32.problems) ADD_FAILURE() << p;
  EXPECT_TRUE(test::matchesReference("two-pass normals, 32-bit stores", two32.normals, one.normals,
                                     [](size_t) { return 0.0; }));
  EXPECT_TRUE(test::matchesReference("two-pass tangents, 32-bit stores", two32.tangents, one.tangents,
                                     [](size_t) { return 0.0; }));
}

INSTANTIATE_TEST_SUITE_P(Sizes, TangentFramesConformance,
                         ::testing::Values(FramesCase{1, 1}, FramesCase{7, 2}, FramesCase{997, 3},
                                           FramesCase{100003, 1}),
                         [](const auto& info) {
                           return "V" + std::to_string(info.param.vertices) + "_I" +
                                  std::to_string(info.param.instances);
                         });

class TangentFramesSpecialCases : public test::GpuTest {};

// Without UVs every tangent comes from the fallback perpendicular of the normal.
TEST_F(TangentFramesSpecialCases, MeshWithoutUvsUsesTheFallbackTangentLikeTheReference) {
  Rng rng(test::testSeed(0x0F0));
  test::RandomModelSpec spec;
  spec.vertices = 50;
  spec.normalMaps = 0;
  const Model m = test::makeRandomModel(rng, spec);
  const auto pos = deformedPositions(rng, m, 2);
  for (bool twoPass : {false, true})
    expectMatch(runGpu(ctx(), m, pos, 2, false, twoPass), runReference(m, pos, 2, false));
}

// A NaN position poisons the frames of the vertices around it exactly as in the reference (whose
// fallbacks turn a NaN normal into (0,0,1) and a NaN tangent into the fallback perpendicular).
TEST_F(TangentFramesSpecialCases, NanPositionAffectsExactlyTheReferenceVertices) {
  SWISH_TEST_SEED_SCOPE(seed, 0x4A4);
  Rng rng(seed);
  test::RandomModelSpec spec;
  spec.vertices = 64;
  spec.normalMaps = 0;
  const Model m = test::makeRandomModel(rng, spec);
  auto pos = deformedPositions(rng, m, 2);
  pos[(64 + 27) * 3 + 1] = std::numeric_limits<float>::quiet_NaN();  // instance 1, vertex 27, y
  pos[(0 + 5) * 3 + 0] = std::numeric_limits<float>::infinity();     // instance 0, vertex 5, x
  const Frames gpu = runGpu(ctx(), m, pos, 2, true, false), ref = runReference(m, pos, 2);
  expectMatch(gpu, ref);
  expectMatch(runGpu(ctx(), m, pos, 2, true, true), ref);
  // The reference's fallbacks must actually have fired near the poisoned vertices: the frames there
  // differ from the frames of the same mesh without poison.
  size_t changed = 0;
  const Frames unpoisoned = runReference(
      m,
      [&] {
        Rng again(seed);
        test::makeRandomModel(again, spec);
        return deformedPositions(again, m, 2);
      }(),
      2);
  for (size_t i = 0; i < ref.normals.size(); ++i) changed += ref.normals[i] != unpoisoned.normals[i];
  EXPECT_GT(changed, 0u);
}

// An axis-aligned flat grid with integer coordinates: every cross product, sum and norm is exact, so
// normals (0,0,1) and tangents (1,0,0,+1) come out exactly on lavapipe. A device may normalise with
// its inversesqrt, which Vulkan allows 2 ULP (the SPIR-V environment's precision table): the NVIDIA
// H100 gives 1 - 2^-24 for some unit components. So 2 ULP of 1 (2^-22), no more.
TEST_F(TangentFramesSpecialCases, FlatIntegerGridIsExact) {
  Rng rng(1);
  test::RandomModelSpec spec;
  spec.vertices = 36;
  spec.normalMaps = 0;
  Model m = test::makeRandomModel(rng, spec);
  std::vector<float> pos;
  for (Eigen::Index v = 0; v < 36; ++v) {
    m.gameMesh.positions.row(v) << float(v % 6), float(v / 6), 0.f;
    m.gameMesh.uvs.row(v) << float(v % 6) * 0.125f, float(v / 6) * 0.125f;
    pos.insert(pos.end(), {float(v % 6) * 2.f, float(v / 6) * 2.f, 0.f});
  }
  const Frames ref = runReference(m, pos, 1);
  for (bool twoPass : {false, true}) {
    const Frames gpu = runGpu(ctx(), m, pos, 1, true, twoPass);
    for (const auto& p : gpu.problems) ADD_FAILURE() << p;
    constexpr double kTwoUlpOfOne = 1.0 / (1 << 22);
    EXPECT_TRUE(test::matchesReference("normals", gpu.normals, ref.normals, [](size_t) { return kTwoUlpOfOne; }));
    EXPECT_TRUE(test::matchesReference("tangents", gpu.tangents, ref.tangents, [](size_t) { return kTwoUlpOfOne; }));
  }
  EXPECT_EQ(std::abs(ref.normals[2]), 1.f);  // the case really is the flat one
}

// The two-pass gather walks the welded adjacency once, with the entries that are not the vertex's own
// triangles flagged; the own triangles must be a subsequence of the welded ones (their order is the
// order of the tangent sums).
TEST(TangentFramesAdjacency, FlagsTheWeldedOnlyEntriesAndRejectsAnotherOrder) {
  MeshFrameTopology topo;
  topo.normalAdjacency = {{0, 3, 5}, {1, 4, 7, 2, 3}};
  topo.tangentAdjacency = {{0, 2, 3}, {1, 7, 3}};
  const uint32_t f = gpu::TangentFramesPass::kNotOwnTriangle;
  EXPECT_EQ(gpu::TangentFramesPass::frameTriangles(topo), (std::vector<uint32_t>{1, 4 | f, 7, 2 | f, 3}));
  topo.tangentAdjacency = {{0, 2, 3}, {7, 1, 3}};
  EXPECT_THROW(gpu::TangentFramesPass::frameTriangles(topo), Error);
}

}  // namespace
}  // namespace swish
