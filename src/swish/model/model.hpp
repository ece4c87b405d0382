#pragma once
// The Model: everything the run time needs for one garment on one body, as plain data. Written by the
// bake, read from a .swish file (model_file.hpp), consumed by the runtime. No Vulkan, no I/O here.
//
// Per frame (paper section 2.3):
//   Theta  = 6D rotations of inputJoints, in order            (size 6 * inputJoints.size())
//            [+ gravity in the root joint's frame, 3 values, when rootGravity: runtime/theta.hpp]
//   Lambda = denormalise(MLP(normalise(Theta)))               (size meshComponents + normalCodeDims)
//   mesh weights = Lambda[0 .. K), normal code = Lambda[K .. K + C)
//   pre-skin shape = meshPca.mean + meshPca.basis * weights  ->  linear blend skinning
//   normal map = database map whose key is nearest the code  ->  VQ decode -> temporal blend
#include <array>
#include <string>
#include <vector>

#include "swish/core/mesh.hpp"
#include "swish/core/skeleton.hpp"
#include "swish/core/types.hpp"

namespace swish {

// x_normalised = (x - mean) / scale, elementwise. scale > 0.
struct Normalisation {
  VecXf mean;
  VecXf scale;
};

struct MlpLayer {
  MatXf weight;  // out x in
  VecXf bias;    // out
};

// Every layer but the last is followed by SELU; the last is linear.
struct Mlp {
  std::vector<MlpLayer> layers;
  int inputSize() const { return layers.empty() ? 0 : int(layers.front().weight.cols()); }
  int outputSize() const { return layers.empty() ? 0 : int(layers.back().weight.rows()); }
};

// PCA of game-mesh shapes in pre-skinning space. Vertex v, axis a lives at row 3*v + a.
struct MeshPca {
  VecXf mean;   // 3N
  MatXf basis;  // 3N x K, one column per component
  int components() const { return int(basis.cols()); }
};

// The k-means normal-map database, compressed with vector quantisation of 4x4 blocks.
// Map texel (x, y) of map m: block b = (y/4) * (width/4) + (x/4), entry e = indices[m * blocksPerMap + b],
// texel t = (y%4)*4 + (x%4); X = codebook[(e*16 + t)*2 + 0] / 127, Y = codebook[(e*16 + t)*2 + 1] / 127
// (snorm8, clamped to [-1, 1]); Z = sqrt(max(0, 1 - X^2 - Y^2)). Tangent space.
struct NormalMapDatabase {
  uint32_t width = 0, height = 0;  // multiples of 4
  MatXf keys;                      // mapCount x codeDims: each map's normal-map PCA code
  uint32_t codebookSize = 0;       // entries; indices are 16-bit so at most 65536
  std::vector<int8_t> codebook;    // codebookSize * 16 texels * 2 channels
  std::vector<uint16_t> indices;   // mapCount * blocksPerMap()

