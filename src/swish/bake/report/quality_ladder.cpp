#include "swish/bake/report/quality_ladder.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include "swish/bake/compression/normal_map_metrics.hpp"
#include "swish/bake/compression/vq_codebook.hpp"
#include "swish/bake/report/bake_evaluation.hpp"
#include "swish/core/error.hpp"
#include "swish/io/svg_plot.hpp"
#include "swish/runtime/frame_evaluator.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/nearest_code.hpp"
#include "swish/runtime/novelty_guard.hpp"
#include "swish/runtime/reference_pca.hpp"
#include "swish/runtime/reference_skinning.hpp"
#include "swish/runtime/theta.hpp"

namespace swish::bake {

namespace {

using runtime::QualityLadder;
using runtime::QualityLevel;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string f2(double v) {
  if (!std::isfinite(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}

bool hasMap(const NormalMapImage& m) { return m.width > 0 && m.height > 0 && !m.xy.empty(); }

// Per-level accumulation over the poses.
struct LevelErrors {
  std::vector<double> vertexMm;
  AngularErrorAccumulator angles;
  bool anglesMeasured = false;
};

}  // namespace

QualityLadder measureLadder(const Model& model, const std::vector<const DatasetPose*>& poses,
                            const QualityLadder& ladder, const std::string& measuredOn) {
  if (poses.empty()) throw Error("quality levels: no pose to measure the levels on");
  if (ladder.empty()) throw Error("quality levels: the ladder has no level");
  const size_t n = model.gameMesh.vertexCount();
  const int K = model.meshComponents();
  for (const QualityLevel& l : ladder.levels) {
    if (int(l.meshComponents) > K)
      throw Error("quality levels: level '" + l.name + "' reads " + std::to_string(l.meshComponents) +
                  " components, the model has " + std::to_string(K));
    if (l.normalMaps && model.normalMaps.empty())
      throw Error("quality levels: level '" + l.name + "' draws normal maps, the model has no normal-map database");
  }
  bool networkNeeded = false, mapsNeeded = false;
  for (const QualityLevel& l : ladder.levels) networkNeeded |= l.needsNetwork(), mapsNeeded |= l.normalMaps;

  // The run-time path of the bake's evaluation (bake_evaluation.cpp), step for step.
  const runtime::MlpEvaluator mlp(model);
  const runtime::NoveltyGuardEvaluator guard(model);
  std::unique_ptr<runtime::NearestCodeSearch> search;
  std::vector<NormalMapImage> decoded;
  if (mapsNeeded) {
    search = std::make_unique<runtime::NearestCodeSearch>(model.normalMaps.keys);
    for (uint32_t m = 0; m < model.normalMaps.mapCount(); ++m) decoded.push_back(decodeVqMap(model.normalMaps, m));
  }

  std::vector<LevelErrors> acc(ladder.size());
  for (LevelErrors& e : acc) e.vertexMm.reserve(n * poses.size());
  std::vector<float> lambda(size_t(mlp.outputSize()));
  for (const DatasetPose* p : poses) {
    const std::string pose = "quality levels: pose " + std::to_string(p->id);
    if (size_t(p->gameMeshWorld.rows()) != n)
      throw Error(pose + " has a game mesh of " + std::to_string(p->gameMeshWorld.rows()) + " vertices, the model's " +
                  std::to_string(n));
    if (p->pose.local.size() != model.skeleton.size())
      throw Error(pose + " has " + std::to_string(p->pose.local.size()) + " joint rotations, the model's skeleton " +
                  std::to_string(model.skeleton.size()) + " joints");
    const bool truthMap = hasMap(p->normalMap);
    if (truthMap && p->normalMap.xy.size() != size_t(p->normalMap.width) * p->normalMap.height * 2)
      throw Error(pose + ": its normal map holds " + std::to_string(p->normalMap.xy.size()) + " values for " +
                  std::to_string(p->normalMap.width) + "x" + std::to_string(p->normalMap.height) + " texels");
    if (truthMap && mapsNeeded &&
        (p->normalMap.width != model.normalMaps.width || p->normalMap.height != model.normalMaps.height))
      throw Error(pose + ": its normal map is " + std::to_string(p->normalMap.width) + "x" +
                  std::to_string(p->normalMap.height) + ", the model's database " +
                  std::to_string(model.normalMaps.width) + "x" + std::to_string(model.normalMaps.height));
    const auto mats = model.skeleton.skinningMatrices(p->pose);
    if (networkNeeded) {
      const std::vector<float> theta = runtime::computeTheta(model.inputJoints, model.rootGravity, p->pose.local);
      mlp.evaluate(theta, lambda);
      guard.apply(guard.measureOne(theta), std::span<float>(lambda.data(), size_t(K)));
    }
    // What the renderer shades with: the selected map decoded (maps), or the flat map (no maps).
    std::optional<AngularErrorAccumulator> mapped, flat;
    for (size_t li = 0; li < ladder.size(); ++li) {
      const QualityLevel& l = ladder.levels[li];
      // The first k weights (k = 0: the mean shape; lambda is not read then, nor computed).
      const Points3f shape = runtime::referencePcaReconstruct(
          model.meshPca, std::span<const float>(lambda.data(), size_t(K)), l.meshComponents);
      const Points3f predicted = runtime::referenceSkin(shape, model.gameMesh.skin, mats);
      for (size_t v = 0; v < n; ++v)
        acc[li].vertexMm.push_back(
            1000.0 * double((predicted.row(Eigen::Index(v)) - p->gameMeshWorld.row(Eigen::Index(v))).norm()));
      if (!truthMap) continue;
      if (l.normalMaps) {
        if (!mapped) {
          const std::span<const float> code(lambda.data() + K, size_t(model.normalCodeDims()));
          mapped.emplace();
          mapped->addMaps(p->normalMap, decoded[search->find(code).index]);
        }
        acc[li].angles.merge(*mapped);
      } else {
        if (!flat) {
          const NormalMapImage flatMap{p->normalMap.width, p->normalMap.height,
                                       std::vector<float>(p->normalMap.xy.size(), 0.f)};
          flat.emplace();
          flat->addMaps(p->normalMap, flatMap);
        }
        acc[li].angles.merge(*flat);
      }
      acc[li].anglesMeasured = true;
    }
  }
  QualityLadder out = ladder;
  out.poses = uint32_t(poses.size());
  out.measuredOn = measuredOn;
  for (size_t li = 0; li < out.size(); ++li) {
    QualityLevel& l = out.levels[li];
    const DistanceStats s = distanceStats(std::move(acc[li].vertexMm));
    l.vertexMeanMm = s.mean, l.vertexP95Mm = s.p95, l.vertexMaxMm = s.max;
    // A pose without a truth map leaves the whole level's normal error unmeasured (not a partial mean).
    bool allMaps = true;
    for (const DatasetPose* p : poses) allMaps &= hasMap(p->normalMap);
    l.normalMeanDeg = acc[li].anglesMeasured && allMaps ? acc[li].angles.stats().meanDegrees : kNaN;
  }
  return out;
}

QualityLadder measureLadder(const Model& model, const std::vector<const DatasetPose*>& poses,
                            const std::string& measuredOn) {
  return measureLadder(model, poses, runtime::ladderOf(model), measuredOn);
}

std::string cpuDescription() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) != 0) continue;
    const size_t colon = line.find(':');
    if (colon == std::string::npos) break;
    std::string name = line.substr(colon + 1);
    name.erase(0, name.find_first_not_of(" \t"));
    if (!name.empty()) return name + ", 1 thread";
  }
  return "unknown CPU, 1 thread";
}

