// swish bake CONFIG: runs the bake described by a JSON recipe (bake/pipeline/bake_config.hpp) end to end and
// writes <output>/<name>.swish and <output>/report/. The config is validated before any work. Part 1
// (character + clips -> simulated poses -> dataset) and part 2 (dataset -> model) are both resumable:
// interrupt it and run the same command again. --export-poses writes part 1's poses for an external
// cloth tool instead (bake/cloth/pose_export.hpp); part1.simulation "source": "external" reads its results.
//
// With --slurm the same bake is submitted to a Slurm cluster instead (swish/cluster/slurm_bake.hpp):
// part 1's simulations as a job array, the dataset and part 2 as jobs that depend on it; --status
// prints its progress. The jobs run this program with --slurm-task, an option for the jobs only.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "swish/bake/character/default_character.hpp"
#include "swish/bake/cloth/pose_export.hpp"
#include "swish/bake/cloth/simulation_quality.hpp"
#include "swish/bake/pipeline/bake_config.hpp"
#include "swish/bake/pipeline/bake_pipeline.hpp"
#include "swish/bake/pipeline/part1_dataset.hpp"
#include "swish/cluster/pose_list_file.hpp"
#include "swish/cluster/slurm_bake.hpp"
#include "swish/command.hpp"
#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/io/gltf_export.hpp"

