#pragma once
// Choosing the normal-map database (paper 2.2): k-means over the maps' PCA codes; per cluster, the
// real map whose code is nearest the cluster centre joins the database, keyed by its own code (not
// the centre: the key must describe the map actually shown).
#include <cstdint>
#include <vector>

#include "swish/bake/compression/kmeans.hpp"

namespace swish::bake {

struct DatabaseSelection {
  std::vector<uint32_t> mapIndices;  // per database entry, the index of the chosen input map
  MatXf keys;                        // entries x C: codes of the chosen maps
  std::vector<uint32_t> clusterOf;   // per input map, its database entry
  double inertia = 0.0;              // k-means inertia over the codes
  int iterations = 0;
};

// codes: C x N (one column per map). Fewer than `count` entries when fewer distinct codes exist.
DatabaseSelection selectDatabaseMaps(const MatXf& codes, int count, uint64_t seed);

// Row of `keys` nearest `code` (squared Euclidean; ties -> lowest row): the runtime's lookup.
uint32_t nearestKey(const MatXf& keys, const VecXf& code);

}  // namespace swish::bake
