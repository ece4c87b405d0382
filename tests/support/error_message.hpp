#pragma once
// errorOf: the message of the swish::Error a piece of code throws, for tests that check what an error says.
//   EXPECT_NE(test::errorOf([&] { readObj(path); }).find("bad.obj:3"), std::string::npos);
#include <gtest/gtest.h>

#include <functional>
#include <source_location>
#include <string>

#include "swish/core/error.hpp"

namespace swish::test {

// Runs f and returns e.what() of the swish::Error it throws. If f returns normally, the test fails (the
// failure is reported at `where`: the caller's line, unless a wrapper passes its own caller's) and ""
// is returned. Other exceptions pass through.
inline std::string errorOf(const std::function<void()>& f,
                           std::source_location where = std::source_location::current()) {
  try {
    f();
  } catch (const swish::Error& e) {
    return e.what();
  }
  ADD_FAILURE_AT(where.file_name(), int(where.line())) << "expected a swish::Error, but nothing was thrown";
  return "";
}

}  // namespace swish::test
