#include "swish/bake/report/subject_evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include "swish/core/error.hpp"
#include "swish/runtime/mlp_evaluator.hpp"
#include "swish/runtime/novelty_guard.hpp"
#include "swish/runtime/reference_pca.hpp"
#include "swish/runtime/reference_skinning.hpp"
#include "swish/runtime/theta.hpp"

namespace swish::bake {

namespace {
std::string f2(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}
// SubjectEvaluation::perSubject: per subject (origins' "subject", in name order), the mean error and the
// part of it that is the same in every frame (pre-skinning space).
std::vector<SubjectEvaluation::Subject> systematicErrors(const Model& model,
                                                         const std::vector<const DatasetPose*>& poses,
                                                         const nlohmann::json& origins) {
  struct Sum {
    Eigen::MatrixXd offset;       // per vertex, summed error vectors
    Eigen::VectorXd vertexError;  // per vertex, summed |error| over poses
    size_t poses = 0;
  };
  std::map<std::string, Sum> sums;
  for (const DatasetPose* p : poses) {
    const std::string subject = origins.is_array() && p->id < origins.size()
                                    ? origins[p->id].value("subject", std::string("?"))
                                    : std::string("?");
    const Points3f d = predictPreSkin(model, p->pose) - p->gameMeshPreSkin;
    Sum& s = sums[subject];
    if (s.poses == 0) s.offset = Eigen::MatrixXd::Zero(d.rows(), 3), s.vertexError = Eigen::VectorXd::Zero(d.rows());
    s.offset += d.cast<double>();
    s.vertexError += d.cast<double>().rowwise().norm();
    ++s.poses;
  }
  // Each game vertex's region: its strongest skinning joint (Model::validate keeps every joint index
  // inside the skeleton; predictPreSkin gives one row per game vertex).
  const size_t nv = model.gameMesh.vertexCount();
  std::vector<uint16_t> region(nv);
  std::vector<size_t> regionVertices(model.skeleton.size(), 0);
  for (size_t v = 0; v < nv; ++v) {
    region[v] = model.gameMesh.skin.strongestJoint(v);
    ++regionVertices[region[v]];
  }
  std::vector<SubjectEvaluation::Subject> out;
  for (const auto& [subject, s] : sums) {
    const double n = double(nv);
    const Eigen::VectorXd same = (s.offset / double(s.poses)).rowwise().norm();
    SubjectEvaluation::Subject x{
        subject, s.poses, 1000.0 * s.vertexError.sum() / (n * double(s.poses)), 1000.0 * same.sum() / n, {}};
    std::vector<double> err(regionVertices.size(), 0.0), sys(regionVertices.size(), 0.0);
    for (size_t v = 0; v < nv; ++v)
      err[region[v]] += s.vertexError[Eigen::Index(v)], sys[region[v]] += same[Eigen::Index(v)];
    for (size_t j = 0; j < regionVertices.size(); ++j)
      if (regionVertices[j] > 0)
        x.byJoint.push_back({model.skeleton.joints[j].name, regionVertices[j],
                             1000.0 * err[j] / (double(regionVertices[j]) * double(s.poses)),
                             1000.0 * sys[j] / double(regionVertices[j])});
    out.push_back(std::move(x));
  }
  return out;
}

}  // namespace

nlohmann::json evaluationSummary(const BakeEvaluation& ev) {
  nlohmann::json j = {{"poses", ev.poses},
                      {"vertex", toJson(ev.totalMm)},
                      {"baseline_rest_skinned", toJson(ev.restSkinnedMm)},
                      {"baseline_mean_skinned", toJson(ev.meanSkinnedMm)}};
  if (ev.hasNormalMaps) j["normal_total"] = toJson(ev.normalTotal);
  return j;
}

nlohmann::json SubjectEvaluation::toJson() const {
  nlohmann::json clips = nlohmann::json::array();
  for (const Clip& c : perClip) {
    nlohmann::json j = evaluationSummary(c.evaluation);
    j["clip"] = c.clip;
    j["subject"] = c.subject;
    clips.push_back(std::move(j));
  }
  nlohmann::json j = {{"subjects", subjects},
                      {"poses_planned", posesPlanned},
                      {"overall", evaluationSummary(overall)},
                      {"per_clip", clips}};
  nlohmann::json subj = nlohmann::json::array();
  for (const Subject& x : perSubject) {
    nlohmann::json regions = nlohmann::json::array();
    for (const Subject::Region& r : x.byJoint)
      regions.push_back({{"joint", r.joint},
                         {"vertices", r.vertices},
                         {"pre_skin_error_mm", r.errorMm},
                         {"systematic_mm", r.systematicMm}});
    subj.push_back({{"subject", x.subject},
                    {"poses", x.poses},
                    {"pre_skin_error_mm", x.errorMm},
                    {"systematic_mm", x.systematicMm},
                    {"by_joint", regions}});
  }
  j["per_subject_systematic"] = subj;
  if (overall.penetrationMeasured) j["penetration"] = penetrationJson(overall);
  if (!guard.rows.empty()) j["novelty_guard_study"] = guard.toJson();
  if (levels.measured()) j["quality_levels"] = runtime::toJson(levels);
  return j;
}

std::string GuardSetting::name() const {
  if (!clamp) return "no guard";
  if (!(end > start)) return "clamp to the training range";
  return "clamp + blend to the mean shape, novelty " + f2(start) + " .. " + f2(end);
}

nlohmann::json GuardStudy::toJson() const {
  nlohmann::json rs = nlohmann::json::array();
  for (const Row& r : rows)
    rs.push_back({{"clamp", r.setting.clamp},
                  {"blend_start", r.setting.start},
                  {"blend_end", r.setting.end},
                  {"held_out_subjects", bake::toJson(r.subjects)},
                  {"random_frames", bake::toJson(r.random)}});
  return {
      {"novelty_unit", unit},
      {"novelty_held_out_subjects",
       {{"mean", noveltySubjects.mean}, {"p95", noveltySubjects.p95}, {"max", noveltySubjects.max}}},
      {"novelty_random_frames", {{"mean", noveltyRandom.mean}, {"p95", noveltyRandom.p95}, {"max", noveltyRandom.max}}},
      {"error_novelty_correlation", errorNoveltyCorrelation},
      {"settings", rs},
      {"chosen", chosen}};
}

std::string GuardStudy::markdown() const {
  std::ostringstream md;
  md << "### The novelty guard, measured offline\n\n"
     << "Novelty, as the run time measures it: the distance of a pose's normalised network input to the nearest of "
        "the model's k-means centres of the training inputs, in units of the training poses' own such distance (p95, "
     << f2(unit) << " RMS per input). Held-out subjects: mean " << f2(noveltySubjects.mean) << ", p95 "
     << f2(noveltySubjects.p95) << ", max " << f2(noveltySubjects.max) << "; random held-out frames: mean "
     << f2(noveltyRandom.mean) << ", p95 " << f2(noveltyRandom.p95) << ", max " << f2(noveltyRandom.max)
     << ". Per-pose mean error against novelty on the held-out subjects: correlation " << f2(errorNoveltyCorrelation)
     << ".\n\n| guard | held-out subjects mean | p95 | max | random frames mean | p95 | max "
        "|\n|---|---|---|---|---|---|---|\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    md << "| " << r.setting.name() << (i == chosen ? " (lowest held-out mean)" : "") << " | " << f2(r.subjects.mean)
       << " | " << f2(r.subjects.p95) << " | " << f2(r.subjects.max) << " | " << f2(r.random.mean) << " | "
       << f2(r.random.p95) << " | " << f2(r.random.max) << " |\n";
  }
  md << "\nThe model carries the chosen row and the run time applies it (runtime/novelty_guard.hpp; `swish replay "
        "--no-guard` compares). The thresholds are chosen on the same held-out subjects they are reported on: an "
        "optimistic figure for the chosen row.\n\n";
  return md.str();
}

