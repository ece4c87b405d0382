// Bring your own simulation, end to end: `swish bake --export-poses` writes the pose list, an
// "external tool" simulates it and writes one OBJ per pose in the exported layout, and a bake with
// part1.simulation "source": "external" learns from those files. The external tool here is swish's
// own solver, driven only by what the export wrote (poses.json's rotations, garment.obj's mesh) and
// writing OBJ with 6 decimals as Maya, Blender and Marvelous Designer do: so the external bake must
// give the built-in bake's dataset and model, up to the OBJ round trip's rounding (0.5 um per
// coordinate). A second bake reads a re-meshed garment (another vertex count and order, no vertex
// where the simulation mesh has one) bound by closest point, with one result missing and one broken.
//
// Small recipe (the default character, 10 thinned poses of CMU 01_01 plus the rest pose, the welded
// game mesh as simulation mesh, a short transition): two sets of simulations and three part-2 bakes
// in well under a minute on two cores.
#include <gtest/gtest.h>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>

#include "support/paths.hpp"
#include "support/temp_dir.hpp"
#include "swish/bake/cloth/cloth_solver.hpp"
#include "swish/bake/cloth/external_simulation.hpp"
#include "swish/bake/cloth/pose_export.hpp"
#include "swish/bake/dataset/dataset_io.hpp"
#include "swish/bake/pipeline/bake_pipeline.hpp"
#include "swish/core/error.hpp"
#include "swish/io/animation_import.hpp"
#include "swish/model/model_file.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/reference_frame.hpp"
#include "swish/runtime/theta.hpp"

using namespace swish;
using namespace swish::bake;
namespace fs = std::filesystem;

