// deform.comp and deform_basis_texels.comp (the shader code of both).
// PCA reconstruction (pre-skinning space) + linear blend skinning for ALL instances of one model in one
// dispatch. One thread per vertex: it loads its 3K basis values and its skin influences ONCE into
// registers, then loops over the instances. The basis, the largest input (3N x K floats), is
// therefore read once per frame, not once per instance.
//
// The per-instance inputs, read N times per instance, come through texel buffers (set 0), a whole vec4
// per fetch: the mesh weights as vec4[instance][K4 / 4] (K4 = K rounded up to 4, zero padded; every
// thread fetches the same texels) and the skin matrices as vec4[instance][joint][3], the top three
// rows of each affine matrix (the bottom row is 0 0 0 1). On lavapipe a vec4 texel fetch costs about
// what ONE scalar load through a buffer address costs (descriptor_binding.hpp), so 8 + 12 fetches per
// vertex and instance replace 32 + 48 scalar loads. Shared-memory staging of the weights and a subgroup
// broadcast of them were both measured slower on lavapipe, whose shared-memory loads, barriers and
// broadcasts are costly (figures: docs/performance.md, "Deform").
//
// Conforms to runtime/reference_pca.cpp (x = mean + sum_k basis_k * w_k, k ascending, starting at the
// mean) and runtime/reference_skinning.cpp (core/skinning.cpp: B = sum over influences with w != 0 of
// w * M, then B * x). `precise` forbids fused multiply-add contraction so that the sums round like
// the CPU reference (which is compiled without FMA); devices may still differ within the documented
// tolerance.
//
// The basis: deform.comp reads it through its buffer address, deform_basis_texels.comp as R32 texels
// (binding 2), where it fits in the device's maxTexelBufferElements (DeformPass decides). Lavapipe loads
// through an address lane by lane, and the basis is 3K loads per vertex per frame, whatever the
// instance count, so the texel form pays most where characters are few (docs/performance.md).
//
// The push-out (runtime/reference_push_out.hpp, the specification): after skinning, each instance's
// vertex is kept outside its body anchors' balls, one after the other (the first anchor, then the
// second and the third where the model has them). Each anchor (rest centre, reach, weights) is loaded once
// per thread with the rest of the vertex, and its centre skinned per instance with the instance's
// matrix rows like the vertex itself, no per-frame input. The matrices come from the vertex's push-out
// joint table: its own skin joints, whose rows the skinning fetches anyway, then ANCHOR_EXTRA_JOINTS
// more (a specialisation constant: the most any vertex of the model needs, DeformPass::
// anchorExtraJointsOf). Each anchor's weights are over the table's slots (DeformPass::packAnchors
// places them), so a frame fetches 3 texels per extra slot and instance, not 3 per influence of every
// anchor (27 a vertex for three sets of three). The anchor fit puts the anchors on the vertex's own
// joints (bake::onGarmentJoints), so a fitted model has no extra slots and its push-out fetches no
// matrix at all beyond the skinning's; each set's blend then runs over the skin's slots. The sum runs
// in slot order, not in the anchor's rank order: within the rounding the conformance test allows. An
// indexed fetch from the table (a slot number per influence) would keep the order, but lavapipe puts
// such arrays in scratch memory: that measured 2.5 to 3 times the push-out's cost (docs/performance.md,
// "Deform"). `pushOut` (a push constant: the anchor sets to apply, 0 for none) is
// uniform, so a frame without the push-out skips it in uniform branches on a GPU. Lavapipe runs uniform
// branches masked, i.e. pays for the push-out in every frame, so the code exists only in the pipelines
// made for it: ANCHOR_SETS (a specialisation constant, the model's sets) bounds the unrolled loops, and
// DeformPass records a frame without the push-out with the pipeline of ANCHOR_SETS 0, the kernel without
// it (the honest baseline of its cost, too; made with no extra joints). deform_basis_texels.comp
// loads the anchors as uvec4 texels (binding 3; the floats' bits through uintBitsToFloat, exact):
// through the address each word is a scalar load, lane by lane on lavapipe (docs/performance.md,
// "Deform").
//
// Loops over K and the influences are unrolled ([[unroll]]; both are specialisation constants), so
// that the per-thread basis and skin arrays stay in registers instead of indexed scratch memory.
//
// Quality levels (runtime/quality_levels.hpp): instance i reconstructs from its first k_i components
// only, in this one dispatch, and reads only the weight groups (vec4 texels) its level needs. Levels
// come as BANDS of weight groups fixed at pipeline creation (specialisation constants, from
// DeformPass::bandsOf: K4, then about K4 / 2, K4 / 4, K4 / 8 groups, then 0, the distinct ones): the
// host orders the instances by band (instanceOrder) and gives each band's end (bandEnd), and each band
// is its own instance loop whose body is unrolled to exactly that band's groups. Why loops and not
// branches: a uniform `if (q < groups)` inside one unrolled body is what a GPU skips cheaply, but
// lavapipe (Mesa 22.3) runs both sides of every `if` under a lane mask, so it saved nothing there
// (docs/performance.md, "Quality levels"); a loop's later iterations are real branches everywhere, so
// a band's loop costs what its instances need. An empty band still costs lavapipe one masked
// iteration of its body, which is why frames without levels use a pipeline with one band (BANDS = 1,
// instanceOrder 0: the kernel as it was) and why the bands are few. An instance whose k_i is below its
// band's groups reads zeros there: DeformPass::packWeights zeroes each row from k_i, and adding an
// exact zero changes nothing, so the sum is the reference's sum over k < k_i, k ascending. Each vertex
// loads only the basis groups of the widest band in use (maxGroups, a push constant: skipped on GPUs,
// masked on lavapipe, where the basis is loaded once per vertex whatever the instance count).
#include "swish_buffers.glsl"
#include "swish_layouts.h"

layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint K = 1;               // mesh PCA components
layout(constant_id = 2) const uint INFLUENCES = 4;      // skin influences per vertex
layout(constant_id = 3) const bool APPLY_SKINNING = true;  // false: write the pre-skinning shape
layout(constant_id = 4) const uint BANDS = 1;           // bands of weight groups, 1..5 (1: all at K4)
layout(constant_id = 5) const uint BAND1 = 0;           // weight groups of bands 1..4 (descending;
layout(constant_id = 6) const uint BAND2 = 0;           //  band 0 reads all K4; those from BANDS on
layout(constant_id = 7) const uint BAND3 = 0;           //  are unused)
layout(constant_id = 8) const uint BAND4 = 0;
layout(constant_id = 9) const uint ANCHOR_SETS = 0;     // anchor sets the kernel can push out of, 0..3
layout(constant_id = 10) const uint ANCHOR_EXTRA_JOINTS = 0;  // push-out table slots after the skin joints
layout(constant_id = 11) const bool ANCHOR_ZERO_SKIP = true;  // the anchors' blends skip zero weights (below)
const uint SLOTS = INFLUENCES + ANCHOR_EXTRA_JOINTS;          // the push-out joint table (the skin's alone: none)
const uint EXTRA_TEXELS = (ANCHOR_EXTRA_JOINTS + 3u) / 4u;     // per vertex, before the sets (layout: swish_layouts.h)
const uint SET_TEXELS = 1u + (SLOTS + 3u) / 4u;                // per vertex and set: centre + reach, weights

layout(push_constant) uniform Push { DeformParams p; };
layout(set = 0, binding = 0) uniform samplerBuffer weightTexels;  // vec4[instance][K4 / 4]
layout(set = 0, binding = 1) uniform samplerBuffer matrixRows;  // vec4[instance][joint][3] (rows 0..2)
#ifdef SWISH_DEFORM_BASIS_TEXELS
layout(set = 0, binding = 2) uniform samplerBuffer basisTexels;  // float[K][3N]
layout(set = 0, binding = 3) uniform usamplerBuffer anchorTexels;  // uvec4: the body anchors' layout
#endif
const uint K4 = (K + 3u) / 4u;

// This thread's vertex: loaded once, read by every instance.
uint v;
vec3 mean;
float basis[3 * K];
uint joints[SLOTS];  // its push-out joint table: the skin joints, then the extra ones
float skinW[INFLUENCES];
// Its body anchors (p.pushOut of them, at most SWISH_MAX_ANCHOR_SLOTS: the first, the second, the third).
vec3 anchorC[SWISH_MAX_ANCHOR_SLOTS];   // each ball's centre (rest)
float anchorR[SWISH_MAX_ANCHOR_SLOTS];  // its reach (radius + clearance; 0: no anchor)
float anchorW[SWISH_MAX_ANCHOR_SLOTS][SLOTS];  // its weights over the table's slots

// The blend of the first `count` table matrices of this instance (rows r0..r2 per slot; weights W), as
// the columns b0..b3 of its top three rows. With `skip` a zero weight is skipped by a select, as in the
// reference; a constant false `skip` folds the select away (the anchors' blends where it is not needed).
#define SWISH_BLEND_MATRICES(count, W, skip, b0, b1, b2, b3)                                           \
  [[unroll]] for (uint i = 0u; i < count; ++i) {                                                       \
    const float w = W[i];                                                                              \
    const vec4 r0 = rows0[i], r1 = rows1[i], r2 = rows2[i];                                            \
    const vec3 c0 = vec3(r0.x, r1.x, r2.x), c1 = vec3(r0.y, r1.y, r2.y), c2 = vec3(r0.z, r1.z, r2.z), c3 = vec3(r0.w, r1.w, r2.w); \
    const bool use = !(skip) || w != 0.0;                                                              \
    b0 = use ? b0 + w * c0 : b0;                                                                       \
    b1 = use ? b1 + w * c1 : b1;                                                                       \
    b2 = use ? b2 + w * c2 : b2;                                                                       \
    b3 = use ? b3 + w * c3 : b3;                                                                       \
  }

