#include "swish/bake/training/kernel_ridge.hpp"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "swish/bake/training/mlp_trainer.hpp"
#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

namespace swish::bake {

namespace {

// |a_i - b_j|^2 for every column pair (A: D x n, B: D x m), clamped at 0 against rounding.
MatXd squaredDistances(const MatXd& a, const MatXd& b) {
  MatXd d = -2.0 * a.transpose() * b;
  d.colwise() += a.colwise().squaredNorm().transpose();
  d.rowwise() += b.colwise().squaredNorm();
  return d.cwiseMax(0.0);
}

MatXd gaussian(const MatXd& squared, double width) {
  return (squared * (-0.5 / (width * width))).array().exp().matrix();
}

MatXd standardised(const MatXf& inputs, const Normalisation& n) {
  return ((inputs.colwise() - n.mean).array().colwise() / n.scale.array()).matrix().cast<double>();
}

// alpha of (K + lambda I) alpha = y; false where the factorisation fails (not positive definite).
bool solveRidge(const MatXd& kernel, double lambda, const MatXd& yT, MatXd& alpha) {
  MatXd a = kernel;
  a.diagonal().array() += lambda;
  const Eigen::LLT<MatXd> llt(a);
  if (llt.info() != Eigen::Success) return false;
  alpha = llt.solve(yT);
  return alpha.allFinite();
}

}  // namespace

MatXf KernelRidgeFit::predict(const MatXf& inputs) const {
  if (inputs.rows() != centres.rows())
    throw Error("kernel ridge: inputs of " + std::to_string(inputs.rows()) + " values, the fit takes " +
                std::to_string(centres.rows()));
  const MatXd k = gaussian(squaredDistances(centres, standardised(inputs, inputNorm)), width);
  return ((alpha.transpose() * k).colwise() + outputMean).cast<float>();
}

KernelRidgeFit fitKernelRidge(const MatXf& inputs, const MatXf& outputs, const KernelRidgeOptions& o) {
  const Eigen::Index n = inputs.cols();
  if (outputs.cols() != n) throw Error("kernel ridge: inputs and outputs differ in sample count");
  if (inputs.rows() < 1 || outputs.rows() < 1) throw Error("kernel ridge: empty input or output vectors");
  if (n < 4) throw Error("kernel ridge: needs at least 4 samples, got " + std::to_string(n));
  if (!inputs.allFinite() || !outputs.allFinite()) throw Error("kernel ridge: the samples contain NaN or Inf");
  if (o.widthScales.empty() || o.lambdas.empty()) throw Error("kernel ridge: empty width or lambda grid");
  for (double w : o.widthScales)
    if (!(w > 0.0) || !std::isfinite(w)) throw Error("kernel ridge: width scales must be positive");
  for (double l : o.lambdas)
    if (!(l > 0.0) || !std::isfinite(l)) throw Error("kernel ridge: lambdas must be positive");
  if (!(o.validationFraction > 0.0 && o.validationFraction < 1.0))
    throw Error("kernel ridge: validation fraction must be in (0, 1)");
  if (!o.outputWeights.empty() && Eigen::Index(o.outputWeights.size()) != outputs.rows())
    throw Error("kernel ridge: " + std::to_string(o.outputWeights.size()) + " output weights for " +
                std::to_string(outputs.rows()) + " outputs");
  VecXd weights = VecXd::Ones(outputs.rows());
  for (size_t i = 0; i < o.outputWeights.size(); ++i) {
    if (!(o.outputWeights[i] >= 0.0) || !std::isfinite(o.outputWeights[i]))
      throw Error("kernel ridge: output weights must be finite and >= 0");
    weights[Eigen::Index(i)] = o.outputWeights[i];
  }

  KernelRidgeFit fit;
  fit.inputNorm = standardisation(inputs);
  fit.centres = standardised(inputs, fit.inputNorm);
  const MatXd y = outputs.cast<double>();
  const MatXd all = squaredDistances(fit.centres, fit.centres);
  std::vector<double> nearest(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  for (Eigen::Index j = 0; j < n; ++j)
    for (Eigen::Index i = 0; i < n; ++i)
      if (i != j) nearest[size_t(j)] = std::min(nearest[size_t(j)], all(i, j));
  std::nth_element(nearest.begin(), nearest.begin() + long(nearest.size() / 2), nearest.end());
  fit.nearestMedian = std::sqrt(nearest[nearest.size() / 2]);
  if (!(fit.nearestMedian > 0.0))
    throw Error("kernel ridge: most samples share their input with another one (median nearest distance 0)");

  // The grid on a validation share: fit on the rest, error on it.
  Rng rng(o.seed);
  const size_t nVal = std::clamp<size_t>(size_t(std::lround(o.validationFraction * double(n))), 1, size_t(n) - 3);
  const IndexSplit split = seededSplit(size_t(n), nVal, rng);
  auto gather = [](const MatXd& m, const std::vector<uint32_t>& rows, const std::vector<uint32_t>& cols) {
    MatXd out(Eigen::Index(rows.size()), Eigen::Index(cols.size()));
    for (size_t c = 0; c < cols.size(); ++c)
      for (size_t r = 0; r < rows.size(); ++r) out(Eigen::Index(r), Eigen::Index(c)) = m(rows[r], cols[c]);
    return out;
  };
  const MatXd dFit = gather(all, split.kept, split.kept), dVal = gather(all, split.kept, split.held);
  MatXd yFit(y.rows(), Eigen::Index(split.kept.size())), yVal(y.rows(), Eigen::Index(split.held.size()));
  for (size_t i = 0; i < split.kept.size(); ++i) yFit.col(Eigen::Index(i)) = y.col(split.kept[i]);
  for (size_t i = 0; i < split.held.size(); ++i) yVal.col(Eigen::Index(i)) = y.col(split.held[i]);
  const VecXd fitMean = yFit.rowwise().mean();
  const MatXd yFitT = (yFit.colwise() - fitMean).transpose();
  double best = std::numeric_limits<double>::infinity();
  for (double scale : o.widthScales) {
    const double width = scale * fit.nearestMedian;
    const MatXd kFit = gaussian(dFit, width), kVal = gaussian(dVal, width);
    for (double lambda : o.lambdas) {
      MatXd alpha;
      double error = std::numeric_limits<double>::infinity();
      if (solveRidge(kFit, lambda, yFitT, alpha)) {
        const MatXd residual = ((alpha.transpose() * kVal).colwise() + fitMean) - yVal;
        error = (residual.cwiseAbs2().transpose() * weights).sum() / double(yVal.cols());
      }
      fit.trials.push_back({scale, lambda, error});
      if (error < best) best = error, fit.widthScale = scale, fit.lambda = lambda;
    }
  }
  if (!std::isfinite(best)) throw Error("kernel ridge: no width and lambda of the grid gave a finite fit");
  fit.validationError = best;

  // Refitted on every sample at the chosen pair.
  fit.width = fit.widthScale * fit.nearestMedian;
  fit.outputMean = y.rowwise().mean();
  if (!solveRidge(gaussian(all, fit.width), fit.lambda, (y.colwise() - fit.outputMean).transpose(), fit.alpha))
    throw Error("kernel ridge: the fit on all samples failed at the chosen width and lambda");
  return fit;
}

}  // namespace swish::bake