void timeLadderCpu(const Model& model, const std::vector<const Pose*>& poses, QualityLadder& ladder,
                   const LadderTimingOptions& options) {
  if (poses.empty()) throw Error("quality levels: no pose to time the levels on");
  const uint32_t C = std::max<uint32_t>(1, options.characters);
  const uint32_t repeats = std::max<uint32_t>(1, options.repeats);
  // The run time's own CPU frame (runtime::FrameEvaluator) for C characters all at a level of each kind
  // that runs anything: the network alone (every weight; the CPU work does not depend on k), and the
  // network with the lookup and filter. The batches take the poses in turn, made before timing.
  QualityLevel network;
  network.meshComponents = uint32_t(model.meshComponents());
  network.normalMaps = false;
  QualityLevel mapped = network;
  mapped.normalMaps = true;
  const bool anyMaps = !model.normalMaps.empty() && std::any_of(ladder.levels.begin(), ladder.levels.end(),
                                                                [](const QualityLevel& l) { return l.normalMaps; });
  runtime::FrameEvaluator networkFrames(model, C), mappedFrames(model, C);
  for (uint32_t c = 0; c < C; ++c)
    networkFrames.setLevel(c, network), mappedFrames.setLevel(c, anyMaps ? mapped : network);
  std::vector<std::vector<Pose>> batches(poses.size());
  for (size_t b = 0; b < batches.size(); ++b)
    for (uint32_t c = 0; c < C; ++c) batches[b].push_back(*poses[(b * C + c) % poses.size()]);
  size_t next = 0;
  const auto batch = [&](runtime::FrameEvaluator& frames) {
    frames.evaluate(std::span<const Pose>(batches[next++ % batches.size()]), 1.f / 60.f);
  };
  using Clock = std::chrono::steady_clock;
  // The two kinds timed in alternation so that both see the same machine.
  std::vector<double> networkOnly, withMaps;
  for (uint32_t w = 0; w < options.warmup; ++w) batch(anyMaps ? mappedFrames : networkFrames);
  for (uint32_t r = 0; r < repeats; ++r) {
    auto t0 = Clock::now();
    batch(networkFrames);
    networkOnly.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / C);
    if (anyMaps) {
      t0 = Clock::now();
      batch(mappedFrames);
      withMaps.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / C);
    }
  }
  const auto median = [](std::vector<double> v) {
    if (v.empty()) return kNaN;
    std::nth_element(v.begin(), v.begin() + long(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  const double usNetwork = median(networkOnly), usMaps = median(withMaps);
  for (QualityLevel& l : ladder.levels)
    l.cpuUsPerCharacter = !l.needsNetwork() ? 0.0 : l.normalMaps ? usMaps : usNetwork;
  ladder.timedOn = cpuDescription() + ", MLP kernel " + runtime::toString(networkFrames.mlp().kernel()) +
                   ", batches of " + std::to_string(C) + " characters, median of " + std::to_string(repeats);
}

std::vector<std::string> ladderProblems(const QualityLadder& ladder) {
  std::vector<std::string> out;
  const auto check = [&](const char* what, const char* unit, double QualityLevel::*field) {
    for (size_t i = 0; i < ladder.size(); ++i)
      for (size_t j = i + 1; j < ladder.size(); ++j) {
        const QualityLevel &dear = ladder.levels[i], &cheap = ladder.levels[j];
        const double a = dear.*field, b = cheap.*field;
        if (!(std::isfinite(a) && std::isfinite(b)) || !(a > b)) continue;
        out.push_back("level '" + dear.name + "' (k " + std::to_string(dear.meshComponents) +
                      (dear.normalMaps ? ", maps" : ", no maps") + ") has a larger " + what + " (" + f2(a) + " " +
                      unit + ") than the cheaper level '" + cheap.name + "' (k " +
                      std::to_string(cheap.meshComponents) + (cheap.normalMaps ? ", maps" : ", no maps") + ": " +
                      f2(b) + " " + unit + ")");
      }
  };
  check("vertex mean error", "mm", &QualityLevel::vertexMeanMm);
  check("normal-map mean error", "deg", &QualityLevel::normalMeanDeg);
  return out;
}

QualityLadder withoutTimes(QualityLadder ladder) {
  for (QualityLevel& l : ladder.levels) l.cpuUsPerCharacter = l.gpuUsPerCharacter = kNaN;
  ladder.timedOn.clear();
  return ladder;
}

nlohmann::json ladderReportJson(const QualityLadder& ladder, const QualityLadder* subjects) {
  nlohmann::json j = runtime::toJson(ladder);
  j["problems"] = ladderProblems(ladder);
  if (subjects) {
    j["held_out_subjects"] = runtime::toJson(*subjects);
    j["held_out_subjects"]["problems"] = ladderProblems(*subjects);
  }
  return j;
}

std::string ladderMarkdown(const QualityLadder& ladder, const QualityLadder* subjects, const std::string& plotFile) {
  std::ostringstream md;
  md << "## Quality levels\n\n"
     << "Each level draws a character with the first k PCA weights the network predicts (the rest 0; k = 0: the "
        "mean shape skinned, no network) and, with maps, the selected database map VQ-decoded, else the mesh's own "
        "normals (the flat map). Errors against the truth on "
     << ladder.measuredOn << " (" << ladder.poses
     << " poses), through the run-time path (novelty guard included); normal-map error: the map the renderer shades "
        "with at that level against the truth's. CPU: Theta + MLP + guard (+ lookup and temporal filter with maps) "
        "per character, "
     << (ladder.timedOn.empty() ? std::string("not timed") : ladder.timedOn) << "; GPU time is not measured here.\n\n";
  md << "| level | k | maps | vertex mean mm | p95 | max | normal deg | CPU us/character |";
  if (subjects) md << " held-out subjects mean mm | p95 | normal deg |";
  md << "\n|---|---|---|---|---|---|---|---|";
  if (subjects) md << "---|---|---|";
  md << "\n";
  for (size_t i = 0; i < ladder.size(); ++i) {
    const QualityLevel& l = ladder.levels[i];
    md << "| " << l.name << " | " << l.meshComponents << " | " << (l.normalMaps ? "yes" : "no") << " | "
       << f2(l.vertexMeanMm) << " | " << f2(l.vertexP95Mm) << " | " << f2(l.vertexMaxMm) << " | " << f2(l.normalMeanDeg)
       << " | " << f2(l.cpuUsPerCharacter) << " |";
    if (subjects) {
      const bool same = i < subjects->size() && subjects->levels[i].name == l.name;
      md << " " << (same ? f2(subjects->levels[i].vertexMeanMm) : "-") << " | "
         << (same ? f2(subjects->levels[i].vertexP95Mm) : "-") << " | "
         << (same ? f2(subjects->levels[i].normalMeanDeg) : "-") << " |";
    }
    md << "\n";
  }
  const auto problems = [&](const QualityLadder& l, const std::string& on) {
    const std::vector<std::string> p = ladderProblems(l);
    if (p.empty()) {
      md << "\nThe ladder is monotone on " << on << ": no level has a larger error than a cheaper one.\n";
      return;
    }
    md << "\nNot monotone on " << on << " (the levels are kept in their order):\n\n";
    for (const std::string& s : p) md << "- " << s << "\n";
  };
  problems(ladder, "these poses");
  if (subjects) problems(*subjects, "the held-out subjects");
  if (!plotFile.empty()) md << "\n![error against CPU time per level](" << plotFile << ")\n";
  md << "\n";
  return md.str();
}

std::string ladderPlotSvg(const QualityLadder& ladder, const QualityLadder* subjects) {
  io::SvgPlot plot;
  plot.title = "Quality levels: vertex error against CPU time per character";
  plot.xLabel = "CPU time per character, us (network + guard + lookup)";
  plot.yLabel = "vertex error mean, mm";
  plot.yFromZero = true;
  plot.width = 720;
  // The levels in ladder order; the held-out subjects' levels at the same levels' times (the same work).
  const auto line = [&](const QualityLadder& l, const std::string& label, const std::string& colour) {
    io::PlotSeries s{label, {}, {}, colour};
    for (size_t i = 0; i < l.size() && i < ladder.size(); ++i)
      s.x.push_back(ladder.levels[i].cpuUsPerCharacter), s.y.push_back(l.levels[i].vertexMeanMm);
    return s;
  };
  plot.series.push_back(line(ladder, "levels in ladder order", "#888888"));
  if (subjects) plot.series.push_back(line(*subjects, "the same, held-out subjects", "#cccccc"));
  for (const QualityLevel& l : ladder.levels) {
    io::PlotSeries s{l.name + (l.normalMaps ? " (maps)" : ""), {l.cpuUsPerCharacter}, {l.vertexMeanMm}, ""};
    s.markers = true;
    plot.series.push_back(std::move(s));
  }
  return plot.render();
}

}  // namespace swish::bake
