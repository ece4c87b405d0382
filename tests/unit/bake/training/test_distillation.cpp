// Kernel ridge regression (the distillation teacher) fits a smooth function and predicts it between the
// samples, deterministically, and refuses bad data; distillation's synthetic poses change the input joints
// only, blends stay between a pose and its neighbour, mixes take each joint from a training pose, and the
// teacher labels them; the MLP's validation share ignores the distilled samples.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "support/random_model.hpp"
#include "swish/bake/training/distillation.hpp"
#include "swish/bake/training/kernel_ridge.hpp"
#include "swish/bake/training/mlp_trainer.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"
#include "swish/runtime/theta.hpp"

using namespace swish;
using namespace swish::bake;

namespace {

// y = (sin(2 x0) + x1^2, x0 x1) on n points drawn in [-1, 1]^2.
void smoothSamples(size_t n, uint64_t seed, MatXf& x, MatXf& y) {
  Rng rng(seed);
  x.resize(2, Eigen::Index(n));
  y.resize(2, Eigen::Index(n));
  for (Eigen::Index i = 0; i < Eigen::Index(n); ++i) {
    x(0, i) = rng.uniformf(-1.f, 1.f), x(1, i) = rng.uniformf(-1.f, 1.f);
    y(0, i) = std::sin(2.f * x(0, i)) + x(1, i) * x(1, i);
    y(1, i) = x(0, i) * x(1, i);
  }
}

double rms(const MatXf& a, const MatXf& b) { return std::sqrt((a - b).squaredNorm() / double(a.size())); }

// Poses of a 3-joint skeleton: joint 1 turned about z by angles[i], joint 2 about x by angles2[i]; joint 0 at rest.
std::vector<Pose> turnedPoses(const std::vector<float>& angles, const std::vector<float>& angles2) {
  std::vector<Pose> out(angles.size());
  for (size_t i = 0; i < angles.size(); ++i) {
    out[i].local = {Quatf::Identity(), Quatf(Eigen::AngleAxisf(angles[i], Vec3f::UnitZ())),
                    Quatf(Eigen::AngleAxisf(angles2[i], Vec3f::UnitX()))};
  }
  return out;
}

MatXf thetaOf(const std::vector<Pose>& poses, const std::vector<uint32_t>& joints) {
  MatXf t(Eigen::Index(6 * joints.size()), Eigen::Index(poses.size()));
  for (size_t i = 0; i < poses.size(); ++i) {
    const std::vector<float> th = runtime::computeTheta(joints, false, poses[i].local);
    t.col(Eigen::Index(i)) = Eigen::Map<const VecXf>(th.data(), Eigen::Index(th.size()));
  }
  return t;
}

}  // namespace

TEST(KernelRidge, PredictsASmoothFunctionBetweenItsSamples) {
  MatXf x, y, xt, yt;
  smoothSamples(300, test::testSeed(11), x, y);
  smoothSamples(200, test::testSeed(12), xt, yt);
  const KernelRidgeFit fit = fitKernelRidge(x, y);
  const MatXf mean = y.rowwise().mean().replicate(1, yt.cols());
  const double err = rms(fit.predict(xt), yt), baseline = rms(mean, yt);
  // 300 samples of a function with curvature ~4 over the square: a Gaussian-kernel interpolant is within a few
  // percent of its spread (measured 0.004 against 0.52 for the mean); 5 % of the mean's error leaves room for
  // other seeds while a fit that merely smoothed towards the mean would fail.
  EXPECT_LT(err, 0.05 * baseline) << "test rms " << err << ", the mean's " << baseline;
  EXPECT_EQ(fit.trials.size(), KernelRidgeOptions{}.widthScales.size() * KernelRidgeOptions{}.lambdas.size());
  EXPECT_GT(fit.nearestMedian, 0.0);
  EXPECT_DOUBLE_EQ(fit.width, fit.widthScale * fit.nearestMedian);
  // The chosen pair is the grid's best on the validation share.
  for (const auto& t : fit.trials) EXPECT_GE(t.validationError, fit.validationError);
}