namespace {

const fs::path kClip = test::debianMocap("01_01.bvh");

// The limb clearance keeps the whole trunk clear (limb_garment_reach 0) as when the model comparison's
// bound below was set: with the 30 mm default the ten poses' thighs are corrected differently, and this
// tiny network's training amplifies the OBJ rounding (0.7 um in the dataset) to 0.125 mm in its
// predictions instead of 0.004 mm (measured), a property of the training, not of the files' path.
nlohmann::json recipe(const std::string& name, const nlohmann::json& simulationExtra = nlohmann::json::object()) {
  nlohmann::json sim = {
      {"vertices", 0}, {"transition_seconds", 0.3}, {"settle_seconds", 0.2}, {"frame_rate", 20}, {"threads", 2},
      {"gravity", 0},  {"limb_garment_reach", 0}};
  sim.update(simulationExtra);
  return {{"name", name},
          {"output", name},
          {"part1",
           {{"character", "default"},
            {"clips", {kClip.string()}},
            {"thinning", {{"target_poses", 10}}},
            {"simulation", sim},
            // The game mesh as transferred: keeping it over the body (cover_body_mm, on by default) moves the
            // two bakes' shoulders differently where their bindings already differ (measured: 29.1 mm max
            // between the re-meshed and built-in bakes with it, 13.9 without; mean 0.47 / 0.44 mm), and
            // what this test compares is the binding.
            {"transfer", {{"cover_body_mm", 0}}},
            {"normal_maps", {{"size", 16}, {"dilation_rings", 2}}},
            {"preview", {{"poses", 0}}}}},
          {"train",
           {{"mesh_components", 8},
            {"normal_code_dims", 4},
            {"database_size", 4},
            {"codebook_size", 16},
            {"hidden_layers", 2},
            {"hidden_width", 16},
            {"max_epochs", 100},
            {"patience", 30},
            {"test_fraction", 0.2},
            {"bc5_baseline", false}}}};
}

// OBJ as a DCC tool writes it: fixed 6 decimals (half a micrometre of rounding per coordinate).
void writeToolObj(const fs::path& file, const Points3f& p, const Triangles& t) {
  std::ofstream o(file);
  char line[128];
  for (Eigen::Index v = 0; v < p.rows(); ++v) {
    std::snprintf(line, sizeof line, "v %.6f %.6f %.6f\n", double(p(v, 0)), double(p(v, 1)), double(p(v, 2)));
    o << line;
  }
  for (Eigen::Index f = 0; f < t.rows(); ++f)
    o << "f " << t(f, 0) + 1 << " " << t(f, 1) + 1 << " " << t(f, 2) + 1 << "\n";
}

// A re-meshed garment: a vertex at every edge midpoint and, instead of each original vertex, the mean
// of its edges' midpoints; four triangles per original one. No vertex coincides with one of the
// original mesh (the corner vertices sit half the umbrella Laplacian off it), so binding is tested
// between vertices, not at them. Its positions are a fixed linear map of the original's (`map`).
struct Remesh {
  Triangles triangles;
  std::vector<std::vector<std::pair<uint32_t, float>>> map;  // per new vertex: (original vertex, weight)
  Points3f apply(const Points3f& p) const {
    Points3f out = Points3f::Zero(Eigen::Index(map.size()), 3);
    for (size_t v = 0; v < map.size(); ++v)
      for (const auto& [i, w] : map[v]) out.row(Eigen::Index(v)) += w * p.row(i);
    return out;
  }
};

Remesh remesh(const Triangles& t, size_t vertexCount, uint64_t seed) {
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoint;
  std::vector<std::vector<std::pair<uint32_t, float>>> map(vertexCount);  // corners first, filled below
  auto mid = [&](uint32_t a, uint32_t b) {
    const auto key = std::minmax(a, b);
    auto [it, added] = midpoint.try_emplace({key.first, key.second}, uint32_t(map.size()));
    if (added) map.push_back({{a, 0.5f}, {b, 0.5f}});
    return it->second;
  };
  std::vector<uint32_t> tris;
  for (Eigen::Index f = 0; f < t.rows(); ++f) {
    const uint32_t a = t(f, 0), b = t(f, 1), c = t(f, 2);
    const uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
    tris.insert(tris.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
  }
  // Corner vertex v: the mean of the midpoints of v's edges; on the garment's border (hem, cuffs,
  // neckline) of its two border edges, so that the re-meshed border follows the original one (as a
  // re-mesher keeps a border) instead of shrinking half an edge inwards.
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (Eigen::Index f = 0; f < t.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const auto key = std::minmax(t(f, k), t(f, (k + 1) % 3));
      ++uses[{key.first, key.second}];
    }
  std::vector<std::vector<uint32_t>> ring(vertexCount), border(vertexCount);
  for (const auto& [edge, m] : midpoint) {
    ring[edge.first].push_back(m);
    ring[edge.second].push_back(m);
    if (uses[edge] == 1) {
      border[edge.first].push_back(m);
      border[edge.second].push_back(m);
    }
  }
  for (size_t v = 0; v < vertexCount; ++v)
    if (!border[v].empty()) ring[v] = border[v];
  for (size_t v = 0; v < vertexCount; ++v) {
    std::map<uint32_t, float> w;
    for (uint32_t m : ring[v])
      for (const auto& [i, x] : map[m]) w[i] += x / float(ring[v].size());
    map[v].assign(w.begin(), w.end());
  }
  // Shuffle the vertex order.
  std::vector<uint32_t> order(map.size());
  for (uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  std::shuffle(order.begin(), order.end(), std::mt19937_64(seed));
  std::vector<uint32_t> newIndex(map.size());
  Remesh r;
  r.map.resize(map.size());
  for (uint32_t k = 0; k < order.size(); ++k) {
    newIndex[order[k]] = k;
    r.map[k] = map[order[k]];
  }
  for (uint32_t& i : tris) i = newIndex[i];
  r.triangles = Eigen::Map<const Triangles>(tris.data(), Eigen::Index(tris.size() / 3), 3);
  return r;
}

// The model's garment for a pose, through the runtime path (MLP -> PCA -> skinning).
Points3f predict(const Model& model, const Pose& pose) {
  const runtime::MlpEvaluator mlp(model);
  std::vector<float> lambda(size_t(mlp.outputSize()));
  mlp.evaluate(runtime::computeTheta(model.inputJoints, pose.local), lambda);
  runtime::FrameKernelInputs in;
  in.instanceCount = 1;
  in.meshWeights.assign(lambda.begin(), lambda.begin() + model.meshComponents());
  in.skinMatrices = model.skeleton.skinningMatrices(pose);
  in.selectedMaps = {0};
  in.blendAlpha = {1.f};
  in.pushOut = false;  // the network's own output: what the two datasets trained
  return runtime::referenceFrame(model, in).positions[0];
}

struct Stats {
  double meanMm = 0, maxMm = 0;
};
Stats vertexError(const Points3f& a, const Points3f& b) {
  Stats s;
  for (Eigen::Index v = 0; v < a.rows(); ++v) {
    const double d = 1000.0 * double((a.row(v) - b.row(v)).norm());
    s.meanMm += d / double(a.rows());
    s.maxMm = std::max(s.maxMm, d);
  }
  return s;
}

// Everything the tests below look at, made once (the simulations are the expensive part).
struct RoundTrip {
  test::TempDir tmp{"bake_external"};
  BakeConfig solverConfig, externalConfig, remeshConfig;
  BakeRunResult solverBake, externalBake, remeshBake;
  PoseExportResult exported;
  nlohmann::json sidecar;
  std::vector<uint32_t> toolFailed;          // poses the external tool could not simulate (no file written)
  uint32_t removedPose = 0, brokenPose = 0;  // the re-meshed set's missing and broken results
  std::vector<std::string> remeshLog;
};

// Each ctest test is its own process: the export alone for the first test, everything for the second.
RoundTrip& roundTrip(bool bake) {
  static std::unique_ptr<RoundTrip> rt;
  if (!rt) {
    rt = std::make_unique<RoundTrip>();
    // 1. Export the poses.
    rt->solverConfig = parseBakeConfig(recipe("solver"), "solver.json", rt->tmp.path());
    rt->exported = exportPoses(*rt->solverConfig.part1, rt->tmp / "export");
    rt->sidecar = nlohmann::json::parse(std::ifstream(rt->tmp / "export" / "poses.json"));
  }
  if (bake && !rt->solverBake.part1.is_object()) {
    RoundTrip* r = rt.get();
    const fs::path dir = r->tmp.path();
    const fs::path out = dir / "export";
    // 2. The built-in bake.
    r->solverBake = runBake(r->solverConfig);

    // 3. The external tool: reads garment.obj and poses.json only, simulates every pose from the A-pose,
    // writes results/pose_<id>.obj; a pose that fails gets no file.
    const DatasetBuildSettings& s = *r->solverConfig.part1;
    const Character character = loadDatasetCharacter(s);
    const ClothSolver solver(character, buildSimulationMesh(character, s.simulationVertices), s.simulation);
    const ObjMesh garment = readObj(out / "garment.obj");
    if (garment.positions != solver.mesh().restPositions || garment.triangles != solver.mesh().triangles)
      throw Error("garment.obj is not the simulation mesh");
    const auto& poses = r->sidecar["poses"];
    std::vector<char> failed(poses.size(), 0);
    std::vector<Points3f> shapes(poses.size());
    tbb::parallel_for(size_t(0), poses.size(), [&](size_t i) {
      const auto& e = poses[i];
      Pose p;
      for (const auto& q : e["rotations"])
        p.local.emplace_back(q[3].get<float>(), q[0].get<float>(), q[1].get<float>(), q[2].get<float>());
      p.rootTranslation = Vec3f(e["root_translation"][0].get<float>(), e["root_translation"][1].get<float>(),
                                e["root_translation"][2].get<float>());
      const PoseSimulation sim = solver.simulate(p);
      if (!sim.ok) {
        failed[i] = 1;
        return;
      }
      shapes[i] = sim.positions;
      writeToolObj(out / e["result"].get<std::string>(), sim.positions, garment.triangles);
    });
    for (size_t i = 0; i < poses.size(); ++i)
      if (failed[i]) r->toolFailed.push_back(poses[i]["id"].get<uint32_t>());

    // 4. Bake from the files.
    r->externalConfig =
        parseBakeConfig(recipe("external", {{"source", "external"}, {"path", "export/results"}}), "external.json", dir);
    r->externalBake = runBake(r->externalConfig);

    // 5. The same results on a re-meshed garment, in another vertex order, with its rest shape; one
    // pose's file left out, one broken.
    const fs::path remeshed = dir / "remeshed";
    fs::create_directories(remeshed);
    const Remesh rm = remesh(garment.triangles, size_t(garment.positions.rows()), 7);
    writeToolObj(remeshed / "rest.obj", rm.apply(garment.positions), rm.triangles);
    std::vector<uint32_t> written;
    for (size_t i = 0; i < poses.size(); ++i) {
      if (failed[i]) continue;
      const uint32_t id = poses[i]["id"].get<uint32_t>();
      // Read back what the tool wrote (its rounding included), as the artist's re-mesher would.
      const ObjMesh m = readObj(out / poses[i]["result"].get<std::string>());
      writeToolObj(remeshed / fs::path(exportedResultName(id)).filename(), rm.apply(m.positions), rm.triangles);
      written.push_back(id);
    }
    r->removedPose = written[1];
    r->brokenPose = written[2];
    fs::remove(externalPoseCandidates(remeshed, r->removedPose)[0]);
    std::ofstream(externalPoseCandidates(remeshed, r->brokenPose)[0], std::ios::trunc) << "v 0 0 0\nv 1 0\n";
    r->remeshConfig =
        parseBakeConfig(recipe("remeshed", {{"source", "external"}, {"path", "remeshed"}}), "remeshed.json", dir);
    BakeRunOptions o;
    o.log = [r](const std::string& l) { r->remeshLog.push_back(l); };
    r->remeshBake = runBake(r->remeshConfig, o);
  }
  return *rt;
}

bool haveClip() { return fs::exists(kClip); }

std::vector<uint32_t> failedIds(const nlohmann::json& part1) {
  std::vector<uint32_t> ids;
  for (const auto& f : part1["failed"]) ids.push_back(f["pose"].get<uint32_t>());
  return ids;
}

}  // namespace

TEST(BakeExternal, ExportWritesTheClipTheSidecarTheMeshesAndAReadme) {
  if (!haveClip()) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  RoundTrip& r = roundTrip(false);
  const fs::path out = r.tmp / "export";
  for (const char* f : {"poses.bvh", "poses.glb", "poses.json", "body.obj", "garment.obj", "README.md"})
    EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
  EXPECT_TRUE(fs::is_directory(out / "results"));
  EXPECT_EQ(r.exported.poses, 11u);  // 10 thinned + the rest pose
  ASSERT_EQ(r.sidecar["poses"].size(), r.exported.poses);
  EXPECT_EQ(r.sidecar["garment"]["vertices"].get<size_t>(), r.exported.simulationVertices);
  EXPECT_EQ(size_t(readObj(out / "garment.obj").positions.rows()), r.exported.simulationVertices);
  std::string readme((std::istreambuf_iterator<char>(std::ifstream(out / "README.md").rdbuf())), {});
  EXPECT_NE(readme.find("results/pose_000000.obj"), std::string::npos);
  EXPECT_NE(readme.find("\"source\": \"external\""), std::string::npos);

  // Both clips give back, at each pose's target frame, the rotations the sidecar lists (the poses the
  // solver simulates): BVH through its Euler angles (1e-5), glTF as stored floats.
  const Character character = loadDatasetCharacter(*r.solverConfig.part1);
  const Skeleton& sk = character.skeleton;
  for (const char* clipFile : {"poses.bvh", "poses.glb"}) {
    const AnimationClip clip = io::importAnimation(out / clipFile, sk);
    ASSERT_EQ(clip.frames.size(), r.sidecar["clip"]["frames"].get<size_t>()) << clipFile;
    EXPECT_NEAR(clip.framesPerSecond, 20.f, 1e-3f) << clipFile;
    for (const auto& e : r.sidecar["poses"]) {
      const Pose& f = clip.frames[e["target_frame"].get<size_t>()];
      for (size_t j = 0; j < sk.size(); ++j) {
        const auto& q = e["rotations"][j];
        const Quatf want(q[3].get<float>(), q[0].get<float>(), q[1].get<float>(), q[2].get<float>());
        EXPECT_GT(std::abs(f.local[j].normalized().dot(want)), 1.f - 1e-5f)
            << clipFile << " pose " << e["id"] << " joint " << sk.joints[j].name;
      }
      const Pose& first = clip.frames[e["first_frame"].get<size_t>()];
      for (size_t j = 1; j < sk.size(); ++j)
        EXPECT_GT(std::abs(first.local[j].normalized().dot(sk.joints[j].rest.rotation)), 1.f - 1e-5f) << clipFile;
    }
  }
}

// The OBJ round trip rounds each coordinate to 6 decimals (<= 0.5 um). Everything downstream of the
// shapes (transfer, Laplacian smoothing, un-skinning) is smooth in them, so the dataset's shapes stay
// within a few micrometres; the normal maps are ray casts (a texel whose ray grazes an edge can move
// to its neighbour), so they are compared by mean. The model is then trained on (almost) the same
// data with the same seed: its predictions are compared to the built-in model's.
TEST(BakeExternal, FilesFromTheExportGiveTheBuiltInBakesModelAndAReMeshedGarmentBinds) {
  if (!haveClip()) GTEST_SKIP() << kClip << " is missing (Debian package assimp-testmodels)";
  RoundTrip& r = roundTrip(true);
  const nlohmann::json& a = r.solverBake.part1;
  const nlohmann::json& b = r.externalBake.part1;
  EXPECT_EQ(b["kept_poses"], a["kept_poses"]);
  EXPECT_EQ(b["simulated"].get<size_t>(), 0u);  // no solver ran
  EXPECT_EQ(b["transferred"], a["transferred"]);
  // The tool's failed poses are the solver's failed poses, reported as missing files.
  EXPECT_EQ(failedIds(a), r.toolFailed);
  EXPECT_EQ(failedIds(b), r.toolFailed);
  for (const auto& f : b["failed"]) EXPECT_NE(f["reason"].get<std::string>().find("missing"), std::string::npos) << f;

  const Dataset da = readDataset(r.solverConfig.dataset), db = readDataset(r.externalConfig.dataset);
  ASSERT_EQ(da.poses.size(), db.poses.size());
  double worldMax = 0, preSkinMax = 0, mapMean = 0;
  for (size_t i = 0; i < da.poses.size(); ++i) {
    ASSERT_EQ(da.poses[i].id, db.poses[i].id);
    worldMax =
        std::max(worldMax, double((da.poses[i].gameMeshWorld - db.poses[i].gameMeshWorld).cwiseAbs().maxCoeff()));
    preSkinMax =
        std::max(preSkinMax, double((da.poses[i].gameMeshPreSkin - db.poses[i].gameMeshPreSkin).cwiseAbs().maxCoeff()));
    const auto& ma = da.poses[i].normalMap.xy;
    const auto& mb = db.poses[i].normalMap.xy;
    ASSERT_EQ(ma.size(), mb.size());
    double sum = 0;
    for (size_t t = 0; t < ma.size(); ++t) sum += std::abs(double(ma[t]) - double(mb[t]));
    mapMean = std::max(mapMean, sum / double(ma.size()));
  }
  const Model ma = loadModel(r.solverBake.model), mb = loadModel(r.externalBake.model);
  double modelMax = 0, modelMean = 0, ownMax = 0, ownMean = 0;
  for (const DatasetPose& p : da.poses) {
    const Points3f pa = predict(ma, p.pose);
    const Stats s = vertexError(pa, predict(mb, p.pose));
    modelMax = std::max(modelMax, s.maxMm);
    modelMean += s.meanMm / double(da.poses.size());
    const Stats own = vertexError(pa, p.gameMeshWorld);
    ownMax = std::max(ownMax, own.maxMm);
    ownMean += own.meanMm / double(da.poses.size());
  }
  std::printf(
      "OBJ round trip (6 decimals): dataset world shapes max %.3g m, pre-skin max %.3g m, normal maps worst "
      "pose mean %.3g; model predictions mean %.4f mm, max %.4f mm over %zu poses (the model's own error "
      "against its dataset: mean %.2f mm, max %.2f mm)\n",
      worldMax, preSkinMax, mapMean, modelMean, modelMax, da.poses.size(), ownMean, ownMax);
  RecordProperty("dataset_world_max_m", std::to_string(worldMax));
  RecordProperty("model_max_mm", std::to_string(modelMax));
  EXPECT_LT(worldMax, 5e-6);  // 0.5 um rounding, through smoothing (a few ulps of metre-scale floats)
  EXPECT_LT(preSkinMax, 5e-6);
  EXPECT_LT(mapMean, 1e-3);  // normal-map components in [-1, 1]
  // The two networks train on data a few micrometres apart with the same seed, but training is not a
  // smooth function of its data: a tiny net on 11 poses amplifies the rounding (measured: 0.27 mm max,
  // 0.024 mm mean with the 4 cm arm-root ring, against its own error of 140 mm max, 26 mm mean). What
  // the round trip must keep is the model: the two disagree by under 1 % of what either gets wrong.
  EXPECT_LT(modelMean, 0.01 * ownMean);
  EXPECT_LT(modelMax, 0.01 * ownMax);

  // The re-meshed garment (closest-point binding), with one result missing and one broken.
  {
    const nlohmann::json& p1 = r.remeshBake.part1;
    // The missing and the broken file: reported per pose with the file, left out; the rest kept.
    std::vector<uint32_t> want = r.toolFailed;
    want.push_back(r.removedPose);
    want.push_back(r.brokenPose);
    std::sort(want.begin(), want.end());
    EXPECT_EQ(failedIds(p1), want);
    for (const auto& f : p1["failed"]) {
      const uint32_t id = f["pose"].get<uint32_t>();
      const std::string reason = f["reason"].get<std::string>();
      const std::string file = externalPoseCandidates(r.tmp / "remeshed", id)[0].filename().string();
      EXPECT_NE(reason.find(file), std::string::npos) << reason;
      if (id == r.brokenPose) {
        EXPECT_NE(reason.find(":2: a vertex needs 3 coordinates"), std::string::npos) << reason;
      }
      if (id == r.removedPose) {
        EXPECT_NE(reason.find("missing"), std::string::npos) << reason;
      }
    }
    bool saidBound = false;
    for (const auto& l : r.remeshLog) saidBound |= l.find("re-meshed") != std::string::npos;
    EXPECT_TRUE(saidBound);

    // The bound shapes against the built-in bake's, pose by pose (game mesh, character space).
    const Dataset dc = readDataset(r.remeshConfig.dataset);
    ASSERT_EQ(dc.poses.size() + 2, da.poses.size());
    double mean = 0, worstMean = 0, max = 0;
    std::vector<double> all;
    for (const DatasetPose& c : dc.poses) {
      const auto it =
          std::find_if(da.poses.begin(), da.poses.end(), [&](const DatasetPose& x) { return x.id == c.id; });
      ASSERT_NE(it, da.poses.end());
      const Stats s = vertexError(c.gameMeshWorld, it->gameMeshWorld);
      for (Eigen::Index v = 0; v < c.gameMeshWorld.rows(); ++v)
        all.push_back(1000.0 * double((c.gameMeshWorld.row(v) - it->gameMeshWorld.row(v)).norm()));
      mean += s.meanMm / double(dc.poses.size());
      worstMean = std::max(worstMean, s.meanMm);
      max = std::max(max, s.maxMm);
    }
    std::sort(all.begin(), all.end());
    const double p99 = all[all.size() * 99 / 100];
    std::printf(
        "re-meshed garment bound by closest point: game mesh vs built-in, mean %.3f mm (worst pose %.3f mm), "
        "p99 %.3f mm, max %.3f mm over %zu poses\n",
        mean, worstMean, p99, max, dc.poses.size());
    RecordProperty("remesh_mean_mm", std::to_string(mean));
    RecordProperty("remesh_p99_mm", std::to_string(p99));
    RecordProperty("remesh_max_mm", std::to_string(max));
    // The re-meshed surface is a smoothed copy: its corners sit half the umbrella Laplacian off the
    // simulation vertices, so each vertex binds with a small normal offset that holds while the surface
    // keeps its curvature. Where a pose folds or creases the cloth (the seam between sleeve and torso),
    // the curvature changes and so does the offset: measured mean 0.43 mm, worst pose mean 0.79 mm,
    // p99 4.2 mm, max 13.9 mm (a strip of shoulder vertices in one pose). The bounds leave room for
    // float differences between machines, not for a worse binding.
    EXPECT_LT(mean, 0.6);
    EXPECT_LT(p99, 6.0);
    EXPECT_LT(max, 20.0);
    EXPECT_TRUE(fs::exists(r.remeshBake.model));
  }
}
