#pragma once
// CPU reference of the PCA reconstruction in shaders/deform.comp (the specification it conforms to):
// the pre-skinning shape of one instance,
//   x[3v + a] = mean[3v + a] + sum over k = 0, 1, ..., K-1 of basis(3v + a, k) * weights[k],
// accumulated in float, in that order, starting from the mean, one multiply and one add per term.
// At a quality level of k < K components (quality_levels.hpp) the sum stops at k - 1: the weights from k
// on count as 0 whatever they hold (k = 0: the mean shape).
#include <cstdint>
#include <span>

#include "swish/core/types.hpp"
#include "swish/model/model.hpp"

namespace swish::runtime {

// weights.size() must equal pca.components(); throws Error otherwise.
Points3f referencePcaReconstruct(const MeshPca& pca, std::span<const float> weights);
// The first `components` terms only (<= pca.components(), else Error); weights.size() as above.
Points3f referencePcaReconstruct(const MeshPca& pca, std::span<const float> weights, uint32_t components);

}  // namespace swish::runtime
