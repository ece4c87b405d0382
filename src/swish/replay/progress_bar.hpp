#pragma once
// A one-line progress bar with the time left, redrawn in place on stderr ("\r"), at most ~10 times a
// second. Silent when quiet. With ground truth (replay --truth-every) the line also counts the truth
// simulations, which then take nearly all the time: the bar and the time left follow them.
#include <chrono>
#include <cstdint>
#include <string>

namespace swish::replay {

class ProgressBar {
 public:
  ProgressBar(std::string label, bool quiet);
  void update(uint32_t done, uint32_t total);
  // Truth simulations done of those planned (total 0: none planned).
  void truth(uint32_t done, uint32_t total);
  void finish();

 private:
  void draw(bool force);

  std::string label_;
  bool quiet_;
  std::chrono::steady_clock::time_point start_, lastDraw_;
  bool drawn_ = false;
  uint32_t done_ = 0, total_ = 0, truthDone_ = 0, truthTotal_ = 0;
};

}  // namespace swish::replay