GuardStudy studyNoveltyGuard(const Model& model, const std::vector<const DatasetPose*>& trainingPoses,
                             const std::vector<const DatasetPose*>& subjects,
                             const std::vector<const DatasetPose*>& random) {
  GuardStudy g;
  if (trainingPoses.size() < 2 || model.noveltyGuard.empty()) return g;
  const runtime::MlpEvaluator mlp(model);
  const runtime::NoveltyGuardEvaluator measure(model);  // the run time's own novelty
  const NoveltyGuard& guard = model.noveltyGuard;
  const int K = model.meshComponents();
  const size_t n = model.gameMesh.vertexCount();
  g.unit = guard.unit;

  struct Prepared {
    const DatasetPose* pose;
    double novelty;
    std::vector<float> lambda;
    std::vector<Mat4f> mats;
  };
  auto prepare = [&](const std::vector<const DatasetPose*>& set) {
    std::vector<Prepared> out;
    for (const DatasetPose* p : set) {
      const std::vector<float> theta = runtime::computeTheta(model.inputJoints, model.rootGravity, p->pose.local);
      Prepared q{p, double(measure.measureOne(theta)), std::vector<float>(size_t(mlp.outputSize())),
                 model.skeleton.skinningMatrices(p->pose)};
      mlp.evaluate(theta, q.lambda);
      out.push_back(std::move(q));
    }
    return out;
  };
  const auto subj = prepare(subjects), rand = prepare(random);
  auto noveltyOf = [](const std::vector<Prepared>& v) {
    std::vector<double> x;
    for (const auto& p : v) x.push_back(p.novelty);
    return distanceStats(x);
  };
  g.noveltySubjects = noveltyOf(subj);
  g.noveltyRandom = noveltyOf(rand);

  // Vertex errors of a set under a setting; per-pose means for the correlation.
  auto errors = [&](const std::vector<Prepared>& set, const GuardSetting& s, std::vector<double>* perPose) {
    std::vector<double> all;
    all.reserve(set.size() * n);
    // The setting as a guard: the model's ranges when it clamps, its thresholds when it blends.
    NoveltyGuard g;
    if (s.clamp) g.weightMin = guard.weightMin, g.weightMax = guard.weightMax;
    if (s.clamp && s.end > s.start) g.blendStart = float(s.start), g.blendEnd = float(s.end);
    std::vector<float> w(static_cast<size_t>(K));
    for (const Prepared& p : set) {
      w.assign(p.lambda.begin(), p.lambda.begin() + K);
      runtime::applyNoveltyGuard(g, float(p.novelty), w);
      const Points3f shape =
          runtime::referenceSkin(runtime::referencePcaReconstruct(model.meshPca, w), model.gameMesh.skin, p.mats);
      double sum = 0.0;
      for (size_t v = 0; v < n; ++v) {
        const double e =
            1000.0 * double((shape.row(Eigen::Index(v)) - p.pose->gameMeshWorld.row(Eigen::Index(v))).norm());
        all.push_back(e);
        sum += e;
      }
      if (perPose) perPose->push_back(sum / double(n));
    }
    return distanceStats(std::move(all));
  };
  std::vector<GuardSetting> settings = {{false, 0, 0}, {true, 0, 0}};
  for (double start : {1.0, 1.5, 2.0, 3.0})
    for (double width : {1.0, 2.0, 4.0}) settings.push_back({true, start, start + width});
  std::vector<double> perPose;
  for (size_t i = 0; i < settings.size(); ++i) {
    g.rows.push_back(
        {settings[i], errors(subj, settings[i], i == 0 ? &perPose : nullptr), errors(rand, settings[i], nullptr)});
    if (g.rows.back().subjects.mean < g.rows[g.chosen].subjects.mean) g.chosen = i;
  }
  // Pearson correlation of per-pose error and novelty (held-out subjects, no guard).
  if (subj.size() > 2) {
    double mx = 0, my = 0;
    for (size_t i = 0; i < subj.size(); ++i) {
      mx += subj[i].novelty / double(subj.size());
      my += perPose[i] / double(subj.size());
    }
    double sxy = 0, sxx = 0, syy = 0;
    for (size_t i = 0; i < subj.size(); ++i) {
      sxy += (subj[i].novelty - mx) * (perPose[i] - my);
      sxx += (subj[i].novelty - mx) * (subj[i].novelty - mx);
      syy += (perPose[i] - my) * (perPose[i] - my);
    }
    g.errorNoveltyCorrelation = sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
  }
  return g;
}