  uint32_t mapCount() const { return uint32_t(keys.rows()); }
  uint32_t codeDims() const { return uint32_t(keys.cols()); }
  uint32_t blocksPerMap() const { return (width / 4) * (height / 4); }
  bool empty() const { return mapCount() == 0; }
};

struct TemporalFilterParams {
  // Exponential blend of the newly selected map into the per-character map: each frame the new map
  // gets weight 1 - exp(-dt / timeConstant). 0 disables filtering (the selection shows at once).
  float timeConstantSeconds = 0.1f;
};

// The run-time push-out's hold on the body (format 1.3; runtime/reference_push_out.hpp, fitted by
// bake/training/body_anchor_fit.hpp): per game-mesh vertex, the closest point of the body it was baked
// on, at rest, with the body's outward normal there, the body's skin at that point (its triangle's
// three vertices' weights interpolated barycentrically, the kAnchorInfluences largest kept and
// renormalised), and the radius of the largest ball inside the body's part that touches the surface
// there (centre = position - radius * normal): the body under the vertex, as seen from the vertex. At
// run time the ball's centre is skinned like the garment and the vertex is kept outside the ball, its
// `clearance` off the surface, by a radial push: one ball per vertex. A vertex answers to its own
// anchor only, so a sleeve anchored on the arm is never pushed out of the torso (the capsules of
// formats 1.1 and 1.2 did that, and made the error worse).
//
// Why a ball and not the tangent plane at the anchor: cloth slides over the body, and a sleeve vertex
// that has turned 3 cm around the arm is behind the plane of its anchor while well outside the arm.
// Pushed to the plane, such vertices moved away from the simulated truth (measured on the default
// model: +1.0 mm mean vertex error); the ball inscribed in the arm follows the arm's round section
// (a flat chest gets a large ball, a plane in the limit), and the same push then kept the error.
//
// The clearance is the model's margin, or lower where pushing the network's garment to the margin
// took it away from the source simulation in the poses the anchors were calibrated on
// (calibrateBodyAnchors): then the push-out removes what the network adds beyond what the simulation
// does, and never pushes against the simulation there.
inline constexpr int kAnchorInfluences = 4;
struct BodyAnchor {
  Vec3f position = Vec3f::Zero();  // on the body surface, rest character space, metres
  Vec3f normal = Vec3f::Zero();    // unit, out of the body (rest)
  float radius = 0.f;              // of the ball inside the body touching it at `position` (metres, > 0)
  float clearance = 0.f;           // metres off the ball the vertex is kept: <= margin, > -radius, >= -kMaxAnchorDepth
  std::array<uint16_t, kAnchorInfluences> joints{};
  std::array<float, kAnchorInfluences> weights{};  // >= 0, summing to 1; ALL 0 (and everything else 0): no anchor
  bool present() const { return weights[0] != 0.f || weights[1] != 0.f || weights[2] != 0.f || weights[3] != 0.f; }
  // The ball's centre at rest (every user computes it by this one expression, so that it rounds alike).
  Vec3f centre() const { return position - normal * radius; }
  // Distance from the centre the push-out keeps a vertex at: radius + clearance (0 without an anchor).
  float reach() const { return radius + clearance; }
};

struct BodyAnchors {
  // The clearance an anchor starts with (metres): the cloth's own half thickness, so that a pushed
  // vertex does not sit exactly on the body surface and z-fight with it; no anchor's is above it.
  float margin = 0.002f;
  std::vector<BodyAnchor> anchors;  // empty (no push-out) or one per game-mesh vertex: its nearest body part
  // Format 1.4: empty, or one per game-mesh vertex (only with `anchors`): the nearest point of ANOTHER
  // body part within the fit's reach, applied after `anchors`. Where two parts meet (a shoulder, whose
  // jersey lies on the trunk while the upper arm's end turns up through it when the arm hangs), the
  // vertex's own part cannot see the other one; its second anchor does. A vertex with no other part in
  // reach may have a slide anchor here instead: a ball on its own part where the bake's simulation had
  // the cloth slide to (body_anchor_fit.hpp). The run time treats both alike.
  std::vector<BodyAnchor> second;
  // Format 1.5: empty, or one per game-mesh vertex (only with `second`): a cover anchor, applied after
  // `second`. Cloth slides to more than one place: the second set's slide anchor holds the pose where
  // the first ball misses the skin most (the jersey ridden up over the belly with the arms out, rare
  // and large), and the cover anchor the ball that covers most of the skin the first two still miss
  // over the bake's poses (a bent elbow's skin under its sleeve, frequent; body_anchor_fit.hpp).
  std::vector<BodyAnchor> third;
  bool empty() const { return anchors.empty(); }
  // Anchor sets the push-out applies, in order: 0 (none), 1 (`anchors`), 2 (then `second`) or 3 (then `third`).
  uint32_t slots() const { return anchors.empty() ? 0u : second.empty() ? 1u : third.empty() ? 2u : 3u; }
  const std::vector<BodyAnchor>& slot(uint32_t s) const { return s == 0 ? anchors : s == 1 ? second : third; }
  std::vector<BodyAnchor>& slot(uint32_t s) { return s == 0 ? anchors : s == 1 ? second : third; }
  size_t anchored(uint32_t slot = 0) const;  // vertices with an anchor in that set
};
inline constexpr uint32_t kMaxAnchorSlots = 3;
// The sets' names in messages: "first", "second", "third".
inline const char* anchorSlotName(uint32_t s) { return s == 0 ? "first" : s == 1 ? "second" : "third"; }

// Largest margin a model may ask for (metres): beyond a few centimetres the push-out would hold
// the garment visibly off the body, which is not what it is for.
inline constexpr float kMaxAnchorMargin = 0.05f;
// Deepest an anchor's clearance may go into its ball (metres): beyond that the anchor says nothing
// (the calibration drops such anchors instead).
inline constexpr float kMaxAnchorDepth = 0.2f;
// Range of an anchor's ball radius (metres): from a crease of the body to a flat back.
inline constexpr float kMinAnchorRadius = 0.001f, kMaxAnchorRadius = 1.f;

// The run-time novelty guard (format 1.2; runtime/novelty_guard.hpp): how far a frame's network input
// lies from the poses the model was trained on, and what the run time does when it is far. Novelty is
// the distance of the normalised Theta ((Theta - inputNorm.mean) / inputNorm.scale) to the nearest of
// `centres` (k-means centres of the training poses' normalised Theta), as an RMS per input, divided by
// `unit` (the 95th percentile of the training poses' own such distances): about 1 at the sparse edge of
// the training set. The guard clamps the mesh weights to [weightMin, weightMax] (the range the training
// shapes span) and, when blendEnd > blendStart, scales them towards 0 (the PCA mean shape) as novelty
// goes from blendStart to blendEnd. Frames whose novelty is above flagAbove are reported as novel.
struct NoveltyGuard {
  MatXf centres;               // C x thetaSize; C == 0: no guard (models before 1.2)
  float unit = 1.f;            // > 0
  VecXf weightMin, weightMax;  // K each, or both empty: no clamp
  float blendStart = 0.f, blendEnd = 0.f;
  float flagAbove = 2.f;
  bool empty() const { return centres.rows() == 0; }
  bool blends() const { return blendEnd > blendStart; }
};

// The body triangles the garment covers in (nearly) every training pose (format 1.2; bake/transfer/body_coverage.hpp):
// what a renderer may leave out, as games leave out the skin under tight clothing. Indices refer to the
// triangles of the body the model was baked on, which has bodyTriangles of them (a host checks that its
// body is that one). Empty: not computed (no body, or a model before 1.2).
struct BodyCoverage {
  uint32_t bodyTriangles = 0;
  std::vector<uint32_t> covered;  // ascending, < bodyTriangles
};

// Theta's size: 6 per input joint, 3 more with the gravity values (Model::rootGravity).
inline size_t thetaSize(size_t inputJoints, bool rootGravity) { return 6 * inputJoints + (rootGravity ? 3 : 0); }

struct Model {
  Skeleton skeleton;                  // the character's skeleton (for FK and skinning)
  std::vector<uint32_t> inputJoints;  // skeleton joint indices forming Theta, in this order
  // Theta ends with the gravity direction in the root joint's frame (3 values, runtime/theta.hpp): the
  // body's lean. false in models baked without it (the bake's default; part 1's upright datasets refuse it).
  bool rootGravity = false;
  Normalisation inputNorm;   // over Theta
  Normalisation outputNorm;  // over Lambda
  Mlp mlp;
  MeshPca meshPca;
  Mesh gameMesh;                 // rest positions, triangles, UVs, skin, rest normals+tangents
  NormalMapDatabase normalMaps;  // may be empty (a model without normal maps)
  TemporalFilterParams temporalFilter;
  BodyAnchors bodyAnchors;      // may be empty (models before format 1.3, or baked without a body)
  NoveltyGuard noveltyGuard;    // may be empty (models before format 1.2)
  BodyCoverage bodyCoverage;    // may be empty (models before format 1.2, or baked without a body)
  std::string metadata = "{}";  // free-form JSON: bake settings, errors measured at bake time

  int thetaSize() const { return int(swish::thetaSize(inputJoints.size(), rootGravity)); }
  int meshComponents() const { return meshPca.components(); }
  int normalCodeDims() const { return int(normalMaps.codeDims()); }
  int lambdaSize() const { return meshComponents() + normalCodeDims(); }

  // Checks every size, index and value the runtime relies on; throws Error naming `what` and the
  // part that is wrong. Loaders call it; so should anything that builds a Model by hand.
  void validate(const std::string& what = "model") const;
};

}  // namespace swish
