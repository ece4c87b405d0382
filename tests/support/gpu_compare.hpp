#pragma once
// Element-wise comparison of GPU outputs with their CPU reference for the conformance suite.
// Non-finite values must sit in exactly the same places (NaN where NaN, the same infinity where an
// infinity); finite values must agree within the per-element tolerance the caller derives (and
// documents) for its kernel; tolerance 0 means bit-for-bit equal values.
#include <gtest/gtest.h>

#include <cstddef>
#include <functional>
#include <span>
#include <string>

namespace swish::test {

struct CompareReport {
  size_t compared = 0;
  size_t nonFinite = 0;    // elements that were (matching) NaN or Inf
  double maxAbsError = 0;  // over finite elements
};

::testing::AssertionResult matchesReference(const std::string& what, std::span<const float> gpu,
                                            std::span<const float> ref, const std::function<double(size_t)>& tolerance,
                                            CompareReport* report = nullptr);

}  // namespace swish::test
