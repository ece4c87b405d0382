#include "support/gpu_buffers.hpp"

namespace swish::test {

namespace {
void hostBarrier(gpu::Context& ctx) {
  ctx.submitAndWait([](VkCommandBuffer cmd) { gpu::computeToHostBarrier(cmd); });
}
}  // namespace

std::string CheckedInput::unchanged(gpu::Context& ctx) const {
  hostBarrier(ctx);
  std::vector<uint8_t> now(bytes_.size());
  buffer_.download(ctx, now.data(), now.size());
  for (size_t i = 0; i < now.size(); ++i)
    if (now[i] != bytes_[i])
      return "input '" + buffer_.name() + "' changed at byte " + std::to_string(i) + " of " +
             std::to_string(now.size());
  return "";
}

GuardedOutput::GuardedOutput(gpu::Context& ctx, size_t bytes, const std::string& name)
    : bytes_((bytes + 3) / 4 * 4), buffer_(ctx, bytes_ + kGuardWords * 4, gpu::MemoryKind::DeviceLocal, name) {
  std::vector<uint32_t> init(bytes_ / 4 + kGuardWords, kUnwritten);
  std::fill(init.end() - kGuardWords, init.end(), kGuard);
  buffer_.upload(ctx, init.data(), init.size() * 4);
}

void GuardedOutput::readBytes(gpu::Context& ctx, void* dst) const {
  hostBarrier(ctx);
  buffer_.download(ctx, dst, bytes_);
}

std::string GuardedOutput::guardsIntact(gpu::Context& ctx) const {
  hostBarrier(ctx);
  std::vector<uint32_t> g(kGuardWords);
  buffer_.download(ctx, g.data(), kGuardWords * 4, bytes_);
  std::string bad;
  for (size_t i = 0; i < g.size(); ++i)
    if (g[i] != kGuard) bad += (bad.empty() ? "" : ", ") + std::to_string(i);
  return bad.empty() ? "" : "guard words after '" + buffer_.name() + "' overwritten: " + bad;
}

}  // namespace swish::test
