#include "swish/truth_options.hpp"

namespace swish::cli {

void addTruthOverrideOptions(CLI::App& app, replay::TruthOptions& truth, const std::string& saidWhere) {
  app.add_option("--truth-vertices", truth.simulationVertices,
                 "truth simulation vertices instead of the bake's (0: the welded game mesh; coarser is faster, and "
                 "further from the bake's truth; " +
                     saidWhere + " says so)");
  app.add_option("--truth-substeps", truth.substeps, "truth simulation substeps instead of the bake's")
      ->check(CLI::Range(1, 1000));
  app.add_option("--truth-cover-mm", truth.coverBodyMm,
                 "the truth's game mesh kept this far over the body where the simulation covered it (in the "
                 "simulated pose, and again in the recorded one where limb clearance turned a limb), instead of the "
                 "bake's part1.transfer.cover_body_mm (0: off): what the cover does before any re-bake")
      ->check(CLI::Range(0.0, 20.0));
  app.add_option("--truth-limb-clearance-mm", truth.limbClearanceMm,
                 "the truth simulated with limbs turned this far out of the trunk instead of the bake's "
                 "part1.simulation.limb_clearance, in mm (0: each pose simulated as recorded)")
      ->check(CLI::Range(0.0, 100.0));
}

}  // namespace swish::cli
