// swish bake CONFIG: runs the bake described by a JSON recipe (bake/bake_config.hpp) end to end and
// writes <output>/<name>.swish and <output>/report/. The config is validated before any work. Part 1
// (character + clips -> simulated poses -> dataset) and part 2 (dataset -> model) are both resumable:
// interrupt it and run the same command again.
#include <cstdio>
#include <string>

#include "swish/bake/bake_config.hpp"
#include "swish/bake/bake_pipeline.hpp"
#include "swish/bake/dataset_builder.hpp"
#include "swish/bake/default_character.hpp"
#include "swish/model/atomic_write.hpp"
#include "swish/io/gltf_export.hpp"
#include "swish/command.hpp"

namespace {

swish::cli::RunFn setup(CLI::App& sub) {
  struct Opts {
    std::string config, defaultCharacterGlb;
    bool force = false, checkOnly = false;
    size_t checkSimulation = 0, checkPoses = 0;
    uint64_t seed = 1;
  };
  auto o = std::make_shared<Opts>();
  sub.add_option("config", o->config, "bake recipe (JSON)");
  sub.add_option("--write-default-character", o->defaultCharacterGlb,
                 "write the embedded default character (mannequin + jersey, skinned) to a .glb file to look at "
                 "or to use as a starting point, and stop (regenerates assets/default/default_character.glb)");
  sub.add_flag("--force", o->force, "re-train part 2 even when the model is current");
  sub.add_flag("--check", o->checkOnly, "validate the config and stop");
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
  return [o]() -> int {
    if (!o->defaultCharacterGlb.empty()) {
      swish::io::writeCharacterGlb(o->defaultCharacterGlb, swish::bake::makeDefaultCharacter());
      std::printf("wrote the default character to %s\n", o->defaultCharacterGlb.c_str());
      return 0;
    }
    if (o->config.empty()) {
      std::fprintf(stderr, "swish bake: give a bake recipe (JSON), e.g. 'swish bake assets/default/bake.json'; see --help\n");
      return 2;
    }
    const swish::bake::BakeConfig cfg = swish::bake::loadBakeConfig(o->config);
    if (o->checkSimulation > 0) {
      if (!cfg.part1) {
        std::fprintf(stderr, "swish bake --check-simulation: %s has no \"part1\" section to take poses from\n",
                     o->config.c_str());
        return 2;
      }
      swish::bake::DatasetBuildSettings s = *cfg.part1;
      if (o->checkPoses > 0) s.quality.poses = o->checkPoses;
      const nlohmann::json r = swish::bake::checkSimulation(s, o->checkSimulation, o->seed, [](const std::string& line) {
        std::fprintf(stderr, "%s\n", line.c_str());
        std::fflush(stderr);
      });
      std::filesystem::create_directories(cfg.reportDir());
      const std::filesystem::path file = cfg.reportDir() / "simulation_check.json";
      swish::writeTextFileAtomic(file, r.dump(2) + "\n");
      const nlohmann::json& sim = r.at("simulation");
      std::printf("simulated %zu poses: %zu failed (%.1f%%), %zu retried, %.2f s per pose per core, equilibrium residual "
                  "mean %.4f (max %.4f, tolerance %.4f)\n",
                  size_t(sim.value("poses", 0)), size_t(sim.value("failed", 0)), 100.0 * sim.value("failed_share", 0.0),
                  size_t(sim.value("retried_poses", 0)), sim.value("seconds_per_pose_per_core", 0.0),
                  sim.value("equilibrium_residual_mean", 0.0), sim.value("equilibrium_residual_max", 0.0),
                  sim.value("equilibrium_tolerance", 0.0));
      for (const auto& [why, v] : sim.at("failures_by_reason").items())
        std::printf("  %-12s %zu (%.1f%%)\n", why.c_str(), size_t(v.value("count", 0)), 100.0 * v.value("share", 0.0));
      if (sim.contains("quality")) {
        const nlohmann::json& q = sim.at("quality");
        std::printf("convergence (2x substeps, half the tolerance; %zu poses): %.2f mm mean, %.2f mm p95\n"
                    "noise (%.1f degree turns; %zu poses): %.2f mm mean, %.2f mm p95\n",
                    size_t(q.value("convergence_poses", 0)), q.value("convergence_mean_mm", 0.0),
                    q.value("convergence_p95_mm", 0.0), q.value("noise_turn_degrees", 0.0),
                    size_t(q.value("noise_poses", 0)), q.value("noise_mean_mm", 0.0), q.value("noise_p95_mm", 0.0));
      }
      std::printf("report: %s\n", file.string().c_str());
      return 0;
    }
    if (o->checkOnly) {
      std::printf("%s: valid; model -> %s, report -> %s\n", o->config.c_str(), cfg.modelPath().string().c_str(),
                  cfg.reportDir().string().c_str());
      if (cfg.part1)
        std::printf("part 1: %zu clip(s) -> %s poses%s -> simulation (%zu vertices, preset '%s') in %s -> dataset %s\n",
                    cfg.part1->clips.size(),
                    cfg.part1->targetPoses ? std::to_string(cfg.part1->targetPoses).c_str() : "thinned",
                    cfg.part1->includeRestPose ? " (+ the rest pose unless one is near it)" : "",
                    cfg.part1->simulationVertices, cfg.part1->simulation.material.name.c_str(),
                    cfg.simulationDir().string().c_str(), cfg.dataset.string().c_str());
      else
        std::printf("part 1: none (the dataset %s must exist)\n", cfg.dataset.string().c_str());
      return 0;
    }
    swish::bake::BakeRunOptions run;
    run.force = o->force;
    run.log = [](const std::string& line) {
      std::fprintf(stderr, "%s\n", line.c_str());
      std::fflush(stderr);
    };
    swish::bake::runBake(cfg, run);
    return 0;
  };
}

const swish::cli::CommandRegistration reg{"bake", "Bake a .swish model from a character and animation (JSON recipe)",
                                          setup};

}  // namespace
