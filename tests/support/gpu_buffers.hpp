#pragma once
// GPU buffers for conformance tests: inputs that can be checked unchanged after a kernel ran, and
// outputs pre-filled with a marker and followed by guard words, to catch elements a kernel failed to
// write and writes past the end.
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "swish/gpu/buffer.hpp"
#include "swish/gpu/context.hpp"

namespace swish::test {

// An input buffer holding a copy of `data`; unchanged() compares the device contents with it.
class CheckedInput {
 public:
  template <class T>
  CheckedInput(gpu::Context& ctx, std::span<const T> data, const std::string& name)
      : bytes_(reinterpret_cast<const uint8_t*>(data.data()),
               reinterpret_cast<const uint8_t*>(data.data()) + data.size_bytes()),
        buffer_(ctx, bytes_.size(), gpu::MemoryKind::DeviceLocal, name) {
    buffer_.upload(ctx, bytes_.data(), bytes_.size());
  }
  VkDeviceAddress address() const { return buffer_.address(); }
  const gpu::Buffer& buffer() const { return buffer_; }  // for descriptor bindings (texel buffers)
  // "" when unchanged, else a description of the first changed byte.
  std::string unchanged(gpu::Context& ctx) const;

 private:
  std::vector<uint8_t> bytes_;
  gpu::Buffer buffer_;
};

// An output region of `bytes` filled with kUnwritten words, followed by kGuardWords guard words.
class GuardedOutput {
 public:
  static constexpr uint32_t kUnwritten = 0xDEADBEEFu;  // as float: -6.3e18, never a plausible output
  static constexpr uint32_t kGuard = 0xA5A5A5A5u;
  static constexpr size_t kGuardWords = 64;

  GuardedOutput(gpu::Context& ctx, size_t bytes, const std::string& name);
  VkDeviceAddress address() const { return buffer_.address(); }
  const gpu::Buffer& buffer() const { return buffer_; }  // for descriptor bindings (storage buffers)
  // The output region's contents (waits on a host barrier first).
  template <class T>
  std::vector<T> read(gpu::Context& ctx) const {
    std::vector<T> out(bytes_ / sizeof(T));
    readBytes(ctx, out.data());
    return out;
  }
  // "" when every guard word is intact, else which ones were overwritten.
  std::string guardsIntact(gpu::Context& ctx) const;

 private:
  void readBytes(gpu::Context& ctx, void* dst) const;
  size_t bytes_;
  gpu::Buffer buffer_;
};

}  // namespace swish::test
