#include "swish/gpu/copy_vec4_pass.hpp"

#include "shaders/swish_layouts.h"

namespace swish::gpu {

CopyVec4Pass::CopyVec4Pass(Context& ctx)
    : pipeline_(ctx, "copy_vec4.comp", {kWorkgroupSize}, sizeof(layout::CopyVec4Params)) {}

void CopyVec4Pass::record(VkCommandBuffer cmd, VkDeviceAddress src, VkDeviceAddress dst, uint32_t count) const {
  layout::CopyVec4Params p;
  p.src = layout::Address::of(src);
  p.dst = layout::Address::of(dst);
  p.count = count;
  p.pad0 = 0;
  pipeline_.bind(cmd, &p, sizeof(p));
  vkCmdDispatch(cmd, groupCount(count, kWorkgroupSize), 1, 1);
}

}  // namespace swish::gpu
