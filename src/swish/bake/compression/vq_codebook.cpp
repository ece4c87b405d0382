#include "swish/bake/compression/vq_codebook.hpp"

#include <algorithm>
#include <chrono>
#include <string>

#include "swish/core/error.hpp"

namespace swish::bake {

namespace {
double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

RowMatXf quantise(const RowMatXf& centres, std::vector<int8_t>& bytes) {
  bytes.resize(size_t(centres.size()));
  RowMatXf q(centres.rows(), centres.cols());
  for (Eigen::Index i = 0; i < centres.size(); ++i) {
    bytes[size_t(i)] = toSnorm8(centres.data()[i]);
    q.data()[i] = float(bytes[size_t(i)]) / 127.f;
  }
  return q;
}
}  // namespace

RowMatXf extractBlocks(const std::vector<const NormalMapImage*>& maps) {
  if (maps.empty()) throw Error("VQ: no maps to encode");
  const uint32_t w = maps.front()->width, h = maps.front()->height;
  if (w == 0 || h == 0 || w % 4 || h % 4)
    throw Error("VQ: map size " + std::to_string(w) + "x" + std::to_string(h) + " is not a positive multiple of 4");
  const size_t perMap = size_t(w / 4) * (h / 4);
  RowMatXf blocks(Eigen::Index(perMap * maps.size()), 32);
  for (size_t m = 0; m < maps.size(); ++m) {
    const NormalMapImage& map = *maps[m];
    if (map.width != w || map.height != h || map.xy.size() != size_t(w) * h * 2)
      throw Error("VQ: map " + std::to_string(m) + " differs in size from map 0");
    for (uint32_t by = 0; by < h / 4; ++by)
      for (uint32_t bx = 0; bx < w / 4; ++bx) {
        const Eigen::Index row = Eigen::Index(m * perMap + size_t(by) * (w / 4) + bx);
        for (uint32_t t = 0; t < 16; ++t) {
          const size_t texel = size_t(by * 4 + t / 4) * w + (bx * 4 + t % 4);
          blocks(row, 2 * t) = std::clamp(map.xy[2 * texel], -1.f, 1.f);
          blocks(row, 2 * t + 1) = std::clamp(map.xy[2 * texel + 1], -1.f, 1.f);
        }
      }
  }
  return blocks;
}

VqReport encodeVq(const std::vector<const NormalMapImage*>& maps, const VqOptions& o, NormalMapDatabase& db) {
  if (o.codebookSize < 1 || o.codebookSize > 65536)
    throw Error("VQ: codebook size " + std::to_string(o.codebookSize) + " outside 1..65536 (16-bit indices)");
  VqReport rep;
  const RowMatXf blocks = extractBlocks(maps);
  rep.blocks = uint64_t(blocks.rows());

  auto t0 = std::chrono::steady_clock::now();
  // Deterministic training subsample: an evenly strided selection (keeps every map represented).
  RowMatXf training;
  const uint64_t want = o.trainingBlocks == 0 ? rep.blocks : std::min<uint64_t>(o.trainingBlocks, rep.blocks);
  if (want == rep.blocks) {
    training = blocks;
  } else {
    training.resize(Eigen::Index(want), 32);
    for (uint64_t i = 0; i < want; ++i)
      training.row(Eigen::Index(i)) = blocks.row(Eigen::Index(double(i) * double(rep.blocks) / double(want)));
  }
  KMeansOptions ko;
  ko.clusters = int(o.codebookSize);
  ko.maxIterations = o.iterations;
  ko.relativeTolerance = 1e-4;
  ko.seed = o.seed;
  ko.seedingSampleLimit = int(std::min<uint64_t>(want, std::max<uint64_t>(16384, 4ull * o.codebookSize)));
  const KMeansResult km = kMeans(training, ko);
  rep.iterations = km.iterations;
  rep.trainingSeconds = secondsSince(t0);

  t0 = std::chrono::steady_clock::now();
  std::vector<int8_t> bytes;
  RowMatXf codebook = quantise(km.centres, bytes);
  std::vector<uint32_t> assign = nearestCentres(blocks, codebook);
  for (int pass = 0; pass < o.refinements; ++pass) {
    // Refit each entry to every block that uses it (entries nobody uses keep their value).
    MatXd sums = MatXd::Zero(codebook.rows(), 32);
    std::vector<uint32_t> counts(size_t(codebook.rows()), 0);
    for (Eigen::Index i = 0; i < blocks.rows(); ++i) {
      sums.row(assign[size_t(i)]) += blocks.row(i).cast<double>();
      ++counts[assign[size_t(i)]];
    }
    RowMatXf refit = codebook;
    for (Eigen::Index c = 0; c < codebook.rows(); ++c)
      if (counts[size_t(c)]) refit.row(c) = (sums.row(c) / double(counts[size_t(c)])).cast<float>();
    codebook = quantise(refit, bytes);
    assign = nearestCentres(blocks, codebook);
  }
  rep.assignmentSeconds = secondsSince(t0);

  db.width = maps.front()->width;
  db.height = maps.front()->height;
  db.codebookSize = uint32_t(codebook.rows());
  db.codebook = std::move(bytes);
  db.indices.resize(assign.size());
  for (size_t i = 0; i < assign.size(); ++i) db.indices[i] = uint16_t(assign[i]);
  rep.codebookEntries = db.codebookSize;
  rep.codebookBytes = db.codebook.size();
  rep.indexBytes = db.indices.size() * sizeof(uint16_t);
  return rep;
}

NormalMapImage decodeVqMap(const NormalMapDatabase& db, uint32_t map) {
  if (map >= db.mapCount() && !(db.keys.rows() == 0 && size_t(map) * db.blocksPerMap() < db.indices.size()))
    throw Error("VQ decode: map " + std::to_string(map) + " outside the database");
  NormalMapImage out{db.width, db.height, std::vector<float>(size_t(db.width) * db.height * 2)};
  const uint32_t bw = db.width / 4;
  for (uint32_t y = 0; y < db.height; ++y)
    for (uint32_t x = 0; x < db.width; ++x) {
      const uint32_t b = (y / 4) * bw + x / 4, t = (y % 4) * 4 + (x % 4);
      const uint32_t e = db.indices[size_t(map) * db.blocksPerMap() + b];
      if (e >= db.codebookSize) throw Error("VQ decode: block index outside the codebook");
      for (int c = 0; c < 2; ++c)
        out.xy[2 * (size_t(y) * db.width + x) + c] =
            std::clamp(float(db.codebook[(size_t(e) * 16 + t) * 2 + c]) / 127.f, -1.f, 1.f);
    }
  return out;
}

}  // namespace swish::bake