// One instance's vertex from its first `groups` weight groups (a constant at every call, so that the
// unrolled loop keeps constant indices into `basis` and drops the groups beyond).
void deformInstance(const uint instance, const uint groups) {
  precise vec3 x = mean;
  [[unroll]] for (uint q = 0u; q < K4; ++q) {
    if (q < groups) {
      const vec4 w4 = texelFetch(weightTexels, int(instance * K4 + q));  // the same texel in every thread
      [[unroll]] for (uint j = 0u; j < 4u; ++j) {
        const uint k = 4u * q + j;
        if (k < K) x = x + vec3(basis[3u * k], basis[3u * k + 1u], basis[3u * k + 2u]) * w4[j];
      }
    }
  }
  precise vec3 y = x;
  if (APPLY_SKINNING) {
    // Each table matrix comes as its top three rows (3 fetches, once per instance for the skinning
    // and the anchors alike); the columns summed below are their components. The zero-weight skip is
    // a select, not a branch: every lane runs the same fetches (lavapipe gathers per lane, masked
    // branches do not save that), and a skipped matrix still cannot bring its NaN/Inf in.
    vec4 rows0[SLOTS], rows1[SLOTS], rows2[SLOTS];
    [[unroll]] for (uint i = 0u; i < SLOTS; ++i) {
      const int m = int((instance * p.jointCount + joints[i]) * 3u);
      rows0[i] = texelFetch(matrixRows, m);
      rows1[i] = texelFetch(matrixRows, m + 1);
      rows2[i] = texelFetch(matrixRows, m + 2);
    }
    precise vec3 b0 = vec3(0.0), b1 = vec3(0.0), b2 = vec3(0.0), b3 = vec3(0.0);
    SWISH_BLEND_MATRICES(INFLUENCES, skinW, true, b0, b1, b2, b3)
    y = ((b0 * x.x + b1 * x.y) + b2 * x.z) + b3;
    // The push-out (character space: after skinning only).
    [[unroll]] for (uint a = 0u; a < ANCHOR_SETS; ++a) {
      // p.pushOut is uniform; a vertex without an anchor in this set (reach 0: 89 of the default jersey's
      // 3213 in the second set, which holds its slide anchors too) skips the blend, which could not move it. On a GPU whole subgroups of
      // such vertices do; lavapipe runs it masked as before.
      if (a < p.pushOut && anchorR[a] != 0.0) {
        precise vec3 a0 = vec3(0.0), a1 = vec3(0.0), a2 = vec3(0.0), a3 = vec3(0.0);
        // Where every table slot of every vertex carries a non-zero skin weight (no extra joints:
        // DeformPass::anchorsSkipZeroWeights), ANCHOR_ZERO_SKIP is false and the select is not needed: a
        // zero weight times a finite matrix adds an exact zero, and a slot whose matrix is not finite has
        // already made the skinned vertex y non-finite, which no push moves (s is then NaN or infinite),
        // here as in the reference. A third of the blends' work on lavapipe (docs/performance.md, "Deform").
        SWISH_BLEND_MATRICES(SLOTS, anchorW[a], ANCHOR_ZERO_SKIP, a0, a1, a2, a3)
        precise const vec3 c = ((a0 * anchorC[a].x + a1 * anchorC[a].y) + a2 * anchorC[a].z) + a3;
        precise const vec3 e = y - c;
        precise const float s = (e.x * e.x + e.y * e.y) + e.z * e.z;
        const float r = anchorR[a];
        if (s > 1e-12 && s < r * r) y = c + e * (r / sqrt(s));  // kMinAnchorDistanceSq
      }
    }
  }
  FloatsOut outBuf = FloatsOut(p.positionsOut);
  const uint o = (instance * p.vertexCount + v) * 3u;
  outBuf.v[o] = y.x;
  outBuf.v[o + 1u] = y.y;
  outBuf.v[o + 2u] = y.z;
}

// Where band b ends in instanceOrder (the last band at instanceCount).
uint bandEnd(const uint b) { return b + 1u >= BANDS ? p.instanceCount : p.bandEnd[b]; }