TEST(KernelRidge, IsDeterministicForASeed) {
  MatXf x, y;
  smoothSamples(80, test::testSeed(13), x, y);
  const KernelRidgeFit a = fitKernelRidge(x, y), b = fitKernelRidge(x, y);
  EXPECT_EQ(a.widthScale, b.widthScale);
  EXPECT_EQ(a.lambda, b.lambda);
  EXPECT_TRUE((a.predict(x).array() == b.predict(x).array()).all());
}

TEST(KernelRidge, RefusesBadData) {
  MatXf x, y;
  smoothSamples(20, test::testSeed(14), x, y);
  EXPECT_THROW(fitKernelRidge(x, y.leftCols(10)), Error);
  EXPECT_THROW(fitKernelRidge(x.leftCols(3), y.leftCols(3)), Error);
  MatXf bad = x;
  bad(1, 4) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(fitKernelRidge(bad, y), Error);
  KernelRidgeOptions o;
  o.lambdas = {};
  EXPECT_THROW(fitKernelRidge(x, y, o), Error);
  o = {};
  o.widthScales = {-1.0};
  EXPECT_THROW(fitKernelRidge(x, y, o), Error);
  o = {};
  o.outputWeights = {1.0};  // two outputs
  EXPECT_THROW(fitKernelRidge(x, y, o), Error);
  const KernelRidgeFit fit = fitKernelRidge(x, y);
  EXPECT_THROW(fit.predict(MatXf::Zero(3, 2)), Error);
  // Every input the same: no width to take.
  EXPECT_THROW(fitKernelRidge(MatXf::Ones(2, 20), y), Error);
}

TEST(Distillation, BlendsLieBetweenAPoseAndItsNeighbour) {
  // Joint 1 turned by 0, 10, ..., 190 degrees about z, joint 2 still: with one neighbour every blend's angle is
  // between a pose's and an adjacent one's, so its Theta is within half a step of a training pose's.
  std::vector<float> angles, still;
  for (int i = 0; i < 20; ++i) angles.push_back(float(i) * 10.f * 3.14159265f / 180.f), still.push_back(0.f);
  const std::vector<Pose> poses = turnedPoses(angles, still);
  std::vector<const Pose*> ptrs;
  for (const Pose& p : poses) ptrs.push_back(&p);
  const std::vector<uint32_t> joints = {1, 2};
  const MatXf theta = thetaOf(poses, joints);
  MatXf lambda(1, theta.cols());
  for (Eigen::Index i = 0; i < theta.cols(); ++i) lambda(0, i) = angles[size_t(i)];
  DistillSettings s;
  s.poses = 200;
  s.mixShare = 0.0;
  s.neighbours = 1;
  const DistilledSamples d = distilledSamples(ptrs, joints, false, theta, lambda, s);
  ASSERT_EQ(d.theta.cols(), 200);
  ASSERT_EQ(d.lambda.cols(), 200);
  EXPECT_EQ(d.blends, 200u);
  EXPECT_EQ(d.mixes, 0u);
  const double step = (theta.col(1) - theta.col(0)).norm();
  for (Eigen::Index i = 0; i < d.theta.cols(); ++i) {
    const double nearest = (theta.colwise() - d.theta.col(i)).colwise().norm().minCoeff();
    EXPECT_LE(nearest, 0.5 * step + 1e-5) << "sample " << i;
    // Joint 2 never moved in training, so no blend moves it.
    EXPECT_TRUE(d.theta.col(i).tail(6).isApprox(theta.col(0).tail(6), 1e-6f)) << "sample " << i;
  }
  // The teacher labels the blends with the angle they were made at (the one their Theta decodes to): a Gaussian
  // interpolant of a smooth function of the angle is close to it between the samples, within 1 degree; in the
  // first and last steps of the range it bends towards the mean (measured up to 1.3 degrees), within 2.
  const float degree = 3.14159265f / 180.f;
  for (Eigen::Index i = 0; i < d.theta.cols(); ++i) {
    const float angle = std::atan2(d.theta(1, i), d.theta(0, i));  // the first column of joint 1's rotation
    const float wrapped = angle < -0.1f ? angle + 360.f * degree : angle;
    const bool end = wrapped < 10.f * degree || wrapped > 180.f * degree;
    EXPECT_NEAR(d.lambda(0, i), wrapped, (end ? 2.f : 1.f) * degree) << "sample " << i;
  }
}