std::string SubjectEvaluation::markdown(const BakeEvaluation& random) const {
  std::string names;
  for (const auto& s : subjects) names += (names.empty() ? "" : ", ") + s;
  std::ostringstream md;
  md << "## Held-out subjects\n\n"
     << "Subjects " << names << " were kept out of training: " << overall.poses << " of their frames (of "
     << posesPlanned << " planned, evenly spaced over " << perClip.size()
     << " clips) were simulated and evaluated through the same path. Beside each figure, the two baselines on the "
        "same poses: the garment's rest shape skinned (no correctives) and the PCA mean shape skinned.\n\n"
     << "| poses | n | vertex mean | p95 | max | rest skinned mean | p95 | mean skinned mean | p95 | normal deg |\n"
     << "|---|---|---|---|---|---|---|---|---|---|\n";
  auto row = [&](const std::string& name, const BakeEvaluation& e) {
    md << "| " << name << " | " << e.poses << " | " << f2(e.totalMm.mean) << " | " << f2(e.totalMm.p95) << " | "
       << f2(e.totalMm.max) << " | " << f2(e.restSkinnedMm.mean) << " | " << f2(e.restSkinnedMm.p95) << " | "
       << f2(e.meanSkinnedMm.mean) << " | " << f2(e.meanSkinnedMm.p95) << " | "
       << (e.hasNormalMaps ? f2(e.normalTotal.meanDegrees) : std::string("-")) << " |\n";
  };
  row("random held-out frames of training clips", random);
  row("held-out subjects " + names, overall);
  for (const Clip& c : perClip) row("  " + c.clip + " (subject " + c.subject + ")", c.evaluation);
  size_t worse = 0;
  for (const Clip& c : perClip) worse += c.evaluation.totalMm.p95 > c.evaluation.restSkinnedMm.p95;
  md << "\nHeld-out subjects over random frames (mean): "
     << (random.totalMm.mean > 0 ? f2(overall.totalMm.mean / random.totalMm.mean) + "x" : std::string("-"))
     << ". Clips whose p95 is worse than the rest shape skinned: " << worse << " of " << perClip.size() << ".\n\n";
  if (!perSubject.empty()) {
    md << "How much of each subject's error is the same in all its frames (pre-skinning space: the mean error "
          "vector per vertex over the subject's poses, against the mean error there). A large share is an offset "
          "the corpus does not teach (this subject's posture, or another fold the truth puts the garment in), "
          "not its motion:\n\n| subject | poses | error mm (pre-skinning) | the same in every frame mm | share |\n"
          "|---|---|---|---|---|\n";
    for (const Subject& x : perSubject)
      md << "| " << x.subject << " | " << x.poses << " | " << f2(x.errorMm) << " | " << f2(x.systematicMm) << " | "
         << (x.errorMm > 0 ? f2(100.0 * x.systematicMm / x.errorMm) + " %" : std::string("-")) << " |\n";
    md << "\n";
    // Where on the garment: every subject has the same regions, in the same order (one game mesh).
    const std::vector<Subject::Region>& first = perSubject.front().byJoint;
    md << "Where on the garment (each game vertex with its strongest skinning joint): error / the same in every "
          "frame, mm, pre-skinning space.\n\n| joint | vertices |";
    for (const Subject& x : perSubject) md << " subject " << x.subject << " |";
    md << "\n|---|---|";
    for (size_t i = 0; i < perSubject.size(); ++i) md << "---|";
    md << "\n";
    for (size_t r = 0; r < first.size(); ++r) {
      md << "| " << first[r].joint << " | " << first[r].vertices << " |";
      for (const Subject& x : perSubject)
        md << " " << f2(x.byJoint[r].errorMm) << " / " << f2(x.byJoint[r].systematicMm) << " |";
      md << "\n";
    }
    md << "\n";
  }
  if (!guard.rows.empty()) md << guard.markdown();
  return md.str();
}

