#include "swish/replay/progress_bar.hpp"

#include <cstdio>

namespace swish::replay {

ProgressBar::ProgressBar(std::string label, bool quiet)
    : label_(std::move(label)), quiet_(quiet), start_(std::chrono::steady_clock::now()), lastDraw_(start_) {}

void ProgressBar::update(uint32_t done, uint32_t total) {
  done_ = done, total_ = total;
  draw(done == total);
}

void ProgressBar::truth(uint32_t done, uint32_t total) {
  truthDone_ = done, truthTotal_ = total;
  draw(false);
}

void ProgressBar::draw(bool force) {
  if (quiet_ || total_ + truthTotal_ == 0) return;
  const auto now = std::chrono::steady_clock::now();
  if (drawn_ && !force && now - lastDraw_ < std::chrono::milliseconds(100)) return;
  lastDraw_ = now;
  drawn_ = true;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  // A truth simulation takes about a second, a frame milliseconds: with truth, its count is the progress.
  const double fraction = truthTotal_ > 0 ? double(truthDone_) / truthTotal_ : double(done_) / total_;
  const double left = fraction > 0 ? elapsed / fraction * (1.0 - fraction) : 0.0;
  const int width = 30, filled = int(double(width) * fraction);
  std::string bar(size_t(filled), '#');
  bar.resize(size_t(width), '.');
  char truth[64] = "";
  if (truthTotal_ > 0) std::snprintf(truth, sizeof truth, ", truth %u/%u poses", truthDone_, truthTotal_);
  std::fprintf(stderr, "\r%s [%s] %u/%u frames%s, %.1f s, about %.1f s left   ", label_.c_str(), bar.c_str(), done_,
               total_, truth, elapsed, left);
  std::fflush(stderr);
}

void ProgressBar::finish() {
  if (!quiet_ && drawn_) std::fprintf(stderr, "\n");
  drawn_ = false;
}

}  // namespace swish::replay
