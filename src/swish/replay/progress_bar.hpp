#pragma once
// A one-line progress bar with the time left, redrawn in place on stderr ("\r"), at most ~10 times a
// second. Silent when quiet.
#include <chrono>
#include <cstdint>
#include <string>

namespace swish::replay {

class ProgressBar {
 public:
  ProgressBar(std::string label, bool quiet);
  void update(uint32_t done, uint32_t total);
  void finish();

 private:
  std::string label_;
  bool quiet_;
  std::chrono::steady_clock::time_point start_, lastDraw_;
  bool drawn_ = false;
};

}  // namespace swish::replay
