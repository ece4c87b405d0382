#include "swish/model/model_sections.hpp"

#include <limits>
#include <string>

#include "swish/core/error.hpp"

namespace swish::model_sections {

namespace {

// Counts are u32 in the file; a model too large for that cannot be written (and could not be run).
uint32_t count32(size_t n, const char* what) {
  if (n > std::numeric_limits<uint32_t>::max())
    throw Error("cannot serialize model: " + std::string(what) + " count " + std::to_string(n) +
                " does not fit in 32 bits");
  return uint32_t(n);
}

// ---- SKEL -------------------------------------------------------------------------------------
// Smallest possible joint record: name length, parent, quaternion, translation (an empty name).
constexpr uint64_t kMinJointBytes = 4 + 4 + 16 + 12;

void writeSkeleton(const Model& m, ByteWriter& w) {
  const Skeleton& sk = m.skeleton;
  w.u32(count32(sk.joints.size(), "joint"));
  for (const Joint& j : sk.joints) {
    w.u32(count32(j.name.size(), "joint name byte"));
    w.text(j.name);
    w.i32(j.parent);
    w.f32s({j.rest.rotation.coeffs().data(), 4});  // x y z w
    w.f32s({j.rest.translation.data(), 3});
  }
  w.u32(count32(sk.inverseBind.size(), "inverse bind matrix"));
  for (const Mat4f& b : sk.inverseBind) w.f32s({b.data(), 16});  // column-major
}

void readSkeleton(ByteReader& r, Model& m) {
  Skeleton& sk = m.skeleton;
  const size_t jointCount = r.checkCount(r.u32("joint count"), kMinJointBytes, "joint");
  sk.joints.resize(jointCount);
  for (Joint& j : sk.joints) {
    const size_t nameBytes = r.checkCount(r.u32("joint name length"), 1, "joint name byte");
    const auto name = r.view(nameBytes, "joint name");
    j.name.assign(name.begin(), name.end());
    j.parent = r.i32("joint parent");
    r.f32s(j.rest.rotation.coeffs().data(), 4, "joint rest rotation");
    r.f32s(j.rest.translation.data(), 3, "joint rest translation");
  }
  const uint32_t bindCount = r.u32("inverse bind matrix count");
  if (bindCount != 0 && bindCount != jointCount)
    r.fail("inverse bind matrix count " + std::to_string(bindCount) + " is neither 0 nor the joint count " +
           std::to_string(jointCount));
  sk.inverseBind.resize(r.checkCount(bindCount, 64, "inverse bind matrix"));
  for (Mat4f& b : sk.inverseBind) r.f32s(b.data(), 16, "inverse bind matrix");
}

// ---- INPJ -------------------------------------------------------------------------------------
// The gravity values (Model::rootGravity) are an entry kRootGravityInput after the joints: a file with
// them is refused by readers from before them (an input joint beyond the skeleton), and a file without
// them reads as ever.
constexpr uint32_t kRootGravityInput = 0xFFFFFFFFu;

void writeInputJoints(const Model& m, ByteWriter& w) {
  w.u32(count32(m.inputJoints.size() + (m.rootGravity ? 1 : 0), "input joint"));
  w.u32s(m.inputJoints);
  if (m.rootGravity) w.u32(kRootGravityInput);
}

void readInputJoints(ByteReader& r, Model& m) {
  m.inputJoints.resize(r.checkCount(r.u32("input joint count"), 4, "input joint"));
  r.u32s(m.inputJoints.data(), m.inputJoints.size(), "input joint");
  m.rootGravity = !m.inputJoints.empty() && m.inputJoints.back() == kRootGravityInput;
  if (m.rootGravity) m.inputJoints.pop_back();
}

// ---- NRMI, NRMO -------------------------------------------------------------------------------
void writeNormalisation(const Normalisation& n, ByteWriter& w) {
  if (n.mean.size() != n.scale.size())
    throw Error("cannot serialize model: normalisation mean and scale differ in size");
  w.u32(count32(size_t(n.mean.size()), "normalisation value"));
  w.f32s({n.mean.data(), size_t(n.mean.size())});
  w.f32s({n.scale.data(), size_t(n.scale.size())});
}

void readNormalisation(ByteReader& r, Normalisation& n) {
  const size_t size = r.checkCount(r.u32("normalisation size"), 8, "normalisation value");
  n.mean.resize(Eigen::Index(size));
  r.f32s(n.mean.data(), size, "normalisation mean");
  n.scale.resize(Eigen::Index(size));
  r.f32s(n.scale.data(), size, "normalisation scale");
}

void writeInputNorm(const Model& m, ByteWriter& w) { writeNormalisation(m.inputNorm, w); }
void readInputNorm(ByteReader& r, Model& m) { readNormalisation(r, m.inputNorm); }
void writeOutputNorm(const Model& m, ByteWriter& w) { writeNormalisation(m.outputNorm, w); }
void readOutputNorm(ByteReader& r, Model& m) { readNormalisation(r, m.outputNorm); }

// ---- MLP --------------------------------------------------------------------------------------
void writeMlp(const Model& m, ByteWriter& w) {
  w.u32(count32(m.mlp.layers.size(), "layer"));
  for (const MlpLayer& l : m.mlp.layers) {
    if (l.bias.size() != l.weight.rows()) throw Error("cannot serialize model: mlp bias size differs from its layer");
    w.u32(count32(size_t(l.weight.rows()), "layer output"));
    w.u32(count32(size_t(l.weight.cols()), "layer input"));
    w.f32s({l.weight.data(), size_t(l.weight.size())});
    w.f32s({l.bias.data(), size_t(l.bias.size())});
  }
}

void readMlp(ByteReader& r, Model& m) {
  // 8 bytes (out, in) is the least a layer can take.
  m.mlp.layers.resize(r.checkCount(r.u32("layer count"), 8, "layer"));
  for (MlpLayer& l : m.mlp.layers) {
    const uint32_t out = r.u32("layer output size"), in = r.u32("layer input size");
    const size_t weights = r.checkCount(r.multiply(out, in, "layer weight"), 4, "layer weight");
    l.weight.resize(out, in);
    r.f32s(l.weight.data(), weights, "layer weight");
    l.bias.resize(Eigen::Index(r.checkCount(out, 4, "layer bias")));
    r.f32s(l.bias.data(), out, "layer bias");
  }
}

// ---- MPCA -------------------------------------------------------------------------------------
void writeMeshPca(const Model& m, ByteWriter& w) {
  const MeshPca& p = m.meshPca;
  if (p.basis.rows() != p.mean.size()) throw Error("cannot serialize model: mesh pca basis rows differ from its mean");
  w.u32(count32(size_t(p.mean.size()), "mesh pca row"));
  w.u32(count32(size_t(p.basis.cols()), "mesh pca component"));
  w.f32s({p.mean.data(), size_t(p.mean.size())});
  w.f32s({p.basis.data(), size_t(p.basis.size())});
}

void readMeshPca(ByteReader& r, Model& m) {
  MeshPca& p = m.meshPca;
  const uint32_t rows = r.u32("mesh pca row count"), components = r.u32("mesh pca component count");
  p.mean.resize(Eigen::Index(r.checkCount(rows, 4, "mesh pca mean value")));
  r.f32s(p.mean.data(), rows, "mesh pca mean value");
  const size_t basis = r.checkCount(r.multiply(rows, components, "mesh pca basis value"), 4, "mesh pca basis value");
  p.basis.resize(rows, components);
  r.f32s(p.basis.data(), basis, "mesh pca basis value");
}

// ---- MESH -------------------------------------------------------------------------------------
constexpr uint32_t kHasNormals = 1, kHasTangents = 2, kHasUvs = 4, kAllAttributes = 7;

void writeMesh(const Model& m, ByteWriter& w) {
  const Mesh& g = m.gameMesh;
  const size_t n = g.vertexCount();
  auto present = [&](Eigen::Index rows, const char* what) {
    if (rows != 0 && size_t(rows) != n)
      throw Error("cannot serialize model: game mesh has " + std::to_string(rows) + " " + what + " for " +
                  std::to_string(n) + " vertices");
    return rows != 0;
  };
  const uint32_t flags = (present(g.normals.rows(), "normals") ? kHasNormals : 0) |
                         (present(g.tangents.rows(), "tangents") ? kHasTangents : 0) |
                         (present(g.uvs.rows(), "UVs") ? kHasUvs : 0);
  w.u32(count32(n, "vertex"));
  w.u32(count32(g.triangleCount(), "triangle"));
  w.u32(flags);
  // Row-major N x k matrices: data() is vertex after vertex.
  w.f32s({g.positions.data(), size_t(g.positions.size())});
  if (flags & kHasNormals) w.f32s({g.normals.data(), size_t(g.normals.size())});
  if (flags & kHasTangents) w.f32s({g.tangents.data(), size_t(g.tangents.size())});
  if (flags & kHasUvs) w.f32s({g.uvs.data(), size_t(g.uvs.size())});
  w.u32s({g.triangles.data(), size_t(g.triangles.size())});
}

void readMesh(ByteReader& r, Model& m) {
  Mesh& g = m.gameMesh;
  const uint32_t n = r.u32("vertex count"), triangles = r.u32("triangle count"), flags = r.u32("attribute flags");
  if (flags & ~kAllAttributes) r.fail("unknown attribute flags " + std::to_string(flags));
  const uint64_t perVertex =
      12 + (flags & kHasNormals ? 12 : 0) + (flags & kHasTangents ? 16 : 0) + (flags & kHasUvs ? 8 : 0);
  r.checkCount(n, perVertex, "vertex");  // all vertex attributes at once, before any allocation
  g.positions.resize(n, 3);
  r.f32s(g.positions.data(), size_t(n) * 3, "vertex position");
  if (flags & kHasNormals) {
    g.normals.resize(n, 3);
    r.f32s(g.normals.data(), size_t(n) * 3, "vertex normal");
  }
  if (flags & kHasTangents) {
    g.tangents.resize(n, 4);
    r.f32s(g.tangents.data(), size_t(n) * 4, "vertex tangent");
  }
  if (flags & kHasUvs) {
    g.uvs.resize(n, 2);
    r.f32s(g.uvs.data(), size_t(n) * 2, "vertex UV");
  }
  r.checkCount(triangles, 12, "triangle");
  g.triangles.resize(triangles, 3);
  r.u32s(g.triangles.data(), size_t(triangles) * 3, "triangle");
}

// ---- SKIN -------------------------------------------------------------------------------------
void writeSkin(const Model& m, ByteWriter& w) {
  const SkinWeights& s = m.gameMesh.skin;
  if (s.joints.size() != s.weights.size() || s.influences < 0 || s.influences > kMaxInfluences ||
      (s.influences == 0 && !s.weights.empty()) || (s.influences > 0 && s.weights.size() % size_t(s.influences)))
    throw Error("cannot serialize model: inconsistent skin weights");
  w.u32(uint32_t(s.influences));
  w.u32(count32(s.vertexCount(), "skinned vertex"));
  w.u16s(s.joints);
  w.f32s(s.weights);
}

void readSkin(ByteReader& r, Model& m) {
  SkinWeights& s = m.gameMesh.skin;
  const uint32_t influences = r.u32("influence count"), n = r.u32("skinned vertex count");
  if (influences > uint32_t(kMaxInfluences))
    r.fail("influence count " + std::to_string(influences) + " outside 0.." + std::to_string(kMaxInfluences));
  if (influences == 0 && n != 0) r.fail(std::to_string(n) + " skinned vertices with 0 influences each");
  const size_t entries = r.checkCount(uint64_t(n) * influences, 6, "skin entry");  // u16 joint + f32 weight
  s.influences = int(influences);
  s.joints.resize(entries);
  r.u16s(s.joints.data(), entries, "skin joint index");
  s.weights.resize(entries);
  r.f32s(s.weights.data(), entries, "skin weight");
}

// ---- NMDB -------------------------------------------------------------------------------------
void writeNormalMaps(const Model& m, ByteWriter& w) {
  const NormalMapDatabase& db = m.normalMaps;
  if (db.codebook.size() != size_t(db.codebookSize) * 32 ||
      db.indices.size() != size_t(db.mapCount()) * db.blocksPerMap())
    throw Error("cannot serialize model: normal-map database sizes are inconsistent");
  w.u32(db.width);
  w.u32(db.height);
  w.u32(count32(size_t(db.keys.rows()), "normal map"));
  w.u32(count32(size_t(db.keys.cols()), "normal code dimension"));
  w.u32(db.codebookSize);
  if (db.keys.cols() > 0)
    for (Eigen::Index i = 0; i < db.keys.rows(); ++i)
      for (Eigen::Index c = 0; c < db.keys.cols(); ++c) w.f32(db.keys(i, c));
  w.bytes({reinterpret_cast<const uint8_t*>(db.codebook.data()), db.codebook.size()});
  w.u16s(db.indices);
}

void readNormalMaps(ByteReader& r, Model& m) {
  NormalMapDatabase& db = m.normalMaps;
  db.width = r.u32("map width");
  db.height = r.u32("map height");
  const uint32_t maps = r.u32("map count"), dims = r.u32("code dimension count");
  db.codebookSize = r.u32("codebook size");
  if (db.width % 4 || db.height % 4)
    r.fail("map size " + std::to_string(db.width) + "x" + std::to_string(db.height) + " is not a multiple of 4");
  r.checkCount(r.multiply(maps, dims, "key value"), 4, "key value");
  db.keys.resize(maps, dims);
  // Keys are stored map after map (row-major); the guard skips a long empty loop when dims == 0.
  if (dims > 0)
    for (Eigen::Index i = 0; i < db.keys.rows(); ++i)
      for (Eigen::Index c = 0; c < db.keys.cols(); ++c) db.keys(i, c) = r.f32("key value");
  const size_t codebookBytes = r.checkCount(r.multiply(db.codebookSize, 32, "codebook byte"), 1, "codebook byte");
  db.codebook.resize(codebookBytes);
  r.bytes(reinterpret_cast<uint8_t*>(db.codebook.data()), codebookBytes, "codebook byte");
  const uint64_t blocksPerMap = uint64_t(db.width / 4) * (db.height / 4);
  const size_t indices = r.checkCount(r.multiply(maps, blocksPerMap, "block index"), 2, "block index");
  db.indices.resize(indices);
  r.u16s(db.indices.data(), indices, "block index");
}

// ---- BPRX (formats 1.1 and 1.2; legacy since 1.3) ---------------------------------------------
// The capsule proxy of the first push-out, replaced by the body anchors (BANC). Still written, empty,
// so that a reader of 1.1 or 1.2 (which requires the section) loads a newer file without a push-out;
// capsules in an older file are checked for structure and dropped (nothing runs on them any more).
constexpr uint64_t kCapsuleBytes = 4 + 12 + 12 + 4;
constexpr uint32_t kMaxLegacyCapsules = 64;

void writeLegacyBodyProxy(const Model&, ByteWriter& w) { w.u32(0); }

void readLegacyBodyProxy(ByteReader& r, Model&) {
  const uint32_t count = r.u32("body capsule count");
  if (count > kMaxLegacyCapsules)
    r.fail(std::to_string(count) + " body capsules; at most " + std::to_string(kMaxLegacyCapsules));
  r.checkCount(count, kCapsuleBytes, "body capsule");
  r.skip(size_t(count * kCapsuleBytes), "body capsules");
}

// ---- BANC (format 1.3) ------------------------------------------------------------------------
// ---- BAN2 (format 1.4): the second anchors, in BANC's layout after the count (no margin) -------
// ---- BAN3 (format 1.5): the third (cover) anchors, as BAN2 -------------------------------------
constexpr uint64_t kAnchorBytes = 12 + 12 + 4 + 4 + 2 * kAnchorInfluences + 4 * kAnchorInfluences;

void writeAnchorList(const std::vector<BodyAnchor>& list, ByteWriter& w) {
  for (const BodyAnchor& a : list) w.f32s({a.position.data(), 3});
  for (const BodyAnchor& a : list) w.f32s({a.normal.data(), 3});
  for (const BodyAnchor& a : list) w.f32(a.radius);
  for (const BodyAnchor& a : list) w.f32(a.clearance);
  for (const BodyAnchor& a : list) w.u16s(a.joints);
  for (const BodyAnchor& a : list) w.f32s(a.weights);
}

void readAnchorList(ByteReader& r, std::vector<BodyAnchor>& list, uint32_t count, uint32_t slot) {
  // (the reader's names are C strings: one for each set)
  auto name = [slot](const char* first, const char* second, const char* third) {
    return slot == 0 ? first : slot == 1 ? second : third;
  };
  list.resize(r.checkCount(count, kAnchorBytes, name("body anchor", "second body anchor", "third body anchor")));
  for (BodyAnchor& a : list)
    r.f32s(a.position.data(), 3,
           name("body anchor position", "second body anchor position", "third body anchor position"));
  for (BodyAnchor& a : list)
    r.f32s(a.normal.data(), 3, name("body anchor normal", "second body anchor normal", "third body anchor normal"));
  for (BodyAnchor& a : list)
    a.radius = r.f32(name("body anchor radius", "second body anchor radius", "third body anchor radius"));
  for (BodyAnchor& a : list)
    a.clearance = r.f32(name("body anchor clearance", "second body anchor clearance", "third body anchor clearance"));
  for (BodyAnchor& a : list)
    r.u16s(a.joints.data(), a.joints.size(),
           name("body anchor joint", "second body anchor joint", "third body anchor joint"));
  for (BodyAnchor& a : list)
    r.f32s(a.weights.data(), a.weights.size(),
           name("body anchor weight", "second body anchor weight", "third body anchor weight"));
}

void writeBodyAnchors(const Model& m, ByteWriter& w) {
  const BodyAnchors& b = m.bodyAnchors;
  w.u32(count32(b.anchors.size(), "body anchor"));
  w.f32(b.margin);
  writeAnchorList(b.anchors, w);
}

void readBodyAnchors(ByteReader& r, Model& m) {
  const uint32_t count = r.u32("body anchor count");
  m.bodyAnchors.margin = r.f32("body anchor margin");
  readAnchorList(r, m.bodyAnchors.anchors, count, 0);
}

void writeSecondAnchors(const Model& m, ByteWriter& w) {
  w.u32(count32(m.bodyAnchors.second.size(), "second body anchor"));
  writeAnchorList(m.bodyAnchors.second, w);
}

void readSecondAnchors(ByteReader& r, Model& m) {
  readAnchorList(r, m.bodyAnchors.second, r.u32("second body anchor count"), 1);
}

void writeThirdAnchors(const Model& m, ByteWriter& w) {
  w.u32(count32(m.bodyAnchors.third.size(), "third body anchor"));
  writeAnchorList(m.bodyAnchors.third, w);
}

void readThirdAnchors(ByteReader& r, Model& m) {
  readAnchorList(r, m.bodyAnchors.third, r.u32("third body anchor count"), 2);
}

// ---- NOVG (format 1.2) ------------------------------------------------------------------------
void writeNoveltyGuard(const Model& m, ByteWriter& w) {
  const NoveltyGuard& g = m.noveltyGuard;
  w.u32(count32(size_t(g.centres.rows()), "novelty centre"));
  w.u32(count32(size_t(g.centres.cols()), "novelty input"));
  for (Eigen::Index i = 0; i < g.centres.rows(); ++i)
    for (Eigen::Index j = 0; j < g.centres.cols(); ++j) w.f32(g.centres(i, j));
  w.f32(g.unit);
  w.u32(count32(size_t(g.weightMin.size()), "novelty weight range"));
  w.f32s({g.weightMin.data(), size_t(g.weightMin.size())});
  w.f32s({g.weightMax.data(), size_t(g.weightMax.size())});
  w.f32(g.blendStart);
  w.f32(g.blendEnd);
  w.f32(g.flagAbove);
}

void readNoveltyGuard(ByteReader& r, Model& m) {
  NoveltyGuard& g = m.noveltyGuard;
  const uint32_t rows = r.u32("novelty centre count"), cols = r.u32("novelty input count");
  r.checkCount(r.multiply(rows, cols, "novelty centre value"), 4, "novelty centre value");
  g.centres.resize(rows, cols);
  if (cols > 0)
    for (Eigen::Index i = 0; i < g.centres.rows(); ++i)
      for (Eigen::Index j = 0; j < g.centres.cols(); ++j) g.centres(i, j) = r.f32("novelty centre value");
  g.unit = r.f32("novelty unit");
  const size_t k = r.checkCount(r.u32("novelty weight range count"), 8, "novelty weight range");
  g.weightMin.resize(Eigen::Index(k));
  g.weightMax.resize(Eigen::Index(k));
  r.f32s(g.weightMin.data(), k, "novelty weight minimum");
  r.f32s(g.weightMax.data(), k, "novelty weight maximum");
  g.blendStart = r.f32("novelty blend start");
  g.blendEnd = r.f32("novelty blend end");
  g.flagAbove = r.f32("novelty flag threshold");
}

// ---- BCOV (format 1.2) ------------------------------------------------------------------------
void writeBodyCoverage(const Model& m, ByteWriter& w) {
  w.u32(m.bodyCoverage.bodyTriangles);
  w.u32(count32(m.bodyCoverage.covered.size(), "covered body triangle"));
  for (uint32_t t : m.bodyCoverage.covered) w.u32(t);
}

void readBodyCoverage(ByteReader& r, Model& m) {
  m.bodyCoverage.bodyTriangles = r.u32("body triangle count");
  m.bodyCoverage.covered.resize(r.checkCount(r.u32("covered body triangle count"), 4, "covered body triangle"));
  for (uint32_t& t : m.bodyCoverage.covered) t = r.u32("covered body triangle");
}

// ---- TFLT, META -------------------------------------------------------------------------------
void writeTemporalFilter(const Model& m, ByteWriter& w) { w.f32(m.temporalFilter.timeConstantSeconds); }
void readTemporalFilter(ByteReader& r, Model& m) { m.temporalFilter.timeConstantSeconds = r.f32("time constant"); }

void writeMetadata(const Model& m, ByteWriter& w) { w.text(m.metadata); }
void readMetadata(ByteReader& r, Model& m) {
  const auto text = r.view(r.remaining(), "metadata");
  m.metadata.assign(text.begin(), text.end());
}

}  // namespace

const std::vector<SectionCodec>& sectionCodecs() {
  static const std::vector<SectionCodec> codecs = {
      {"SKEL", writeSkeleton, readSkeleton},
      {"INPJ", writeInputJoints, readInputJoints},
      {"NRMI", writeInputNorm, readInputNorm},
      {"NRMO", writeOutputNorm, readOutputNorm},
      {"MLP ", writeMlp, readMlp},
      {"MPCA", writeMeshPca, readMeshPca},
      {"MESH", writeMesh, readMesh},
      {"SKIN", writeSkin, readSkin},
      {"NMDB", writeNormalMaps, readNormalMaps},
      {"TFLT", writeTemporalFilter, readTemporalFilter},
      {"BPRX", writeLegacyBodyProxy, readLegacyBodyProxy, 1},
      {"NOVG", writeNoveltyGuard, readNoveltyGuard, 2},
      {"BCOV", writeBodyCoverage, readBodyCoverage, 2},
      {"BANC", writeBodyAnchors, readBodyAnchors, 3},
      {"BAN2", writeSecondAnchors, readSecondAnchors, 4},
      {"BAN3", writeThirdAnchors, readThirdAnchors, 5},
      {"META", writeMetadata, readMetadata},
  };
  return codecs;
}

}  // namespace swish::model_sections
