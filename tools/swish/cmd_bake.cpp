// swish bake CONFIG: runs the bake described by a JSON recipe (bake/bake_config.hpp) end to end and
// writes <output>/<name>.swish and <output>/report/. The config is validated before any work. Part 1
// (character + clips -> simulated poses -> dataset) and part 2 (dataset -> model) are both resumable:
// interrupt it and run the same command again. --export-poses writes part 1's poses for an external
// cloth tool instead (bake/pose_export.hpp); part1.simulation "source": "external" reads its results.
#include <cstdio>
#include <string>

#include "swish/bake/bake_config.hpp"
#include "swish/bake/bake_pipeline.hpp"
#include "swish/bake/default_character.hpp"
#include "swish/bake/pose_export.hpp"
#include "swish/core/error.hpp"
#include "swish/io/gltf_export.hpp"
#include "swish/command.hpp"

namespace {

swish::cli::RunFn setup(CLI::App& sub) {
  struct Opts {
    std::string config, defaultCharacterGlb, exportPoses;
    bool force = false, checkOnly = false;
  };
  auto o = std::make_shared<Opts>();
  sub.add_option("config", o->config, "bake recipe (JSON)");
  sub.add_option("--write-default-character", o->defaultCharacterGlb,
                 "write the embedded default character (mannequin + jersey, skinned) to a .glb file to look at "
                 "or to use as a starting point, and stop (regenerates assets/default/default_character.glb)");
  sub.add_flag("--force", o->force, "re-train part 2 even when the model is current");
  sub.add_flag("--check", o->checkOnly, "validate the config and stop");
  sub.add_option("--export-poses", o->exportPoses,
                 "write part 1's thinned poses for your own cloth tool to DIR (clip as BVH + glTF, target-frame "
                 "sidecar, body + garment OBJ, README for the artist) and stop")
      ->type_name("DIR");
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
      std::fprintf(stderr, "swish bake: give a bake recipe (JSON), e.g. 'swish bake assets/default/bake.json'; see --help\n");
      return 2;
    }
    const swish::bake::BakeConfig cfg = swish::bake::loadBakeConfig(o->config);
    if (!o->exportPoses.empty()) {
      if (!cfg.part1) throw swish::Error(o->config + ": --export-poses needs a \"part1\" section (the poses come from it)");
      const auto log = [](const std::string& l) { std::fprintf(stderr, "%s\n", l.c_str()); };
      const auto r = swish::bake::exportPoses(*cfg.part1, o->exportPoses, log);
      std::printf("exported %zu poses to %s; read %s/README.md\n", r.poses, o->exportPoses.c_str(), o->exportPoses.c_str());
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
