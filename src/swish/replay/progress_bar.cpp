#include "swish/replay/progress_bar.hpp"

#include <cstdio>

namespace swish::replay {

ProgressBar::ProgressBar(std::string label, bool quiet)
    : label_(std::move(label)), quiet_(quiet), start_(std::chrono::steady_clock::now()), lastDraw_(start_) {}

void ProgressBar::update(uint32_t done, uint32_t total) {
  if (quiet_ || total == 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && done < total && now - lastDraw_ < std::chrono::milliseconds(100)) return;
  lastDraw_ = now;
  drawn_ = true;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double left = done > 0 ? elapsed / done * (total - done) : 0.0;
  const int width = 30, filled = int(double(width) * done / total);
  std::string bar(size_t(filled), '#');
  bar.resize(size_t(width), '.');
  std::fprintf(stderr, "\r%s [%s] %u/%u frames, %.1f s, about %.1f s left   ", label_.c_str(), bar.c_str(), done, total,
               elapsed, left);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (!quiet_ && drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace swish::replay