namespace {

swish::cli::RunFn setup(CLI::App& sub) {
  struct Opts {
    std::string config, defaultCharacterGlb, exportPoses;
    bool force = false, checkOnly = false, readClips = false;
    bool slurm = false, status = false;
    swish::cluster::SlurmSubmitOptions submit;
    std::string task, poseList;
    size_t shardSize = 0;
    size_t checkSimulation = 0, checkPoses = 0;
    uint64_t seed = 1;
  };
  auto o = std::make_shared<Opts>();
  sub.add_option(
      "config", o->config,
      "bake recipe (JSON; schema in src/swish/bake/pipeline/bake_config.hpp). part1.clips takes files, folders, globs "
      "(\"mocap/cmu/*.bvh\") and index files ({\"index\": \"mocap/cmu-daz/index.tsv\", \"joint_map\": "
      "\"map.json\", \"weights\": {..}}: src/swish/bake/poses/clip_list.hpp); part1.holdout keeps whole subjects "
      "out of training and reports the model on them (docs/baking.md)");
  sub.add_option("--write-default-character", o->defaultCharacterGlb,
                 "write the embedded default character (mannequin + jersey, skinned) to a .glb file to look at "
                 "or to use as a starting point, and stop (regenerates assets/default/default_character.glb)");
  sub.add_flag("--force", o->force, "re-train part 2 even when the model is current");
  sub.add_flag("--check", o->checkOnly, "validate the config and stop");
  sub.add_flag("--read-clips", o->readClips,
               "validate the config, read and retarget every clip of part1.clips onto the character (in parallel; "
               "a bad file stops it, named), print frames per subject and the time taken, and stop");

  const std::string cl = "Cluster (Slurm; docs/cluster.md)";
  sub.add_flag("--slurm", o->slurm,
               "submit the bake to the Slurm cluster that sbatch reaches instead of running it here: part 1's "
               "simulations as a job array of shards (resumable per pose), then the dataset and part 2 as jobs "
               "that depend on it (afterok). The work and output folders must be on a file system every node sees")
      ->group(cl);
  sub.add_flag("--status", o->status,
               "print the progress of the bake submitted with --slurm: poses done, failed, running, waiting, the "
               "jobs' states and the time left")
      ->group(cl);
  sub.add_option("--partition", o->submit.partition, "sbatch --partition for every job")->group(cl);
  sub.add_option("--account", o->submit.account, "sbatch --account for every job")->group(cl);
  sub.add_option("--time", o->submit.timeLimit,
                 "time limit of each array task (Slurm format, e.g. 30, 2:00:00, 1-00:00:00); the shards are sized "
                 "so a task needs at most 80 % of it")
      ->capture_default_str()
      ->group(cl);
  sub.add_option("--final-time", o->submit.finalTimeLimit,
                 "time limit of the dataset and part 2 jobs (default: the partition's)")
      ->group(cl);
  sub.add_option("--cpus-per-task", o->submit.cpusPerTask,
                 "CPUs of every job; an array task simulates that many poses at once")
      ->capture_default_str()
      ->check(CLI::Range(1, 4096))
      ->group(cl);
  sub.add_option("--max-running", o->submit.maxRunning, "array tasks running at once (--array=...%N); 0: no limit")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000000))
      ->group(cl);
  sub.add_option("--sbatch-arg", o->submit.sbatchArgs,
                 "one more argument for every sbatch call, e.g. --sbatch-arg=--qos=low (repeat for more)")
      ->group(cl);
  sub.add_option("--seconds-per-pose", o->submit.secondsPerPose,
                 "one pose's simulation on one core, for sizing the shards (default: the median of poses already "
                 "simulated, else one pose simulated and timed before submitting)")
      ->check(CLI::PositiveNumber)
      ->group(cl);
  sub.add_option("--poses-per-task", o->submit.posesPerTask,
                 "poses per array task, instead of sizing from the seconds per pose and the time limit")
      ->check(CLI::PositiveNumber)
      ->group(cl);
  sub.add_flag("--dry-run", o->submit.dryRun,
               "with --slurm: write the pose list and job scripts and print the sbatch lines, submit nothing")
      ->group(cl);
  sub.add_option("--swish-binary", o->submit.swishExecutable,
                 "the swish program the jobs run (default: this one; it must be at that path on every node)")
      ->group(cl);
  // Run by the jobs that --slurm submits, not by people: no group, so --help does not list them.
  sub.add_option("--slurm-task", o->task, "")->group("");
  sub.add_option("--pose-list", o->poseList, "")->group("");
  sub.add_option("--shard-size", o->shardSize, "")->group("");

  sub.add_option("--export-poses", o->exportPoses,
                 "write part 1's thinned poses for your own cloth tool to DIR (clip as BVH + glTF, target-frame "
                 "sidecar, body + garment OBJ, README for the artist) and stop")
      ->type_name("DIR");
  sub.add_option("--check-simulation", o->checkSimulation,
                 "simulate N of part 1's thinned poses (seeded sample) without building a dataset and report how far "
                 "the source simulation can be trusted: failures per reason, retried poses, seconds per pose per core, "
                 "equilibrium residuals, convergence (against twice the substeps and half the tolerance) and noise "
                 "(second differences over small turns of the pose); writes <report>/simulation_check.json")
      ->check(CLI::Range(size_t(1), size_t(100000)));
  sub.add_option("--check-poses", o->checkPoses,
                 "with --check-simulation: how many of the N poses get the convergence and noise solves (3 more "
                 "solves each; default: part1.simulation.check_poses, 6)");
  sub.add_option("--seed", o->seed, "with --check-simulation: the sample's seed (default 1)");
  sub.footer(
      "Bring your own simulation (Marvelous Designer, Houdini, Maya...):\n"
      "  1. swish bake recipe.json --export-poses poses/   writes poses/poses.bvh, poses.glb (the clip: per pose\n"
      "     A-pose -> pose, then a hold), poses.json (the frame to export per pose), body.obj, garment.obj and\n"
      "     README.md (what to simulate and send back).\n"
      "  2. Simulate each pose; save the garment at its target frame as poses/results/pose_<id>.obj (or .glb,\n"
      "     .gltf, .fbx; one multi-frame .glb/.fbx also works; a re-meshed garment adds results/rest.obj).\n"
      "  3. In the recipe: \"part1\": {\"simulation\": {\"source\": \"external\", \"path\": \"poses/results\"}}\n"
      "     (\"space\": \"world\" with \"units_per_metre\", \"up_axis\", \"origin\" for a tool's own scene),\n"
      "     then swish bake recipe.json as usual. Missing or broken results are reported per pose and left out.\n"
      "See docs/baking.md, 'Simulating in your own cloth tool'.");
  return [o]() -> int {
    if (!o->defaultCharacterGlb.empty()) {
      swish::io::writeCharacterGlb(o->defaultCharacterGlb, swish::bake::makeDefaultCharacter());
      std::printf("wrote the default character to %s\n", o->defaultCharacterGlb.c_str());
      return 0;
    }
    if (o->config.empty()) {
      std::fprintf(stderr,
                   "swish bake: give a bake recipe (JSON), e.g. 'swish bake assets/default/bake.json'; see --help\n");
      return 2;
    }
    const swish::bake::BakeConfig cfg = swish::bake::loadBakeConfig(o->config);
    if (!o->exportPoses.empty()) {
      if (!cfg.part1)
        throw swish::Error(o->config + ": --export-poses needs a \"part1\" section (the poses come from it)");
      const auto log = [](const std::string& l) { std::fprintf(stderr, "%s\n", l.c_str()); };
      // The bake's own pose list: part1.holdout's subjects are not among its training poses, so they are
      // not exported either (the results' pose-list digest must match what the bake then reads).
      const swish::bake::DatasetBuildSettings training = swish::bake::bakeTrainingSettings(cfg);
      if (training.clips.size() < cfg.part1->clips.size())
        log("export: the bake's training poses; the " +
            std::to_string(cfg.part1->clips.size() - training.clips.size()) +
            " clips of the held-out subjects (part1.holdout) are not exported");
      const auto r = swish::bake::exportPoses(training, o->exportPoses, log);
      std::printf("exported %zu poses to %s; read %s/README.md\n", r.poses, o->exportPoses.c_str(),
                  o->exportPoses.c_str());
      return 0;
    }
    if (o->checkSimulation > 0) {
      if (!cfg.part1) {
        std::fprintf(stderr, "swish bake --check-simulation: %s has no \"part1\" section to take poses from\n",
                     o->config.c_str());
        return 2;
      }
      swish::bake::DatasetBuildSettings s = *cfg.part1;
      if (o->checkPoses > 0) s.quality.poses = o->checkPoses;
      const nlohmann::json r =
          swish::bake::checkSimulation(s, o->checkSimulation, o->seed, [](const std::string& line) {
            std::fprintf(stderr, "%s\n", line.c_str());
            std::fflush(stderr);
          });
      std::filesystem::create_directories(cfg.reportDir());
      const std::filesystem::path file = cfg.reportDir() / "simulation_check.json";
      swish::writeTextFileAtomic(file, r.dump(2) + "\n");
      const nlohmann::json& sim = r.at("simulation");
      std::printf(
          "simulated %zu poses: %zu failed (%.1f%%), %zu retried, %.2f s per pose per core, equilibrium residual "
          "mean %.4f (max %.4f, tolerance %.4f)\n",
          size_t(sim.value("poses", 0)), size_t(sim.value("failed", 0)), 100.0 * sim.value("failed_share", 0.0),
          size_t(sim.value("retried_poses", 0)), sim.value("seconds_per_pose_per_core", 0.0),
          sim.value("equilibrium_residual_mean", 0.0), sim.value("equilibrium_residual_max", 0.0),
          sim.value("equilibrium_tolerance", 0.0));
      for (const auto& [why, v] : sim.at("failures_by_reason").items())
        std::printf("  %-12s %zu (%.1f%%)\n", why.c_str(), size_t(v.value("count", 0)), 100.0 * v.value("share", 0.0));
      if (sim.contains("quality")) {
        const nlohmann::json& q = sim.at("quality");
        std::printf(
            "convergence (2x substeps, half the tolerance; %zu poses): %.2f mm mean, %.2f mm p95\n"
            "noise (%.1f degree turns; %zu poses): %.2f mm mean, %.2f mm p95\n",
            size_t(q.value("convergence_poses", 0)), q.value("convergence_mean_mm", 0.0),
            q.value("convergence_p95_mm", 0.0), q.value("noise_turn_degrees", 0.0), size_t(q.value("noise_poses", 0)),
            q.value("noise_mean_mm", 0.0), q.value("noise_p95_mm", 0.0));
        std::printf("%s\n", swish::bake::simulationQualityDetail(q).c_str());
      }
      std::printf("report: %s\n", file.string().c_str());
      return 0;
    }
    if (o->checkOnly) {
      std::printf("%s: valid; model -> %s, report -> %s\n", o->config.c_str(), cfg.modelPath().string().c_str(),
                  cfg.reportDir().string().c_str());
      if (cfg.part1 && cfg.part1->external.enabled())
        std::printf("part 1: simulated shapes from the external tool's results in %s (%s space)\n",
                    cfg.part1->external.path.string().c_str(), cfg.part1->external.worldSpace ? "world" : "character");
      if (cfg.part1)
        std::printf("part 1: %zu clip(s) -> %s poses%s -> simulation (%zu vertices, preset '%s') in %s -> dataset %s\n",
                    cfg.part1->clips.size(),
                    cfg.part1->targetPoses ? std::to_string(cfg.part1->targetPoses).c_str() : "thinned",
                    cfg.part1->includeRestPose ? " (+ the rest pose unless one is near it)" : "",
                    cfg.part1->simulationVertices, cfg.part1->simulation.material.name.c_str(),
                    cfg.simulationDir().string().c_str(), cfg.dataset.string().c_str());
      if (cfg.part1 && !cfg.part1->holdoutSubjects.empty()) {
        const auto [training, heldOut] = swish::bake::splitHeldOutSubjects(*cfg.part1);
        std::string names;
        for (const auto& n : cfg.part1->holdoutSubjects) names += (names.empty() ? "" : ", ") + n;
        std::printf(
            "held-out subjects %s: %zu clip(s) -> %zu evenly spaced frames -> dataset %s (training: %zu clip(s))\n",
            names.c_str(), heldOut.clips.size(), cfg.part1->holdoutPoses, cfg.holdoutDatasetDir().string().c_str(),
            training.clips.size());
      }
      if (cfg.simulatesAnchorFrames())
        std::printf(
            "body anchors: about %zu frames as played of the training clips -> simulation in %s -> dataset %s\n",
            cfg.train.anchorFramesAsPlayed, cfg.anchorFramesSimulationDir().string().c_str(),
            cfg.anchorFramesDatasetDir().string().c_str());
      else if (cfg.train.anchorsAsPlayed)
        std::printf(
            "body anchors: fitted on the training poses nearest about %zu frames as played of the training clips\n",
            cfg.train.anchorFramesAsPlayed);
      if (!cfg.part1) std::printf("part 1: none (the dataset %s must exist)\n", cfg.dataset.string().c_str());
      return 0;
    }
    if (o->readClips) {
      if (!cfg.part1) throw swish::Error(o->config + ": --read-clips needs a \"part1\" section");
      const auto start = std::chrono::steady_clock::now();
      const swish::Character character = swish::bake::loadDatasetCharacter(*cfg.part1);
      std::vector<std::string> joints = cfg.part1->inputJoints;
      for (const auto& j : cfg.train.inputJoints)
        if (std::find(joints.begin(), joints.end(), j) == joints.end()) joints.push_back(j);
      swish::bake::importClips(cfg.part1->clips, character.skeleton, joints, cfg.part1->threads,
                               [](const std::string& line) { std::printf("%s\n", line.c_str()); });
      std::printf("read-clips: done in %.2f s (character included)\n",
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      return 0;
    }
    auto log = [](const std::string& line) {
      std::fprintf(stderr, "%s\n", line.c_str());
      std::fflush(stderr);
    };
    if (int(o->slurm) + int(o->status) + int(!o->task.empty()) > 1) {
      std::fprintf(stderr, "swish bake: give one of --slurm, --status and --slurm-task\n");
      return 2;
    }
    if (o->status) {
      std::fputs(swish::cluster::slurmBakeStatus(cfg).c_str(), stdout);
      return 0;
    }
    if (o->slurm) {
      o->submit.log = log;
      swish::cluster::submitSlurmBake(cfg, o->config, o->submit);
      return 0;
    }
    if (!o->task.empty()) {
      swish::cluster::runSlurmStage(cfg, o->task, swish::cluster::parseFingerprintHex(o->poseList), o->shardSize, log);
      return 0;
    }
    swish::bake::BakeRunOptions run;
    run.force = o->force;
    run.log = log;
    swish::bake::runBake(cfg, run);
    return 0;
  };
}

const swish::cli::CommandRegistration reg{"bake", "Bake a .swish model from a character and animation (JSON recipe)",
                                          setup};

}  // namespace
