#include "swish/gpu/vq_decode_pass.hpp"

#include "shaders/swish_layouts.h"
#include "swish/core/error.hpp"
#include "swish/gpu/context.hpp"

namespace swish::gpu {

VqDecodePass::VqDecodePass(Context& ctx)
    : pipeline_(ctx, "vq_decode.comp", {kWorkgroupSize}, sizeof(layout::VqDecodeParams)) {}

uint32_t VqDecodePass::record(VkCommandBuffer cmd, const Args& a) const {
  if (a.jobCount == 0 || a.width == 0 || a.height == 0) return 0;
  if (a.width % 4 || a.height % 4)
    throw Error("VQ decode: map size " + std::to_string(a.width) + "x" + std::to_string(a.height) +
                " is not a multiple of 4");
  layout::VqDecodeParams p;
  p.codebook = layout::Address::of(a.codebook);
  p.indices = layout::Address::of(a.indices);
  p.jobMaps = layout::Address::of(a.jobMaps);
  p.jobSlots = layout::Address::of(a.jobSlots);
  p.decodedOut = layout::Address::of(a.decodedOut);
  p.width = a.width;
  p.height = a.height;
  p.jobCount = a.jobCount;
  p.codebookSize = a.codebookSize;
  pipeline_.bind(cmd, &p, sizeof(p));
  vkCmdDispatch(cmd, groupCount(uint64_t(a.width) * a.height / 2, kWorkgroupSize), a.jobCount, 1);
  return 1;
}

}  // namespace swish::gpu
