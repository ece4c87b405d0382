#include "swish/bake/compression/normal_map_pca.hpp"

#include <string>

#include "swish/core/error.hpp"

namespace swish::bake {

MatXf flattenNormalMaps(const std::vector<const NormalMapImage*>& maps) {
  if (maps.empty()) throw Error("normal-map PCA: no maps");
  const NormalMapImage& first = *maps.front();
  const size_t d = size_t(first.width) * first.height * 2;
  if (d == 0) throw Error("normal-map PCA: map 0 is empty");
  MatXf x(Eigen::Index(d), Eigen::Index(maps.size()));
  for (size_t i = 0; i < maps.size(); ++i) {
    const NormalMapImage& m = *maps[i];
    if (m.width != first.width || m.height != first.height || m.xy.size() != d)
      throw Error("normal-map PCA: map " + std::to_string(i) + " is " + std::to_string(m.width) + "x" +
                  std::to_string(m.height) + " (" + std::to_string(m.xy.size()) + " values), map 0 is " +
                  std::to_string(first.width) + "x" + std::to_string(first.height));
    x.col(Eigen::Index(i)) = Eigen::Map<const VecXf>(m.xy.data(), Eigen::Index(d));
  }
  return x;
}

NormalMapPca fitNormalMapPca(const std::vector<const NormalMapImage*>& maps, int codeDims, uint64_t seed) {
  if (codeDims < 1) throw Error("normal-map PCA: code dimensions must be >= 1, got " + std::to_string(codeDims));
  const MatXf x = flattenNormalMaps(maps);
  PcaOptions o;
  o.maxComponents = codeDims;
  o.seed = seed;
  NormalMapPca r;
  r.pca = fitPca(x, o, "normal-map PCA");
  r.codes = r.pca.project(x);
  return r;
}

VecXf normalMapCode(const PcaResult& pca, const NormalMapImage& map) {
  if (size_t(pca.mean.size()) != map.xy.size())
    throw Error("normal-map PCA: map of " + std::to_string(map.xy.size()) + " values, PCA expects " +
                std::to_string(pca.mean.size()));
  return pca.basis.transpose() * (Eigen::Map<const VecXf>(map.xy.data(), pca.mean.size()) - pca.mean);
}

}  // namespace swish::bake
