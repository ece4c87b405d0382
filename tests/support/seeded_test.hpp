#pragma once
// The seed of a randomised test body: SWISH_TEST_SEED_SCOPE(seed, fallback) declares
// `const uint64_t seed` (SWISH_TEST_SEED from the environment, else `fallback`), prints it and adds it
// to every failure message of the enclosing scope, so that a failing run can be replayed.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>

#include "support/random_model.hpp"

#define SWISH_TEST_SEED_SCOPE(name, fallback)                       \
  const uint64_t name = ::swish::test::announcedTestSeed(fallback); \
  SCOPED_TRACE("seed " + std::to_string(name))
