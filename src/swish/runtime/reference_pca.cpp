#include "swish/runtime/reference_pca.hpp"

#include "swish/core/error.hpp"

namespace swish::runtime {

Points3f referencePcaReconstruct(const MeshPca& pca, std::span<const float> weights) {
  return referencePcaReconstruct(pca, weights, uint32_t(pca.components()));
}

Points3f referencePcaReconstruct(const MeshPca& pca, std::span<const float> weights, uint32_t components) {
  if (Eigen::Index(weights.size()) != pca.components())
    throw Error("PCA reconstruction: " + std::to_string(weights.size()) + " weights for " +
                std::to_string(pca.components()) + " components");
  if (Eigen::Index(components) > pca.components())
    throw Error("PCA reconstruction: " + std::to_string(components) + " leading components of " +
                std::to_string(pca.components()));
  const Eigen::Index k = Eigen::Index(components);
  const Eigen::Index n = pca.mean.size() / 3;
  Points3f out(n, 3);
  for (Eigen::Index row = 0; row < 3 * n; ++row) {
    float x = pca.mean[row];
    for (Eigen::Index c = 0; c < k; ++c) x += pca.basis(row, c) * weights[size_t(c)];
    out.data()[row] = x;  // row-major N x 3: element (v, a) lives at 3v + a, as in the mean
  }
  return out;
}

}  // namespace swish::runtime
