// k-means: separated clusters are found, seeding is deterministic, duplicates cap the cluster count,
// empty clusters are re-seeded, and the normal-map database picks real maps nearest the centres.
#include <gtest/gtest.h>

#include <set>

#include "support/random_model.hpp"
#include "swish/bake/compression/kmeans.hpp"
#include "swish/bake/compression/normal_map_database.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

using namespace swish;
using namespace swish::bake;

namespace {
RowMatXf blobs(Rng& rng, int clusters, int perCluster, int dims, float spread) {
  RowMatXf p(clusters * perCluster, dims);
  for (int c = 0; c < clusters; ++c) {
    Eigen::RowVectorXf centre(dims);
    for (int d = 0; d < dims; ++d) centre[d] = float(c * 10 + d);
    for (int i = 0; i < perCluster; ++i)
      for (int d = 0; d < dims; ++d) p(c * perCluster + i, d) = centre[d] + spread * float(rng.normal());
  }
  return p;
}
}  // namespace

TEST(BakeKMeans, FindsSeparatedClustersDeterministically) {
  const uint64_t seed = test::testSeed(201);
  SCOPED_TRACE("seed " + std::to_string(seed));
  Rng rng(seed);
  const RowMatXf p = blobs(rng, 5, 40, 3, 0.3f);
  KMeansOptions o;
  o.clusters = 5;
  o.seed = 7;
  const KMeansResult a = kMeans(p, o), b = kMeans(p, o);
  EXPECT_EQ(a.assignment, b.assignment);
  EXPECT_EQ(a.centres, b.centres);
  // Every blob maps to exactly one cluster, of 40 points.
  for (int c = 0; c < 5; ++c) {
    std::set<uint32_t> labels;
    for (int i = 0; i < 40; ++i) labels.insert(a.assignment[size_t(c * 40 + i)]);
    EXPECT_EQ(labels.size(), 1u) << "blob " << c;
  }
  for (uint32_t s : a.clusterSizes) EXPECT_EQ(s, 40u);
  double direct = 0.0;
  for (Eigen::Index i = 0; i < p.rows(); ++i)
    direct += (p.row(i) - a.centres.row(a.assignment[size_t(i)])).squaredNorm();
  EXPECT_NEAR(a.inertia, direct, 1e-3 * direct);
  EXPECT_GE(a.iterations, 1);
  EXPECT_LT(a.inertia, 200 * 3 * 0.3 * 0.3 * 1.5);
}

TEST(BakeKMeans, DuplicatePointsCapTheClusterCount) {
  RowMatXf p(30, 2);
  for (int i = 0; i < 30; ++i) p.row(i) << float(i % 3), 1.f;  // only 3 distinct points
  KMeansOptions o;
  o.clusters = 8;
  const KMeansResult r = kMeans(p, o);
  EXPECT_EQ(r.centres.rows(), 3);
  EXPECT_DOUBLE_EQ(r.inertia, 0.0);
  EXPECT_TRUE(r.centres.allFinite());
}

TEST(BakeKMeans, EmptyClustersAreReseeded) {
  // Two far groups, and a seed budget that forces centres to collapse into one group at first:
  // with k = 6 on 2 tight blobs + a few outliers, some clusters empty out and must be re-seeded.
  Rng rng(test::testSeed(202));
  RowMatXf p = blobs(rng, 2, 50, 2, 0.01f);
  KMeansOptions o;
  o.clusters = 6;
  o.maxIterations = 30;
  const KMeansResult r = kMeans(p, o);
  EXPECT_EQ(r.centres.rows(), 6);
  for (uint32_t s : r.clusterSizes) EXPECT_GT(s, 0u);
  EXPECT_TRUE(r.centres.allFinite());
}

TEST(BakeKMeans, NearestCentresMatchesBruteForce) {
  Rng rng(test::testSeed(203));
  RowMatXf p(2500, 32), c(70, 32);
  for (Eigen::Index i = 0; i < p.size(); ++i) p.data()[i] = float(rng.normal());
  for (Eigen::Index i = 0; i < c.size(); ++i) c.data()[i] = float(rng.normal());
  std::vector<float> d2;
  const auto a = nearestCentres(p, c, &d2);
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    Eigen::Index best;
    const float bd = (c.rowwise() - p.row(i)).rowwise().squaredNorm().minCoeff(&best);
    EXPECT_NEAR(d2[size_t(i)], bd, 1e-3f * (1.f + bd));
    if (a[size_t(i)] != uint32_t(best)) {  // only a near-tie may differ (expanded-form rounding)
      EXPECT_NEAR((c.row(a[size_t(i)]) - p.row(i)).squaredNorm(), bd, 1e-3f * (1.f + bd));
    }
  }
}

TEST(BakeKMeans, BadInputIsAnError) {
  EXPECT_THROW(kMeans(RowMatXf(0, 3), {}), Error);
  KMeansOptions o;
  o.clusters = 0;
  EXPECT_THROW(kMeans(RowMatXf::Ones(4, 2), o), Error);
}

TEST(BakeNormalMapDatabase, PicksRealMapsNearestTheCentres) {
  Rng rng(test::testSeed(204));
  const RowMatXf pts = blobs(rng, 4, 25, 3, 0.2f);
  const MatXf codes = pts.transpose();
  const DatabaseSelection s = selectDatabaseMaps(codes, 4, 3);
  ASSERT_EQ(s.mapIndices.size(), 4u);
  std::set<uint32_t> blobsHit;
  for (size_t e = 0; e < 4; ++e) {
    EXPECT_EQ(s.keys.row(Eigen::Index(e)), codes.col(s.mapIndices[e]).transpose());  // keys are real codes
    blobsHit.insert(s.mapIndices[e] / 25);
  }
  EXPECT_EQ(blobsHit.size(), 4u);  // one map per blob
  for (Eigen::Index i = 0; i < codes.cols(); ++i) EXPECT_EQ(s.clusterOf[size_t(i)], nearestKey(s.keys, codes.col(i)));
  // Fewer distinct maps than asked: the database shrinks.
  MatXf same = MatXf::Zero(3, 10);
  same.rightCols(5).setOnes();
  EXPECT_EQ(selectDatabaseMaps(same, 128, 1).mapIndices.size(), 2u);
}
