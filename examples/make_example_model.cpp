// Test helper (not part of the example): writes the procedural stand-in jersey model on the default
// character's skeleton, so that CI can run examples/minimal_host without a baked model.
#include <cstdio>

#include "swish/bake/character/default_character.hpp"
#include "swish/model/model_file.hpp"
#include "swish/replay/procedural_model.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT.swish\n", argv[0]);
    return 2;
  }
  try {
    swish::replay::ProceduralModelSpec spec;
    spec.rings = 16;
    spec.segments = 24;
    spec.mapSize = 32;
    spec.normalMaps = 4;
    swish::saveModel(swish::replay::makeProceduralModel(swish::bake::makeDefaultCharacter().skeleton, spec), argv[1]);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "make_example_model: %s\n", e.what());
    return 1;
  }
}
