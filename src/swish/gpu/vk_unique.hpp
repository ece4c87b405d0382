#pragma once
// Move-only owner of one Vulkan handle: destroys it with the given function on destruction, unless it
// was adopted (not owned). Small on purpose: swish uses the C API (Vulkan-Hpp's raii header costs
// minutes of compile time per translation unit on small machines).
#include <functional>
#include <utility>

namespace swish::gpu {

template <class Handle>
class VkUnique {
 public:
  VkUnique() = default;
  VkUnique(Handle h, std::function<void(Handle)> destroy) : h_(h), destroy_(std::move(destroy)) {}
  VkUnique(const VkUnique&) = delete;
  VkUnique& operator=(const VkUnique&) = delete;
  VkUnique(VkUnique&& o) noexcept : h_(std::exchange(o.h_, Handle{})), destroy_(std::move(o.destroy_)) {}
  VkUnique& operator=(VkUnique&& o) noexcept {
    if (this != &o) {
      reset();
      h_ = std::exchange(o.h_, Handle{});
      destroy_ = std::move(o.destroy_);
    }
    return *this;
  }
  ~VkUnique() { reset(); }

  void reset() {
    if (h_ != Handle{} && destroy_) destroy_(h_);
    h_ = Handle{};
  }
  Handle get() const { return h_; }
  explicit operator bool() const { return h_ != Handle{}; }

 private:
  Handle h_{};
  std::function<void(Handle)> destroy_;
};

}  // namespace swish::gpu
