#include "support/gpu_compare.hpp"

#include <cmath>
#include <sstream>

namespace swish::test {

::testing::AssertionResult matchesReference(const std::string& what, std::span<const float> gpu,
                                            std::span<const float> ref, const std::function<double(size_t)>& tolerance,
                                            CompareReport* report) {
  if (gpu.size() != ref.size())
    return ::testing::AssertionFailure() << what << ": " << gpu.size() << " GPU values, " << ref.size()
                                         << " reference values";
  CompareReport r;
  r.compared = gpu.size();
  size_t bad = 0;
  std::ostringstream first;
  for (size_t i = 0; i < gpu.size(); ++i) {
    const float g = gpu[i], c = ref[i];
    bool ok;
    if (std::isnan(c) || std::isnan(g)) {
      ok = std::isnan(c) && std::isnan(g);
    } else if (std::isinf(c) || std::isinf(g)) {
      ok = g == c;
    } else {
      const double err = std::abs(double(g) - double(c));
      r.maxAbsError = std::max(r.maxAbsError, err);
      ok = err <= tolerance(i);
    }
    if (!std::isfinite(c) && ok) ++r.nonFinite;
    if (!ok && bad++ < 5)
      first << "\n  [" << i << "] gpu " << g << " reference " << c << " (|diff| " << std::abs(double(g) - double(c))
            << ", allowed " << tolerance(i) << ")";
  }
  if (report) *report = r;
  if (bad == 0) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << what << ": " << bad << " of " << gpu.size() << " values differ"
                                       << first.str();
}

}  // namespace swish::test
