#include "swish/bake/report/bake_report.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "swish/bake/report/bake_evaluation.hpp"
#include "swish/bake/report/quality_ladder.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/io/error_heat_map.hpp"
#include "swish/io/png.hpp"
#include "swish/io/svg_plot.hpp"
#include "swish/runtime/reference_vq_decode.hpp"

namespace swish::bake {

namespace {
std::string f2(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", v);
  return b;
}
std::string f3(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.3g", v);
  return b;
}
// RMS per-vertex distance (mm) left by K components: residual sum of squares over (samples x vertices).
std::vector<double> truncationRmsMm(const PcaResult& p) {
  const double vertices = double(p.mean.size()) / 3.0;
  std::vector<double> v;
  for (Eigen::Index k = 0; k < p.residualSquaredNorm.size(); ++k)
    v.push_back(1000.0 * std::sqrt(p.residualSquaredNorm[k] / std::max(1.0, double(p.sampleCount) * vertices)));
  return v;
}
std::vector<size_t> worstPoses(const BakeEvaluation& ev, size_t count) {
  std::vector<size_t> idx(ev.perPose.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  std::stable_sort(idx.begin(), idx.end(),
                   [&](size_t a, size_t b) { return ev.perPose[a].meanMm > ev.perPose[b].meanMm; });
  idx.resize(std::min(count, idx.size()));
  return idx;
}
}  // namespace

nlohmann::json bakeReportJson(const BakeTrainOutput& out, const Dataset& ds) {
  const auto& ev = out.evaluation;
  nlohmann::json r;
  r["character"] = ds.character.name;
  r["poses"] = {{"dataset", ds.poses.size()},
                {"training", out.trainingPoses.size()},
                {"held_out", out.testPoses.size()},
                {"synthesized", out.synthesizedPoses}};
  nlohmann::json pinned = nlohmann::json::array();  // dataset pose ids always trained on (the rest pose)
  for (uint32_t i : out.pinnedPoses) pinned.push_back(ds.poses[i].id);
  r["poses"]["always_trained"] = pinned;
  r["settings"] = out.metadata.value("settings", nlohmann::json::object());
  if (out.metadata.contains("distill")) r["distill"] = out.metadata["distill"];
  nlohmann::json perK = nlohmann::json::array();
  const auto rms = truncationRmsMm(out.meshPca);
  for (size_t k = 0; k < rms.size(); ++k)
    perK.push_back(
        {{"k", k}, {"explained_variance", out.meshPca.explainedVariance[Eigen::Index(k)]}, {"rms_mm", rms[k]}});
  r["mesh_pca"] = {{"components", out.meshPca.components()},
                   {"method", out.meshPca.randomized ? "randomized" : "exact"},
                   {"per_k", perK}};
  r["vertex_error_held_out"] = {{"total", toJson(ev.totalMm)},
                                {"pca_truncation", toJson(ev.truncationMm)},
                                {"regression", toJson(ev.regressionMm)},
                                {"baseline_rest_skinned", toJson(ev.restSkinnedMm)},
                                {"baseline_mean_skinned", toJson(ev.meanSkinnedMm)}};
  r["penetration_held_out"] = penetrationJson(ev);
  r["mlp"] = {{"best_epoch", out.regressor.bestEpoch},
              {"epochs_run", out.regressor.epochsRun},
              {"best_validation_loss", out.regressor.bestValidationLoss},
              {"seconds", out.regressor.seconds},
              {"activation", activationName(out.regressor.activation)}};
  if (ev.hasNormalMaps) {
    r["normal_maps"] = {{"code_dims", out.normalPca.codeDims()},
                        {"database_maps", out.model.normalMaps.mapCount()},
                        {"held_out",
                         {{"database", toJson(ev.normalDatabase)},
                          {"selection", toJson(ev.normalSelection)},
                          {"total_vq", toJson(ev.normalTotal)},
                          {"vq_added", toJson(ev.normalVqAdded)},
                          {"selection_agreement", ev.selectionAgreement}}},
                        {"compression",
                         {{"vq_vs_uncompressed", toJson(out.vqVsUncompressed)},
                          {"bc5_vs_uncompressed", toJson(out.bc5VsUncompressed)},
                          {"vq_bytes", out.vq.totalBytes()},
                          {"vq_codebook_bytes", out.vq.codebookBytes},
                          {"vq_index_bytes", out.vq.indexBytes},
                          {"bc5_bytes", out.bc5Bytes},
                          {"bc5_at_vq_memory",
                           {{"vs_uncompressed", toJson(out.bc5AtVqMemoryVsUncompressed)},
                            {"width", out.bc5AtVqMemoryWidth},
                            {"height", out.bc5AtVqMemoryHeight},
                            {"bytes", out.bc5AtVqMemoryBytes}}},
                          {"uncompressed_float_bytes", out.uncompressedBytes},
                          {"codebook_entries", out.vq.codebookEntries},
                          {"vq_training_seconds", out.vq.trainingSeconds},
                          {"vq_assignment_seconds", out.vq.assignmentSeconds}}}};
  }
  nlohmann::json stages = nlohmann::json::array();
  for (const auto& s : out.stages) stages.push_back({{"stage", s.stage}, {"seconds", s.seconds}});
  r["stage_seconds"] = stages;
  nlohmann::json worst = nlohmann::json::array();
  for (size_t i : worstPoses(ev, 8)) {
    const auto& p = ev.perPose[i];
    worst.push_back({{"pose", p.poseId},
                     {"mean_mm", p.meanMm},
                     {"max_mm", p.maxMm},
                     {"truncation_mean_mm", p.truncationMeanMm},
                     {"rest_skinned_mean_mm", p.restSkinnedMeanMm},
                     {"normal_deg", p.normalTotalDegrees},
                     {"selected_map", p.selectedMap},
                     {"ideal_map", p.idealMap}});
    if (ev.penetrationMeasured) {
      worst.back()["truth_inside_deepest_mm"] = p.truthPenetration.deepestMm;
      worst.back()["model_inside_deepest_mm"] = p.modelPenetration.deepestMm;
      if (ev.pushOut) worst.back()["pushed_inside_deepest_mm"] = p.pushedPenetration.deepestMm;
    }
  }
  r["worst_poses"] = worst;
  return r;
}

std::filesystem::path writeBakeReport(const BakeTrainOutput& out, const Dataset& ds, const std::filesystem::path& dir,
                                      size_t galleryPoses, const SubjectEvaluation* subjects) {
  std::filesystem::create_directories(dir);
  nlohmann::json r = bakeReportJson(out, ds);
  if (subjects) r["held_out_subjects"] = subjects->toJson();
  const bool levels = out.ladder.measured();
  const runtime::QualityLadder* subjectLevels = subjects && subjects->levels.measured() ? &subjects->levels : nullptr;
  if (levels) r["quality_levels"] = ladderReportJson(out.ladder, subjectLevels);
  writeTextFileAtomic(dir / "report.json", r.dump(2) + "\n");
  const auto& ev = out.evaluation;

  io::SvgPlot pk;
  pk.title = "Mesh PCA: truncation error against K (training poses)";
  pk.xLabel = "components K";
  pk.yLabel = "RMS vertex error, mm";
  pk.logY = true;
  io::PlotSeries rmsSeries{"RMS truncation error (mm)", {}, truncationRmsMm(out.meshPca), ""};
  for (size_t k = 0; k < rmsSeries.y.size(); ++k) rmsSeries.x.push_back(double(k));
  pk.series.push_back(rmsSeries);
  writeTextFileAtomic(dir / "error_vs_k.svg", pk.render());

  io::SvgPlot pc;
  pc.title = "MLP training curve (standardised, weighted MSE)";
  pc.xLabel = "epoch";
  pc.yLabel = "loss";
  pc.logY = true;
  io::PlotSeries tr{"training", {}, {}, ""}, va{"validation", {}, {}, ""};
  for (const auto& e : out.regressor.curve) {
    tr.x.push_back(e.epoch), tr.y.push_back(e.trainLoss);
    va.x.push_back(e.epoch), va.y.push_back(e.validationLoss);
  }
  pc.series = {tr, va};
  writeTextFileAtomic(dir / "training_curve.svg", pc.render());

  std::ostringstream md;
  md << "# Bake report: " << ds.character.name << "\n\n";
  md << ds.poses.size() << " poses: " << out.trainingPoses.size() << " for training, " << out.testPoses.size()
     << " held out (nothing is fitted on them)"
     << (out.pinnedPoses.empty() ? "" : "; the rest pose part 1 added is always among the training poses")
     << (out.synthesizedPoses == 0
             ? ""
             : "; " + std::to_string(out.synthesizedPoses) +
                   " of the training poses are synthesized (part1.synthesis), so the held-out poses are recorded "
                   "frames only")
     << ". All errors below are on the held-out poses, through the runtime path "
        "(Theta -> MLP -> PCA -> skinning; nearest code -> VQ decode).\n\n";
  md << "## Mesh\n\n| error (mm) | mean | p95 | max |\n|---|---|---|---|\n";
  auto row = [&](const char* name, const DistanceStats& s) {
    md << "| " << name << " | " << f2(s.mean) << " | " << f2(s.p95) << " | " << f2(s.max) << " |\n";
  };
  row("total", ev.totalMm);
  row("PCA truncation", ev.truncationMm);
  row("regression (MLP)", ev.regressionMm);
  row("baseline: rest shape skinned (no correctives)", ev.restSkinnedMm);
  row("baseline: PCA mean shape skinned", ev.meanSkinnedMm);
  md << "\nK = " << out.meshPca.components() << " components explain "
     << f2(100.0 * out.meshPca.explainedVariance[out.meshPca.components()]) << "% of the training variance ("
     << (out.meshPca.randomized ? "randomised" : "exact") << " SVD).\n\n![error against K](error_vs_k.svg)\n\n";
  if (out.metadata.contains("distill")) {
    const nlohmann::json& d = out.metadata["distill"];
    const nlohmann::json& t = d["teacher"];
    md << "**Distillation** (train.distill): the network also trained on " << d["poses"].get<size_t>()
       << " synthetic poses (" << d["blends"].get<size_t>() << " blends of a training pose and a near one, "
       << d["mixes"].get<size_t>()
       << " mixes of joints from different training poses) labelled by a kernel-ridge teacher (Gaussian kernel, "
          "width "
       << f2(t["width_scale"].get<double>()) << " x the median nearest distance, lambda " << t["lambda"].get<double>()
       << ", fitted on the training poses). On the held-out poses, mean pre-skinning vertex error through the mesh "
          "PCA: teacher "
       << f2(d["held_out_pre_skin_mean_mm"]["teacher"].get<double>()) << " mm, network "
       << f2(d["held_out_pre_skin_mean_mm"]["network"].get<double>()) << " mm";
    if (d.contains("held_out_subjects_pre_skin_mean_mm")) {
      const nlohmann::json& h = d["held_out_subjects_pre_skin_mean_mm"];
      md << "; on the held-out subjects: teacher " << f2(h["teacher"].get<double>()) << " mm, network "
         << f2(h["network"].get<double>()) << " mm";
    }
    md << ".\n\n";
  }
  if (subjects) md << subjects->markdown(ev);
  if (levels) {
    writeTextFileAtomic(dir / "quality_levels.svg", ladderPlotSvg(out.ladder, subjectLevels));
    md << ladderMarkdown(out.ladder, subjectLevels, "quality_levels.svg");
    if (subjects && !subjects->guard.rows.empty())
      md << "The levels are measured with the novelty guard of the mesh error above (the clamp); a blend the guard "
            "study above chooses is not in these figures.\n\n";
  }
  if (ev.penetrationMeasured) {
    const BakeEvaluation* subjectEv = subjects && subjects->overall.penetrationMeasured ? &subjects->overall : nullptr;
    md << "## Garment inside the body\n\nHeld-out poses against the character's posed body, truth and model side by "
          "side (whether the model or the truth puts the cloth inside)"
       << (subjectEv ? ", on the random held-out frames of the training clips and on the held-out subjects" : "")
       << ": vertices inside the body, those deeper than " << f2(kVisiblePenetrationMm)
       << " mm (visible), the deepest.\n\n"
       << "| poses | positions | poses with any inside | poses with visible | vertices inside | share | deepest mm | "
          "p95 of per-pose deepest mm |\n"
          "|---|---|---|---|---|---|---|---|\n";
    auto prow = [&](const char* set, const char* name, const PenetrationPool& p) {
      md << "| " << set << " | " << name << " | " << p.framesInside << " / " << p.frames << " | " << p.framesVisible
         << " | " << p.inside << " | " << f3(100.0 * p.share()) << " % | " << f2(p.deepestMm) << " | "
         << f2(p.deepestPercentileMm(0.95)) << " |\n";
    };
    auto rows = [&](const char* set, const BakeEvaluation& e) {
      prow(set, "truth (simulation, transferred + smoothed)", e.truthPenetration);
      prow(set, "model (before the push-out)", e.modelPenetration);
      if (e.pushOut) prow(set, "model after the run-time push-out", e.pushedPenetration);
    };
    rows("random held-out frames", ev);
    if (subjectEv) rows("held-out subjects", *subjectEv);
    md << "\n";
    auto pushedError = [&](const char* set, const BakeEvaluation& e) {
      md << "Vertex error with the push-out, " << set << ": mean " << f2(e.totalPushedMm.mean) << " mm, p95 "
         << f2(e.totalPushedMm.p95) << " mm, max " << f2(e.totalPushedMm.max) << " mm (without: " << f2(e.totalMm.mean)
         << " / " << f2(e.totalMm.p95) << " / " << f2(e.totalMm.max) << " mm).\n\n";
    };
    if (ev.pushOut) {
      pushedError("random held-out frames", ev);
      if (subjectEv && subjectEv->pushOut) pushedError("held-out subjects", *subjectEv);
    } else {
      md << "The model has no body anchors: no push-out at run time.\n\n";
    }
  }
  md << "## MLP\n\n"
     << activationName(out.regressor.activation) << ", best validation epoch " << out.regressor.bestEpoch << " of "
     << out.regressor.epochsRun << ", validation loss " << f3(out.regressor.bestValidationLoss) << ", trained in "
     << f2(out.regressor.seconds) << " s.\n\n![training curve](training_curve.svg)\n\n";
  if (ev.hasNormalMaps) {
    md << "## Normal maps\n\n| angular error (deg) | mean | p95 | max |\n|---|---|---|---|\n";
    auto arow = [&](const char* name, const AngularErrorStats& s) {
      md << "| " << name << " | " << f2(s.meanDegrees) << " | " << f2(s.p95Degrees) << " | " << f2(s.maxDegrees)
         << " |\n";
    };
    arow("database (ideal map, uncompressed)", ev.normalDatabase);
    arow("selection (predicted map, uncompressed)", ev.normalSelection);
    arow("total (predicted map, VQ-decoded)", ev.normalTotal);
    arow("VQ added (selected map vs its VQ decode)", ev.normalVqAdded);
    arow("all database maps: VQ vs uncompressed", out.vqVsUncompressed);
    arow("all database maps: BC5 vs uncompressed", out.bc5VsUncompressed);
    if (out.bc5AtVqMemoryWidth > 0) {
      const std::string name = "all database maps: BC5 at VQ's memory (" + std::to_string(out.bc5AtVqMemoryWidth) +
                               "x" + std::to_string(out.bc5AtVqMemoryHeight) + ", sampled up) vs uncompressed";
      arow(name.c_str(), out.bc5AtVqMemoryVsUncompressed);
    }
    md << "\nPredicted map = ideal map for " << f2(100.0 * ev.selectionAgreement) << "% of held-out poses.\n\n";
    md << "Memory for " << out.model.normalMaps.mapCount() << " maps of " << out.model.normalMaps.width << "x"
       << out.model.normalMaps.height << ": VQ " << f2(double(out.vq.totalBytes()) / 1048576.0) << " MiB ("
       << out.vq.codebookEntries << " codebook entries), BC5 " << f2(double(out.bc5Bytes) / 1048576.0) << " MiB"
       << (out.vq.totalBytes() ? " (" + f2(double(out.bc5Bytes) / double(out.vq.totalBytes())) + "x)" : "") << ".";
    if (out.bc5AtVqMemoryWidth > 0)
      md << " BC5 within the VQ's memory affords " << out.bc5AtVqMemoryWidth << "x" << out.bc5AtVqMemoryHeight
         << " maps (" << f2(double(out.bc5AtVqMemoryBytes) / 1048576.0) << " MiB): the equal-memory row above.";
    md << "\n\n";
  }
  md << "## Worst held-out poses\n\nThe gallery shows, per pose, the model (as the run time shows it"
     << (out.model.bodyAnchors.empty() ? "" : ", after the push-out")
     << ") beside the truth and an error heat map "
        "(per-vertex distance to the truth, 0 to 10 mm and beyond), then the truth's and the run time's normal "
        "maps.\n\n"
     << "| pose | mean mm | max mm | truncation mm | rest skinned mm | normal deg | gallery |\n"
        "|---|---|---|---|---|---|---|\n";
  std::filesystem::create_directories(dir / "gallery");
  std::vector<std::filesystem::path> galleryFiles;
  size_t shown = 0;
  for (size_t i : worstPoses(ev, 8)) {
    const auto& p = ev.perPose[i];
    std::string cell = "";
    const DatasetPose* pose = nullptr;
    for (const auto& dp : ds.poses)
      if (dp.id == p.poseId) pose = &dp;
    if (pose && shown < galleryPoses) {
      const std::string stem = "gallery/pose_" + std::to_string(p.poseId);
      const Points3f model = predictPositions(out.model, pose->pose, true);
      io::HeatMapFigure fig;
      fig.title = "pose " + std::to_string(p.poseId);
      fig.model = &model;
      fig.truth = &pose->gameMeshWorld;
      fig.triangles = &out.model.gameMesh.triangles;
      fig.panelWidth = 220, fig.panelHeight = 260;
      fig.scaleMm = 10.0;  // one scale for the whole gallery
      io::writePng(dir / (stem + "_heat.png"), io::heatMapFigure(fig));
      galleryFiles.push_back(dir / (stem + "_heat.png"));
      cell = "![model, truth, error](" + stem + "_heat.png)";
      if (ev.hasNormalMaps) {
        const std::string truthPng = stem + "_truth.png", runtimePng = stem + "_runtime.png";
        io::writePng(dir / truthPng,
                     io::encodeNormalMap(pose->normalMap.width, pose->normalMap.height, pose->normalMap.xy, 8));
        const auto dec = runtime::referenceVqDecode(out.model.normalMaps, p.selectedMap);
        std::vector<float> xy(dec.xy.size());
        for (size_t k = 0; k < xy.size(); ++k) xy[k] = runtime::snorm8ToFloat(dec.xy[k]);
        io::writePng(dir / runtimePng, io::encodeNormalMap(dec.width, dec.height, xy, 8));
        galleryFiles.push_back(dir / truthPng);
        galleryFiles.push_back(dir / runtimePng);
        cell += " ![truth](" + truthPng + ") ![runtime](" + runtimePng + ")";
      }
      ++shown;
    }
    md << "| " << p.poseId << " | " << f2(p.meanMm) << " | " << f2(p.maxMm) << " | " << f2(p.truncationMeanMm) << " | "
       << f2(p.restSkinnedMeanMm) << " | " << f2(p.normalTotalDegrees) << " | " << cell << " |\n";
  }
  // The worst poses of an earlier bake are other poses: their images must not linger in the gallery.
  constexpr std::string_view kGallerySuffixes[] = {"_truth.png", "_runtime.png", "_heat.png"};
  removeStaleOutputs(dir / "gallery", "pose_", kGallerySuffixes, galleryFiles);
  md << "\n## Time per stage\n\n| stage | seconds |\n|---|---|\n";
  for (const auto& s : out.stages) md << "| " << s.stage << " | " << f2(s.seconds) << " |\n";
  writeTextFileAtomic(dir / "report.md", md.str());
  return dir / "report.md";
}

}  // namespace swish::bake