SubjectEvaluation evaluateHeldOutSubjects(const BakeTrainOutput& out, const Dataset& training, const Dataset& holdout,
                                          const nlohmann::json& origins, const std::vector<std::string>& subjects,
                                          size_t posesPlanned) {
  if (holdout.poses.empty()) throw Error("held-out subjects: the dataset holds no pose (every simulation failed?)");
  if (holdout.character.garment.vertexCount() != out.model.gameMesh.vertexCount())
    throw Error("held-out subjects: the dataset's game mesh has " +
                std::to_string(holdout.character.garment.vertexCount()) + " vertices, the model's " +
                std::to_string(out.model.gameMesh.vertexCount()));
  const PcaResult* normalPca = out.model.normalMaps.mapCount() > 0 ? &out.normalPca.pca : nullptr;
  SubjectEvaluation r;
  r.subjects = subjects;
  r.posesPlanned = posesPlanned;
  std::vector<const DatasetPose*> all;
  std::map<std::string, std::pair<std::string, std::vector<const DatasetPose*>>> byClip;
  for (const DatasetPose& p : holdout.poses) {
    all.push_back(&p);
    std::string clip = "?", subject = "?";
    if (origins.is_array() && p.id < origins.size()) {
      clip = origins[p.id].value("clip", std::string("?"));
      subject = origins[p.id].value("subject", std::string("?"));
    }
    auto& slot = byClip[clip];
    slot.first = subject;
    slot.second.push_back(&p);
  }
  // The body too, as for the random held-out frames: penetration, and the error with the push-out.
  const Mesh* body = holdout.character.body.triangleCount() > 0 ? &holdout.character.body : nullptr;
  r.overall = evaluateModel(out.model, all, out.databaseMaps, normalPca, body);
  r.perSubject = systematicErrors(out.model, all, origins);
  for (const auto& [clip, entry] : byClip)
    r.perClip.push_back({clip, entry.first, evaluateModel(out.model, entry.second, out.databaseMaps, normalPca)});
  std::vector<const DatasetPose*> trained, random;
  for (uint32_t i : out.trainingPoses) trained.push_back(&training.poses[i]);
  for (uint32_t i : out.testPoses) random.push_back(&training.poses[i]);
  r.guard = studyNoveltyGuard(out.model, trained, all, random);
  if (out.ladder.measured())
    r.levels = withoutTimes(
        measureLadder(out.model, all, out.ladder, "the held-out subjects' frames (evenly spaced over their clips)"));
  return r;
}

}  // namespace swish::bake