void main() {
  v = gl_GlobalInvocationID.x;
  if (v >= p.vertexCount) return;
  const uint n3 = p.vertexCount * 3u;

  // Basis groups loaded: those of the widest band in use (the min keeps a maxGroups beyond K4 in range).
  const uint loadGroups = min(p.maxGroups, K4);
  FloatsIn meanBuf = FloatsIn(p.mean);
  mean = vec3(meanBuf.v[3u * v], meanBuf.v[3u * v + 1u], meanBuf.v[3u * v + 2u]);
#ifdef SWISH_DEFORM_BASIS_TEXELS
  [[unroll]] for (uint k = 0u; k < K; ++k) {
    if (k / 4u < loadGroups) {
      [[unroll]] for (uint a = 0u; a < 3u; ++a) basis[3u * k + a] = texelFetch(basisTexels, int(k * n3 + 3u * v + a)).x;
    } else {
      [[unroll]] for (uint a = 0u; a < 3u; ++a) basis[3u * k + a] = 0.0;
    }
  }
#else
  FloatsIn basisBuf = FloatsIn(p.basis);
  [[unroll]] for (uint k = 0u; k < K; ++k) {
    if (k / 4u < loadGroups) {
      [[unroll]] for (uint a = 0u; a < 3u; ++a) basis[3u * k + a] = basisBuf.v[k * n3 + 3u * v + a];
    } else {
      [[unroll]] for (uint a = 0u; a < 3u; ++a) basis[3u * k + a] = 0.0;
    }
  }
#endif
  UintsIn jointBuf = UintsIn(p.skinJoints);
  FloatsIn skinWeightBuf = FloatsIn(p.skinWeights);
  [[unroll]] for (uint i = 0u; i < INFLUENCES; ++i) {
    joints[i] = jointBuf.v[v * INFLUENCES + i];
    skinW[i] = skinWeightBuf.v[v * INFLUENCES + i];
  }
  // The anchors (layout: swish_layouts.h): the table's extra joints, then each set's centre, reach and
  // weights. Texels: the words' bits, floats through uintBitsToFloat (exact).
#ifdef SWISH_DEFORM_BASIS_TEXELS
#define SWISH_ANCHOR_TEXEL(t) texelFetch(anchorTexels, int(t))
#else
  UintsIn anchorU = UintsIn(p.anchors);
#define SWISH_ANCHOR_TEXEL(t) uvec4(anchorU.v[4u * (t)], anchorU.v[4u * (t) + 1u], anchorU.v[4u * (t) + 2u], anchorU.v[4u * (t) + 3u])
#endif
  // (Every loop below has a constant trip count and constant indices once unrolled: an index the
  // compiler cannot fold would put these arrays in scratch memory.)
  if (ANCHOR_EXTRA_JOINTS > 0u) {
    uvec4 j4[(ANCHOR_EXTRA_JOINTS + 4u) / 4u];  // (EXTRA_TEXELS used; never sized 0, even where unused)
    [[unroll]] for (uint q = 0u; q < EXTRA_TEXELS; ++q) j4[q] = p.pushOut > 0u ? SWISH_ANCHOR_TEXEL(v * EXTRA_TEXELS + q) : uvec4(0u);
    [[unroll]] for (uint e = 0u; e < ANCHOR_EXTRA_JOINTS; ++e) joints[INFLUENCES + e] = j4[e / 4u][e % 4u];
  }
  [[unroll]] for (uint a = 0u; a < ANCHOR_SETS; ++a) {
    uvec4 t4[SET_TEXELS];  // centre + reach, then the weights
    const uint t = p.vertexCount * EXTRA_TEXELS + (a * p.vertexCount + v) * SET_TEXELS;
    [[unroll]] for (uint q = 0u; q < SET_TEXELS; ++q) t4[q] = a < p.pushOut ? SWISH_ANCHOR_TEXEL(t + q) : uvec4(0u);
    anchorC[a] = uintBitsToFloat(t4[0].xyz);
    anchorR[a] = uintBitsToFloat(t4[0].w);
    [[unroll]] for (uint i = 0u; i < SLOTS; ++i) anchorW[a][i] = uintBitsToFloat(t4[1u + i / 4u][i % 4u]);
  }
#undef SWISH_ANCHOR_TEXEL

  if (BANDS == 1u) {  // every instance at K4 groups, in order
    for (uint instance = 0u; instance < p.instanceCount; ++instance) deformInstance(instance, K4);
    return;
  }
  // The instances band by band, in instanceOrder (the same word in every thread).
  UintsIn order = UintsIn(p.instanceOrder);
  uint j = 0u;
  for (; j < bandEnd(0u); ++j) deformInstance(order.v[j], K4);
  for (; j < bandEnd(1u); ++j) deformInstance(order.v[j], BAND1);
  if (BANDS > 2u)
    for (; j < bandEnd(2u); ++j) deformInstance(order.v[j], BAND2);
  if (BANDS > 3u)
    for (; j < bandEnd(3u); ++j) deformInstance(order.v[j], BAND3);
  if (BANDS > 4u)
    for (; j < bandEnd(4u); ++j) deformInstance(order.v[j], BAND4);
}
