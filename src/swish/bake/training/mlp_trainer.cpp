#include "swish/bake/training/mlp_trainer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "swish/core/error.hpp"
#include "swish/core/rng.hpp"

namespace swish::bake {

Normalisation standardisation(const MatXf& samples) {
  const Eigen::Index d = samples.rows(), n = samples.cols();
  Normalisation nrm{VecXf::Zero(d), VecXf::Ones(d)};
  if (n == 0) return nrm;
  const MatXd x = samples.cast<double>();
  const VecXd mean = x.rowwise().mean();
  const VecXd var = (x.colwise() - mean).cwiseAbs2().rowwise().mean();
  const double biggest = var.size() ? var.maxCoeff() : 0.0;
  for (Eigen::Index i = 0; i < d; ++i) {
    nrm.mean[i] = float(mean[i]);
    const double sd = std::sqrt(var[i]);
    nrm.scale[i] = (var[i] > 1e-12 * std::max(biggest, 1e-30) && sd > 1e-12) ? float(sd) : 1.f;
  }
  return nrm;
}

namespace {

template <class M>
void checkFinite(const M& m, const char* what) {
  if (!m.allFinite()) throw Error(std::string("MLP training: ") + what + " contain NaN or Inf");
}

// Adam (Kingma & Ba) state for one parameter tensor.
struct AdamSlot {
  MatXf m, v;
};

Mlp toModelMlp(const MlpNetwork<float>& net) {
  Mlp out;
  for (int l = 0; l < net.layers(); ++l) out.layers.push_back({net.weights[size_t(l)], net.biases[size_t(l)]});
  return out;
}

}  // namespace

namespace {

std::vector<bool> pinnedMask(size_t n, std::span<const uint32_t> pinned) {
  std::vector<bool> isPinned(n, false);
  for (uint32_t i : pinned)
    if (i < n) isPinned[i] = true;
  return isPinned;
}

// The first `held` of `order` (the unpinned indices in the split's order) held, the rest and the pinned
// kept; both ascending.
IndexSplit takeFirst(const std::vector<uint32_t>& order, size_t held, const std::vector<bool>& isPinned) {
  held = std::min(held, order.size());
  IndexSplit s;
  s.held.assign(order.begin(), order.begin() + long(held));
  s.kept.assign(order.begin() + long(held), order.end());
  for (size_t i = 0; i < isPinned.size(); ++i)
    if (isPinned[i]) s.kept.push_back(uint32_t(i));
  std::sort(s.held.begin(), s.held.end());
  std::sort(s.kept.begin(), s.kept.end());
  return s;
}

}  // namespace

IndexSplit seededSplit(size_t n, size_t held, Rng& rng, std::span<const uint32_t> pinned) {
  const std::vector<bool> isPinned = pinnedMask(n, pinned);
  std::vector<uint32_t> order;
  order.reserve(n);
  for (size_t i = 0; i < n; ++i)
    if (!isPinned[i]) order.push_back(uint32_t(i));
  for (size_t i = order.size(); i > 1; --i) std::swap(order[i - 1], order[rng.below(i)]);
  return takeFirst(order, held, isPinned);
}

IndexSplit keyedSplit(std::span<const uint64_t> keys, size_t held, Rng& rng, std::span<const uint32_t> pinned) {
  const std::vector<bool> isPinned = pinnedMask(keys.size(), pinned);
  const Rng hashes(rng.next());  // the seed's share of every key's hash
  struct Keyed {
    uint64_t hash, key;
    uint32_t index;
  };
  std::vector<Keyed> keyed;
  keyed.reserve(keys.size());
  for (size_t i = 0; i < keys.size(); ++i)
    if (!isPinned[i]) keyed.push_back({hashes.split(keys[i]).next(), keys[i], uint32_t(i)});
  std::sort(keyed.begin(), keyed.end(), [](const Keyed& a, const Keyed& b) {
    return a.hash != b.hash ? a.hash < b.hash : a.key != b.key ? a.key < b.key : a.index < b.index;
  });
  std::vector<uint32_t> order;
  order.reserve(keyed.size());
  for (const Keyed& k : keyed) order.push_back(k.index);
  return takeFirst(order, held, isPinned);
}

MlpTrainResult trainMlp(const MatXf& inputs, const MatXf& outputs, const MlpTrainOptions& o) {
  const Eigen::Index n = inputs.cols();
  if (n < 2) throw Error("MLP training: needs at least 2 samples, got " + std::to_string(n));
  if (outputs.cols() != n) throw Error("MLP training: inputs and outputs differ in sample count");
  if (inputs.rows() < 1 || outputs.rows() < 1) throw Error("MLP training: empty input or output vectors");
  checkFinite(inputs, "inputs");
  checkFinite(outputs, "outputs");
  if (o.hiddenLayers < 0 || o.hiddenWidth < 1) throw Error("MLP training: hidden layers/width out of range");
  if (!(o.learningRate > 0.0) || o.batchSize < 1 || o.maxEpochs < 1 || o.patience < 1)
    throw Error("MLP training: learning rate, batch size, epochs and patience must be positive");
  if (!(o.weightDecay >= 0.0) || !(o.weightDecay * o.learningRate < 1.0))
    throw Error("MLP training: weight decay must be at least 0 and below 1 / learning rate");
  if (!(o.inputNoise >= 0.0) || !std::isfinite(o.inputNoise))
    throw Error("MLP training: input noise must be at least 0");
  if (!(o.validationFraction > 0.0 && o.validationFraction < 1.0))
    throw Error("MLP training: validation fraction must be in (0, 1)");
  if (!o.outputWeights.empty() && Eigen::Index(o.outputWeights.size()) != outputs.rows())
    throw Error("MLP training: " + std::to_string(o.outputWeights.size()) + " output weights for " +
                std::to_string(outputs.rows()) + " outputs");

  const auto t0 = std::chrono::steady_clock::now();
  Rng rng(o.seed);
  MlpTrainResult r;
  r.activation = o.activation;

  // Split: a seeded shuffle (or keyed by sampleKeys); validation takes the first share, never an alwaysTrain
  // sample.
  for (uint32_t i : o.alwaysTrain)
    if (Eigen::Index(i) >= n)
      throw Error("MLP training: always-train sample " + std::to_string(i) + " of " + std::to_string(n));
  if (o.validationPool > size_t(n))
    throw Error("MLP training: a validation pool of " + std::to_string(o.validationPool) + " of " + std::to_string(n) +
                " samples");
  const size_t pool = o.validationPool ? o.validationPool : size_t(n);
  const size_t nVal = std::clamp<size_t>(size_t(std::lround(o.validationFraction * double(pool))), 1, size_t(n) - 1);
  if (!o.sampleKeys.empty() && Eigen::Index(o.sampleKeys.size()) != n)
    throw Error("MLP training: " + std::to_string(o.sampleKeys.size()) + " sample keys for " + std::to_string(n) +
                " samples");
  IndexSplit split = o.sampleKeys.empty() ? seededSplit(size_t(n), nVal, rng, o.alwaysTrain)
                                          : keyedSplit(o.sampleKeys, nVal, rng, o.alwaysTrain);
  if (split.held.empty()) throw Error("MLP training: every sample is always-train; none left for validation");
  r.validationSamples = std::move(split.held);
  r.trainingSamples = std::move(split.kept);

  auto gather = [](const MatXf& m, const std::vector<uint32_t>& idx) {
    MatXf out(m.rows(), Eigen::Index(idx.size()));
    for (size_t i = 0; i < idx.size(); ++i) out.col(Eigen::Index(i)) = m.col(idx[i]);
    return out;
  };
  const MatXf xTrainRaw = gather(inputs, r.trainingSamples), yTrainRaw = gather(outputs, r.trainingSamples);
  r.inputNorm = standardisation(xTrainRaw);
  r.outputNorm = standardisation(yTrainRaw);
  auto normalise = [](const MatXf& m, const Normalisation& nrm) -> MatXf {
    return ((m.colwise() - nrm.mean).array().colwise() / nrm.scale.array()).matrix();
  };
  const MatXf xTrain = normalise(xTrainRaw, r.inputNorm), yTrain = normalise(yTrainRaw, r.outputNorm);
  const MatXf xVal = normalise(gather(inputs, r.validationSamples), r.inputNorm);
  const MatXf yVal = normalise(gather(outputs, r.validationSamples), r.outputNorm);
  VecXf weights = VecXf::Ones(outputs.rows());
  for (size_t i = 0; i < o.outputWeights.size(); ++i) {
    if (!(o.outputWeights[i] >= 0.0) || !std::isfinite(o.outputWeights[i]))
      throw Error("MLP training: output weight " + std::to_string(i) + " must be finite and >= 0");
    weights[Eigen::Index(i)] = float(o.outputWeights[i]);
  }
  if (!(weights.sum() > 0.f)) throw Error("MLP training: output weights are all zero");

  std::vector<int> sizes{int(inputs.rows())};
  for (int l = 0; l < o.hiddenLayers; ++l) sizes.push_back(o.hiddenWidth);
  sizes.push_back(int(outputs.rows()));
  MlpNetwork<float> net(sizes, o.activation, rng);
  MlpNetwork<float> best = net;

  std::vector<AdamSlot> adamW(size_t(net.layers())), adamB(size_t(net.layers()));
  for (int l = 0; l < net.layers(); ++l) {
    adamW[size_t(l)] = {MatXf::Zero(net.weights[size_t(l)].rows(), net.weights[size_t(l)].cols()),
                        MatXf::Zero(net.weights[size_t(l)].rows(), net.weights[size_t(l)].cols())};
    adamB[size_t(l)] = {MatXf::Zero(net.biases[size_t(l)].size(), 1), MatXf::Zero(net.biases[size_t(l)].size(), 1)};
  }
  constexpr float beta1 = 0.9f, beta2 = 0.999f, eps = 1e-8f;
  float lr = float(o.learningRate);
  int step = 0, sinceBest = 0, sinceLrChange = 0;
  r.bestValidationLoss = std::numeric_limits<double>::infinity();

  const Eigen::Index nTrain = xTrain.cols();
  std::vector<Eigen::Index> perm(static_cast<size_t>(nTrain));
  for (Eigen::Index i = 0; i < nTrain; ++i) perm[size_t(i)] = i;
  std::vector<MatXf> gW;
  std::vector<VecXf> gB;
  MatXf xb, yb;
  for (int epoch = 1; epoch <= o.maxEpochs; ++epoch) {
    for (size_t i = perm.size() - 1; i > 0; --i) std::swap(perm[i], perm[rng.below(i + 1)]);
    double trainSum = 0.0;
    for (Eigen::Index start = 0; start < nTrain; start += o.batchSize) {
      const Eigen::Index b = std::min<Eigen::Index>(o.batchSize, nTrain - start);
      xb.resize(xTrain.rows(), b);
      yb.resize(yTrain.rows(), b);
      for (Eigen::Index j = 0; j < b; ++j) {
        xb.col(j) = xTrain.col(perm[size_t(start + j)]);
        yb.col(j) = yTrain.col(perm[size_t(start + j)]);
      }
      if (o.inputNoise > 0.0)
        for (Eigen::Index j = 0; j < b; ++j)
          for (Eigen::Index i = 0; i < xb.rows(); ++i) xb(i, j) += float(o.inputNoise * rng.normal());
      trainSum += double(net.lossAndGradient(xb, yb, weights, gW, gB)) * double(b);
      ++step;
      const float c1 = 1.f - std::pow(beta1, float(step)), c2 = 1.f - std::pow(beta2, float(step));
      auto adam = [&](auto& param, const auto& grad, AdamSlot& s) {
        s.m = beta1 * s.m + (1.f - beta1) * grad;
        s.v = beta2 * s.v + (1.f - beta2) * grad.cwiseAbs2();
        param.array() -= lr * (s.m.array() / c1) / ((s.v.array() / c2).sqrt() + eps);
      };
      const float decay = 1.f - lr * float(o.weightDecay);
      for (int l = 0; l < net.layers(); ++l) {
        if (o.weightDecay > 0.0) net.weights[size_t(l)] *= decay;
        adam(net.weights[size_t(l)], gW[size_t(l)], adamW[size_t(l)]);
        adam(net.biases[size_t(l)], gB[size_t(l)], adamB[size_t(l)]);
      }
    }
    const double valLoss = double(net.loss(xVal, yVal, weights));
    r.curve.push_back({epoch, trainSum / double(nTrain), valLoss, double(lr)});
    r.epochsRun = epoch;
    if (!std::isfinite(valLoss))
      throw Error("MLP training diverged (non-finite loss) at epoch " + std::to_string(epoch));
    if (valLoss < r.bestValidationLoss) {
      r.bestValidationLoss = valLoss;
      r.bestEpoch = epoch;
      best = net;
      sinceBest = 0;
      sinceLrChange = 0;
    } else {
      ++sinceBest;
      if (++sinceLrChange >= o.plateauEpochs && lr > float(o.minLearningRate)) {
        lr = std::max(lr * 0.5f, float(o.minLearningRate));
        sinceLrChange = 0;
      }
    }
    if (sinceBest >= o.patience) break;
    if (o.maxSeconds > 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() > o.maxSeconds)
      break;
  }
  r.mlp = toModelMlp(best);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

VecXf evaluateMlp(const Mlp& mlp, const Normalisation& inN, const Normalisation& outN, const VecXf& theta,
                  Activation activation) {
  if (theta.size() != mlp.inputSize() || inN.mean.size() != theta.size())
    throw Error("MLP evaluation: Theta of " + std::to_string(theta.size()) + " values, the MLP takes " +
                std::to_string(mlp.inputSize()));
  MlpNetwork<float> net;
  net.activation = activation;
  for (const auto& L : mlp.layers) {
    net.weights.push_back(L.weight);
    net.biases.push_back(L.bias);
  }
  const MatXf x = ((theta - inN.mean).array() / inN.scale.array()).matrix();
  const VecXf y = net.forward(x).col(0);
  return (y.array() * outN.scale.array()).matrix() + outN.mean;
}

}  // namespace swish::bake
