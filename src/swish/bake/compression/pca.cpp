#include "swish/bake/compression/pca.hpp"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <string>

#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

namespace swish::bake {

MatXf PcaResult::project(const MatXf& samples) const { return basis.transpose() * (samples.colwise() - mean); }

MatXf PcaResult::reconstruct(const MatXf& codes) const { return (basis * codes).colwise() + mean; }

namespace {

// Orthonormal basis of the columns of y (thin Householder QR; defined for rank-deficient y too).
MatXf orthonormalColumns(const MatXf& y) {
  Eigen::HouseholderQR<MatXf> qr(y);
  return qr.householderQ() * MatXf::Identity(y.rows(), y.cols());
}

struct Decomposition {
  MatXd u;  // D x r
  VecXd s;  // r
};

Decomposition exactSvd(const MatXf& x, const VecXf& mean) {
  MatXd centred = (x.colwise() - mean).cast<double>();
  Eigen::BDCSVD<MatXd> svd(centred, Eigen::ComputeThinU);
  return {svd.matrixU(), svd.singularValues()};
}

// Randomised range finder on the implicitly centred matrix Xc = X - mean * 1^T.
Decomposition randomizedSvd(const MatXf& x, const VecXf& mean, int rank, const PcaOptions& o) {
  const Eigen::Index n = x.cols();
  const int l = int(std::min<Eigen::Index>(rank + o.oversampling, std::min(n, x.rows())));
  Rng rng(o.seed);
  MatXf omega(n, l);
  for (Eigen::Index j = 0; j < l; ++j)
    for (Eigen::Index i = 0; i < n; ++i) omega(i, j) = float(rng.normal());
  auto timesXc = [&](const MatXf& m) -> MatXf {  // Xc * m   (D x l)
    MatXf r = x * m;
    r -= mean * m.colwise().sum();
    return r;
  };
  auto xcTransposeTimes = [&](const MatXf& q) -> MatXf {  // Xc^T * q   (N x l)
    MatXf r = x.transpose() * q;
    const Eigen::RowVectorXf mq = mean.transpose() * q;
    r.rowwise() -= mq;
    return r;
  };
  MatXf q = orthonormalColumns(timesXc(omega));
  for (int it = 0; it < o.powerIterations; ++it) {
    MatXf z = orthonormalColumns(xcTransposeTimes(q));
    q = orthonormalColumns(timesXc(z));
  }
  const MatXd b = xcTransposeTimes(q).transpose().cast<double>();  // l x N
  Eigen::BDCSVD<MatXd> svd(b, Eigen::ComputeThinU);
  return {q.cast<double>() * svd.matrixU(), svd.singularValues()};
}

}  // namespace

PcaResult fitPca(const MatXf& samples, const PcaOptions& o, const char* what) {
  const std::string name(what);
  if (samples.cols() == 0 || samples.rows() == 0) throw Error(name + ": no samples to analyse");
  if (!samples.allFinite()) throw Error(name + ": samples contain NaN or Inf");
  if (o.maxComponents < 0) throw Error(name + ": maxComponents must be >= 0");
  if (o.varianceToKeep < 0.0 || o.varianceToKeep > 1.0) throw Error(name + ": varianceToKeep must be in [0, 1]");

  PcaResult r;
  r.sampleCount = int(samples.cols());
  r.mean = (samples.cast<double>().rowwise().sum() / double(samples.cols())).cast<float>();
  for (Eigen::Index j = 0; j < samples.cols(); ++j)
    r.totalSquaredNorm += (samples.col(j) - r.mean).cast<double>().squaredNorm();

  const Eigen::Index maxRank = std::min(samples.rows(), samples.cols());
  const bool exact =
      o.method == PcaOptions::Method::Exact ||
      (o.method == PcaOptions::Method::Auto && double(samples.rows()) * double(samples.cols()) <= o.exactLimit);
  Decomposition d;
  if (exact) {
    d = exactSvd(samples, r.mean);
  } else {
    // The sketch must cover the components asked for; with a variance target and no count, take
    // what a sketch of reasonable size can hold and stop early below.
    const int want = o.maxComponents > 0 ? o.maxComponents : int(std::min<Eigen::Index>(maxRank, 64));
    d = randomizedSvd(samples, r.mean, std::min<int>(want, int(maxRank)), o);
    r.randomized = true;
  }
  r.singularValues = d.s;

  const Eigen::Index computed = d.s.size();
  r.explainedVariance.resize(computed + 1);
  r.residualSquaredNorm.resize(computed + 1);
  double captured = 0.0;
  for (Eigen::Index k = 0; k <= computed; ++k) {
    if (k > 0) captured += d.s[k - 1] * d.s[k - 1];
    const double residual = std::max(0.0, r.totalSquaredNorm - captured);
    r.residualSquaredNorm[k] = residual;
    r.explainedVariance[k] = r.totalSquaredNorm > 0.0 ? std::min(1.0, captured / r.totalSquaredNorm) : 1.0;
  }

  // Choose K: the count asked for, cut to the variance target; never components the data does not
  // have (singular value ~ 0) except that at least one is kept, so a model always has a mesh basis.
  Eigen::Index k = o.maxComponents > 0 ? std::min<Eigen::Index>(o.maxComponents, computed) : computed;
  if (o.varianceToKeep > 0.0) {
    Eigen::Index kv = 0;
    while (kv < k && r.explainedVariance[kv] < o.varianceToKeep) ++kv;
    k = kv;
  }
  // Singular values below float round-off of the input carry no data (the input is float; the
  // randomised path's implicit centring adds round-off of the size of the UNcentred data).
  const double tiny = 1e-6 * std::max(d.s.size() ? d.s[0] : 0.0, double(samples.norm()));
  Eigen::Index rank = 0;
  while (rank < computed && d.s[rank] > tiny && d.s[rank] > 0.0) ++rank;
  k = std::max<Eigen::Index>(1, std::min(k, rank));
  k = std::min<Eigen::Index>(k, d.u.cols());
  r.basis = d.u.leftCols(k).cast<float>();
  // Sign convention (deterministic across methods): the largest-magnitude entry of each column is positive.
  for (Eigen::Index c = 0; c < r.basis.cols(); ++c) {
    Eigen::Index i;
    r.basis.col(c).cwiseAbs().maxCoeff(&i);
    if (r.basis(i, c) < 0.f) r.basis.col(c) *= -1.f;
  }
  return r;
}

}  // namespace swish::bake