TEST(Distillation, MixesTakeEachJointFromATrainingPose) {
  Rng rng(test::testSeed(15));
  std::vector<float> a, b;
  for (int i = 0; i < 30; ++i) a.push_back(rng.uniformf(-1.f, 1.f)), b.push_back(rng.uniformf(-1.f, 1.f));
  const std::vector<Pose> poses = turnedPoses(a, b);
  std::vector<const Pose*> ptrs;
  for (const Pose& p : poses) ptrs.push_back(&p);
  const std::vector<uint32_t> joints = {1, 2};
  const MatXf theta = thetaOf(poses, joints);
  MatXf lambda = theta.topRows(2);
  DistillSettings s;
  s.poses = 100;
  s.mixShare = 1.0;
  s.swapProbability = 1.0;
  const DistilledSamples d = distilledSamples(ptrs, joints, false, theta, lambda, s);
  EXPECT_EQ(d.mixes, 100u);
  size_t recombined = 0;
  for (Eigen::Index i = 0; i < d.theta.cols(); ++i) {
    bool sameColumn = false;
    for (int block = 0; block < 2; ++block) {
      bool found = false;
      for (Eigen::Index p = 0; p < theta.cols(); ++p) {
        found |= d.theta.col(i).segment(6 * block, 6) == theta.col(p).segment(6 * block, 6);
        if (block == 0 && d.theta.col(i) == theta.col(p)) sameColumn = true;
      }
      EXPECT_TRUE(found) << "sample " << i << " joint block " << block;
    }
    recombined += !sameColumn;
  }
  // Two joints drawn independently from 30 poses: almost every mix is a combination no pose had.
  EXPECT_GT(recombined, 90u);
  // Deterministic for a seed; another seed draws other poses.
  const DistilledSamples again = distilledSamples(ptrs, joints, false, theta, lambda, s);
  EXPECT_TRUE((again.theta.array() == d.theta.array()).all());
  s.seed = 2;
  EXPECT_FALSE((distilledSamples(ptrs, joints, false, theta, lambda, s).theta.array() == d.theta.array()).all());
}

TEST(Distillation, RefusesBadSettings) {
  std::vector<float> a = {0.f, 0.2f, 0.4f, 0.6f, 0.8f}, b(5, 0.f);
  const std::vector<Pose> poses = turnedPoses(a, b);
  std::vector<const Pose*> ptrs;
  for (const Pose& p : poses) ptrs.push_back(&p);
  const std::vector<uint32_t> joints = {1};
  const MatXf theta = thetaOf(poses, joints);
  const MatXf lambda = theta.topRows(1);
  DistillSettings s;
  s.poses = 10;
  EXPECT_NO_THROW(distilledSamples(ptrs, joints, false, theta, lambda, s));
  EXPECT_THROW(distilledSamples(ptrs, joints, false, theta.leftCols(4), lambda, s), Error);
  EXPECT_THROW(distilledSamples(ptrs, {}, false, theta, lambda, s), Error);
  const std::vector<uint32_t> outside = {7};
  EXPECT_THROW(distilledSamples(ptrs, outside, false, theta, lambda, s), Error);
  DistillSettings bad = s;
  bad.mixShare = 1.5;
  EXPECT_THROW(distilledSamples(ptrs, joints, false, theta, lambda, bad), Error);
  bad = s;
  bad.swapProbability = 0.0;
  EXPECT_THROW(distilledSamples(ptrs, joints, false, theta, lambda, bad), Error);
}

TEST(Distillation, TheValidationShareIgnoresDistilledSamples) {
  // 40 real samples and 400 always-trained ones: with the pool set to the real ones the validation share is 10 %
  // of 40, as without the distilled samples, and none of it is distilled.
  MatXf x, y;
  smoothSamples(440, test::testSeed(16), x, y);
  MlpTrainOptions o;
  o.hiddenLayers = 1;
  o.hiddenWidth = 4;
  o.maxEpochs = 2;
  o.validationPool = 40;
  for (uint32_t i = 40; i < 440; ++i) o.alwaysTrain.push_back(i);
  const MlpTrainResult r = trainMlp(x, y, o);
  EXPECT_EQ(r.validationSamples.size(), 4u);
  for (uint32_t v : r.validationSamples) EXPECT_LT(v, 40u);
  o.validationPool = 441;
  EXPECT_THROW(trainMlp(x, y, o), Error);
}
