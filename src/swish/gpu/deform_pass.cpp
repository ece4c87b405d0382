#include "swish/gpu/deform_pass.hpp"

#include <algorithm>
#include <cstring>
#include <vector>

#include "shaders/swish_layouts.h"
#include "swish/core/error.hpp"
#include "swish/core/mesh.hpp"
#include "swish/gpu/buffer.hpp"
#include "swish/gpu/context.hpp"

namespace swish::gpu {

void DeformPass::packWeights(const float* w, uint32_t instances, uint32_t k, float* out) {
  const uint32_t k4 = paddedComponents(k);
  for (uint32_t i = 0; i < instances; ++i) {
    std::copy(w + size_t(i) * k, w + size_t(i + 1) * k, out + size_t(i) * k4);
    std::fill(out + size_t(i) * k4 + k, out + size_t(i + 1) * k4, 0.f);
  }
}

void DeformPass::packWeights(const float* w, uint32_t instances, uint32_t k, std::span<const uint32_t> components,
                             float* out) {
  if (components.empty()) return packWeights(w, instances, k, out);
  if (components.size() != instances)
    throw Error("deform pass: " + std::to_string(components.size()) + " per-instance component counts for " +
                std::to_string(instances) + " instances");
  const uint32_t k4 = paddedComponents(k);
  for (uint32_t i = 0; i < instances; ++i) {
    const uint32_t ki = components[i];
    if (ki > k)
      throw Error("deform pass: instance " + std::to_string(i) + " reads " + std::to_string(ki) +
                  " mesh components; the model has " + std::to_string(k));
    std::copy(w + size_t(i) * k, w + size_t(i) * k + ki, out + size_t(i) * k4);
    std::fill(out + size_t(i) * k4 + ki, out + size_t(i + 1) * k4, 0.f);
  }
}

std::vector<uint32_t> DeformPass::bandsOf(uint32_t k) {
  const uint32_t g = groupsOf(k);
  std::vector<uint32_t> bands;
  for (const uint32_t b : {g, (g + 1) / 2, (g + 3) / 4, (g + 7) / 8, 0u})
    if (bands.empty() || b < bands.back()) bands.push_back(b);
  return bands;
}

DeformPass::Levels DeformPass::packLevels(std::span<const uint32_t> components, uint32_t k) {
  const std::vector<uint32_t> bands = bandsOf(k);
  Levels l;
  std::vector<std::vector<uint32_t>> members(bands.size());
  for (size_t i = 0; i < components.size(); ++i) {
    if (components[i] > k)
      throw Error("deform pass: instance " + std::to_string(i) + " reads " + std::to_string(components[i]) +
                  " mesh components; the model has " + std::to_string(k));
    size_t b = 0;  // the narrowest band that holds the instance's groups
    while (b + 1 < bands.size() && bands[b + 1] >= groupsOf(components[i])) ++b;
    members[b].push_back(uint32_t(i));
    l.groups.push_back(bands[b]);
    l.maxGroups = std::max(l.maxGroups, bands[b]);
  }
  for (size_t b = 0; b < bands.size(); ++b) {
    l.order.insert(l.order.end(), members[b].begin(), members[b].end());
    if (b < l.bandEnd.size()) l.bandEnd[b] = uint32_t(l.order.size());
  }
  for (size_t b = bands.size(); b < l.bandEnd.size(); ++b) l.bandEnd[b] = uint32_t(l.order.size());
  return l;
}

void DeformPass::packSkinMatrices(const Mat4f* m, size_t count, float* out) {
  for (size_t i = 0; i < count; ++i)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out[12 * i + 4 * r + c] = m[i](r, c);
}

static_assert(SWISH_MAX_ANCHOR_SLOTS == kMaxAnchorSlots, "shaders/swish_layouts.h: body anchor sets");
static_assert(SWISH_MAX_ANCHOR_EXTRA_JOINTS == kMaxAnchorSlots * kAnchorInfluences,
              "shaders/swish_layouts.h: push-out table joints");

namespace {

// Vertex v's push-out joint table beyond its skin joints (DeformPass::anchorExtraJointsOf), and the
// table slot of each weighed anchor influence (slot[set][influence]; -1 for a zero weight).
struct AnchorTable {
  std::vector<uint32_t> extra;
  std::array<std::array<int, kAnchorInfluences>, kMaxAnchorSlots> slot{};
};
AnchorTable anchorTable(const BodyAnchors& anchors, const SkinWeights& skin, size_t v) {
  AnchorTable t;
  const size_t influences = size_t(skin.influences);
  for (uint32_t s = 0; s < anchors.slots(); ++s) {
    const BodyAnchor& a = anchors.slot(s)[v];
    for (size_t i = 0; i < size_t(kAnchorInfluences); ++i) {
      int& at = t.slot[s][i];
      at = -1;
      if (a.weights[i] == 0.f) continue;
      for (size_t k = 0; k < influences && at < 0; ++k)
        if (skin.joints[v * influences + k] == a.joints[i]) at = int(k);
      for (size_t e = 0; e < t.extra.size() && at < 0; ++e)
        if (t.extra[e] == a.joints[i]) at = int(influences + e);
      if (at < 0) {
        at = int(influences + t.extra.size());
        t.extra.push_back(a.joints[i]);
      }
    }
  }
  return t;
}

void checkAnchorsMatchSkin(const BodyAnchors& anchors, const SkinWeights& skin) {
  for (uint32_t s = 0; s < anchors.slots(); ++s)
    if (anchors.slot(s).size() != skin.vertexCount() || skin.joints.size() != skin.weights.size())
      throw Error("body anchors: the " + std::string(anchorSlotName(s)) + " set has " +
                  std::to_string(anchors.slot(s).size()) + " anchors for " + std::to_string(skin.vertexCount()) +
                  " skinned vertices");
}

}  // namespace

uint32_t DeformPass::anchorExtraJointsOf(const BodyAnchors& anchors, const SkinWeights& skin) {
  checkAnchorsMatchSkin(anchors, skin);
  size_t most = 0;
  for (size_t v = 0; !anchors.empty() && v < anchors.anchors.size(); ++v)
    most = std::max(most, anchorTable(anchors, skin, v).extra.size());
  return uint32_t(most);
}

bool DeformPass::anchorsSkipZeroWeights(uint32_t extraJoints, const SkinWeights& skin) {
  return extraJoints > 0 || std::any_of(skin.weights.begin(), skin.weights.end(), [](float w) { return w == 0.f; });
}

std::vector<uint32_t> DeformPass::packAnchors(const BodyAnchors& anchors, const SkinWeights& skin,
                                              uint32_t jointCount) {
  const uint32_t extra = anchorExtraJointsOf(anchors, skin), influences = uint32_t(skin.influences);
  const size_t n = anchors.anchors.size(), extraWords = 4 * size_t((extra + 3) / 4),
               setWords = 4 * size_t(1 + (influences + extra + 3) / 4);
  std::vector<uint32_t> out(4 * anchorTexelsOf(n, influences, extra, anchors.slots()), 0u);
  auto put = [&](size_t at, float f) { std::memcpy(&out[at], &f, 4); };
  for (size_t v = 0; v < n; ++v) {
    for (uint32_t s = 0; s < anchors.slots(); ++s)
      for (const uint16_t j : anchors.slot(s)[v].joints)
        if (j >= jointCount)
          throw Error("body anchor of vertex " + std::to_string(v) + ": joint " + std::to_string(j) +
                      " is not in the skeleton of " + std::to_string(jointCount) + " joints");
    const AnchorTable t = anchorTable(anchors, skin, v);
    std::copy(t.extra.begin(), t.extra.end(), out.begin() + std::ptrdiff_t(v * extraWords));
    for (uint32_t s = 0; s < anchors.slots(); ++s) {
      const BodyAnchor& a = anchors.slot(s)[v];
      const size_t o = n * extraWords + (s * n + v) * setWords;
      const Vec3f centre = a.present() ? a.centre() : Vec3f::Zero();
      for (int k = 0; k < 3; ++k) put(o + size_t(k), centre[k]);
      put(o + 3, a.present() ? a.reach() : 0.f);
      std::vector<float> w(influences + extra, 0.f);
      for (size_t i = 0; i < size_t(kAnchorInfluences); ++i)
        if (t.slot[s][i] >= 0) w[size_t(t.slot[s][i])] += a.weights[i];
      for (size_t i = 0; i < w.size(); ++i) put(o + 4 + i, w[i]);
    }
  }
  return out;
}

DeformPass::DeformPass(Context& ctx, uint32_t k, uint32_t influences, bool applySkinning, uint64_t basisFloats,
                       uint32_t anchorSets, uint32_t anchorExtraJoints, bool anchorZeroSkip)
    : basisTexels_(basisFloats > 0 &&
                   std::max(basisFloats, anchorTexelsOf(basisFloats / (3 * uint64_t(std::max(k, 1u))), influences,
                                                        anchorExtraJoints, anchorSets)) <=
                       ctx.properties().limits.maxTexelBufferElements),
      meshComponents_(k),
      anchorSets_(anchorSets),
      anchorExtraJoints_(anchorExtraJoints) {
  if (k < 1 || k > SWISH_MAX_MESH_COMPONENTS)
    throw Error("deform pass: " + std::to_string(k) + " mesh components; the kernel supports 1.." +
                std::to_string(SWISH_MAX_MESH_COMPONENTS));
  if (influences < 1 || influences > uint32_t(kMaxInfluences))
    throw Error("deform pass: " + std::to_string(influences) + " skin influences; supported: 1..8");
  if (anchorSets > kMaxAnchorSlots)
    throw Error("deform pass: " + std::to_string(anchorSets) + " body anchor sets; supported: 0.." +
                std::to_string(kMaxAnchorSlots));
  if (anchorExtraJoints > SWISH_MAX_ANCHOR_EXTRA_JOINTS)
    throw Error("deform pass: " + std::to_string(anchorExtraJoints) +
                " push-out table joints beyond the skin's; supported: 0.." +
                std::to_string(SWISH_MAX_ANCHOR_EXTRA_JOINTS));
  if (anchorExtraJoints > 0 && anchorSets == 0)
    throw Error("deform pass: push-out table joints without anchor sets (a pass without the push-out takes none)");
  if (anchorSets > 0 && !applySkinning)
    throw Error("deform pass: the push-out follows the skinning; a pass without skinning takes no anchor sets");
  inputsLayout_ = DescriptorLayout(
      ctx, std::vector<VkDescriptorType>(basisTexels_ ? 4 : 2, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER));
  bands_ = bandsOf(k);
  const char* shader = basisTexels_ ? "deform_basis_texels.comp" : "deform.comp";
  // Specialisation constants: workgroup size, K, influences, skinning, bands and their groups (band 0: K),
  // anchor sets, the push-out table's extra joints (none in the pipelines without the push-out).
  const std::array<uint32_t, 2> setsOf = {0u, anchorSets};  // pipelines [0] and, with anchor sets, [1]
  for (size_t i = 0; i < (anchorSets > 0 ? 2u : 1u); ++i) {
    const uint32_t sets = setsOf[i];
    std::vector<uint32_t> spec = {kWorkgroupSize,
                                  k,
                                  influences,
                                  applySkinning ? 1u : 0u,
                                  1u,
                                  0u,
                                  0u,
                                  0u,
                                  0u,
                                  sets,
                                  sets > 0 ? anchorExtraJoints : 0u,
                                  anchorZeroSkip ? 1u : 0u};
    pipeline_[i] = ComputePipeline(ctx, shader, spec, sizeof(layout::DeformParams), inputsLayout_.get());
    spec[4] = uint32_t(bands_.size());
    for (size_t b = 1; b < bands_.size(); ++b) spec[4 + b] = bands_[b];
    bandedPipeline_[i] = ComputePipeline(ctx, shader, spec, sizeof(layout::DeformParams), inputsLayout_.get());
  }
}

DescriptorBinding DeformPass::bindInstanceInputs(Context& ctx, const Buffer& weights, const Buffer& skinMatrices,
                                                 const Buffer* basis, const Buffer* anchors, VkDeviceSize weightsOffset,
                                                 VkDeviceSize matricesOffset) const {
  std::vector<BoundResource> r = {BoundResource::texels(weights, VK_FORMAT_R32G32B32A32_SFLOAT, weightsOffset),
                                  BoundResource::texels(skinMatrices, VK_FORMAT_R32G32B32A32_SFLOAT, matricesOffset)};
  if (basisTexels_) {
    if (!basis) throw Error("deform pass: reads the basis as texels, but no basis buffer was bound");
    r.push_back(BoundResource::texels(*basis, VK_FORMAT_R32_SFLOAT));
    // Without anchors (none in the model, or an empty buffer) the weights (whole texels) stand in: no
    // frame pushes out then, so the kernel never reads them.
    const bool anchorsBound = anchors && anchors->size() > 0;
    r.push_back(anchorsBound ? BoundResource::texels(*anchors, VK_FORMAT_R32G32B32A32_UINT)
                             : BoundResource::texels(weights, VK_FORMAT_R32G32B32A32_UINT, weightsOffset));
  }
  return DescriptorBinding(ctx, inputsLayout_, r);
}

uint32_t DeformPass::record(VkCommandBuffer cmd, const Args& a) const {
  if (a.vertexCount == 0 || a.instanceCount == 0) return 0;
  if (!a.instanceInputs) throw Error("deform pass: no instance inputs bound (bindInstanceInputs)");
  layout::DeformParams p;
  p.mean = layout::Address::of(a.mean);
  p.basis = layout::Address::of(a.basis);
  p.skinJoints = layout::Address::of(a.skinJoints);
  p.skinWeights = layout::Address::of(a.skinWeights);
  p.positionsOut = layout::Address::of(a.positionsOut);
  p.anchors = layout::Address::of(a.anchors);
  if (a.anchors && (a.anchorSlots < 1 || a.anchorSlots > anchorSets_))
    throw Error("deform pass: " + std::to_string(a.anchorSlots) + " body anchor sets, made for 1 to " +
                std::to_string(anchorSets_) + (anchorSets_ == 0 ? " (made without the push-out)" : ""));
  p.pushOut = a.anchors ? a.anchorSlots : 0u;
  p.vertexCount = a.vertexCount;
  p.instanceCount = a.instanceCount;
  p.jointCount = a.jointCount;
  p.instanceOrder = layout::Address::of(a.instanceOrder);
  p.maxGroups = groupsOf(meshComponents_);
  for (size_t b = 0; b < a.bandEnd.size(); ++b) p.bandEnd[b] = a.instanceCount;
  if (a.instanceOrder) {
    if (a.maxGroups > p.maxGroups)
      throw Error("deform pass: maxGroups " + std::to_string(a.maxGroups) + " beyond the " +
                  std::to_string(p.maxGroups) + " weight groups of " + std::to_string(meshComponents_) + " components");
    p.maxGroups = a.maxGroups;
    for (size_t b = 0; b + 1 < bands_.size(); ++b) {
      if (a.bandEnd[b] > a.instanceCount || (b > 0 && a.bandEnd[b] < a.bandEnd[b - 1]))
        throw Error("deform pass: band " + std::to_string(b) + " ends at " + std::to_string(a.bandEnd[b]) +
                    ", out of order or beyond " + std::to_string(a.instanceCount) + " instances");
      p.bandEnd[b] = a.bandEnd[b];
    }
  }
  p.pad0 = 0;
  const size_t withPush = a.anchors ? 1 : 0;
  (a.instanceOrder ? bandedPipeline_ : pipeline_)[withPush].bind(cmd, &p, sizeof(p), a.instanceInputs);
  vkCmdDispatch(cmd, groupCount(a.vertexCount, kWorkgroupSize), 1, 1);
  return 1;
}

}  // namespace swish::gpu
