#include "swish/runtime/mlp_evaluator.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <string>

#include "swish/core/error.hpp"
#include "swish/runtime/mlp_kernel.hpp"

namespace swish::runtime {

namespace {

size_t padded8(size_t n) { return (n + 7) & ~size_t(7); }
std::string n2s(long long v) { return std::to_string(v); }

// Rows of this many floats fit the on-stack workspace (two buffers): 16 KiB each keeps a chunk of the
// paper's network (32 floats a row: 128 instances) in L1 while its layers run.
constexpr size_t kStackFloats = 4096;

// The largest |input| a layer may receive so that none of its sums can overflow: every partial sum is
// bounded by sum_k |w_ok| * limit + |b_o| <= FLT_MAX / 4. Capped at 1e30, far beyond any trained network.
float inputLimitFor(const MlpLayer& L) {
  double rowSum = 0.0, maxBias = 0.0;
  for (Eigen::Index o = 0; o < L.weight.rows(); ++o) {
    double s = 0.0;
    for (Eigen::Index k = 0; k < L.weight.cols(); ++k) s += std::abs(double(L.weight(o, k)));
    rowSum = std::max(rowSum, s);
    maxBias = std::max(maxBias, std::abs(double(L.bias[o])));
  }
  const double room = double(FLT_MAX) / 4.0 - maxBias;
  double limit = rowSum > 0.0 ? room / rowSum : 1e30;
  limit = std::clamp(limit, 0.0, 1e30);
  return float(limit);
}

}  // namespace

const char* toString(CpuKernel k) {
  switch (k) {
    case CpuKernel::Auto:
      return "auto";
    case CpuKernel::Portable:
      return "portable";
    case CpuKernel::Avx2Fma:
      return "avx2+fma";
  }
  return "?";
}

CpuKernel resolveCpuKernel(CpuKernel requested, const char* user) {
  if (requested == CpuKernel::Auto) return cpuHasAvx2Fma() ? CpuKernel::Avx2Fma : CpuKernel::Portable;
  if (requested == CpuKernel::Avx2Fma && !cpuHasAvx2Fma())
    throw Error(std::string(user) + ": the AVX2+FMA kernel was asked for but this CPU lacks it");
  return requested;
}

std::vector<CpuKernel> availableCpuKernels() {
  std::vector<CpuKernel> k{CpuKernel::Portable};
  if (cpuHasAvx2Fma()) k.push_back(CpuKernel::Avx2Fma);
  return k;
}

MlpEvaluator::MlpEvaluator(const Model& model, CpuKernel kernel)
    : MlpEvaluator(model.mlp, model.inputNorm, model.outputNorm, model.meshComponents(), kernel) {}

MlpEvaluator::MlpEvaluator(const Mlp& mlp, const Normalisation& inputNorm, const Normalisation& outputNorm,
                           int meshComponents, CpuKernel kernel) {
  auto fail = [](const std::string& problem) { throw Error("mlp evaluator: " + problem); };
  if (mlp.layers.empty()) fail("the network has no layers");
  for (size_t l = 0; l < mlp.layers.size(); ++l) {
    const MlpLayer& L = mlp.layers[l];
    if (L.weight.rows() == 0 || L.weight.cols() == 0) fail("layer " + n2s(l) + " is empty");
    if (L.bias.size() != L.weight.rows()) fail("layer " + n2s(l) + " has a bias of the wrong size");
    if (l > 0 && L.weight.cols() != mlp.layers[l - 1].weight.rows())
      fail("layer " + n2s(l) + " takes " + n2s(L.weight.cols()) + " inputs but layer " + n2s(l - 1) + " gives " +
           n2s(mlp.layers[l - 1].weight.rows()));
    if (!L.weight.allFinite() || !L.bias.allFinite()) fail("layer " + n2s(l) + " has non-finite values");
  }
  inputSize_ = mlp.inputSize();
  outputSize_ = mlp.outputSize();
  auto checkNorm = [&](const Normalisation& n, int size, const char* name) {
    if (n.mean.size() != size || n.scale.size() != size)
      fail(std::string(name) + " normalisation has " + n2s(n.mean.size()) + "/" + n2s(n.scale.size()) +
           " values, expected " + n2s(size));
    if (!n.mean.allFinite() || !n.scale.allFinite()) fail(std::string(name) + " normalisation has non-finite values");
    for (Eigen::Index i = 0; i < size; ++i)
      if (!(n.scale[i] > 0.f)) fail(std::string(name) + " normalisation scale " + n2s(i) + " is not positive");
  };
  checkNorm(inputNorm, inputSize_, "input");
  checkNorm(outputNorm, outputSize_, "output");
  if (meshComponents < 0 || meshComponents > outputSize_)
    fail("mesh components " + n2s(meshComponents) + " outside 0.." + n2s(outputSize_));
  meshComponents_ = meshComponents;

  kernel_ = resolveCpuKernel(kernel, "mlp evaluator");

  // Pack everything into one array: transposed, zero-padded weights, so that a kernel reads each
  // layer's weights as contiguous rows of outputsPadded floats.
  stride_ = padded8(size_t(inputSize_));
  auto append = [&](size_t n, float fill) {
    const size_t at = params_.size();
    params_.resize(at + n, fill);
    return at;
  };
  for (size_t l = 0; l < mlp.layers.size(); ++l) {
    const MlpLayer& src = mlp.layers[l];
    Layer L;
    L.inputs = int(src.weight.cols());
    L.outputs = int(src.weight.rows());
    L.outputsPadded = int(padded8(size_t(L.outputs)));
    L.selu = l + 1 < mlp.layers.size();
    L.activationLimit = L.selu ? inputLimitFor(mlp.layers[l + 1]) : 0.f;
    stride_ = std::max(stride_, size_t(L.outputsPadded));
    L.weightsOffset = append(size_t(L.inputs) * size_t(L.outputsPadded), 0.f);
    for (int k = 0; k < L.inputs; ++k)
      for (int o = 0; o < L.outputs; ++o) params_[L.weightsOffset + size_t(k) * L.outputsPadded + o] = src.weight(o, k);
    L.biasOffset = append(size_t(L.outputsPadded), 0.f);
    for (int o = 0; o < L.outputs; ++o) params_[L.biasOffset + o] = src.bias[o];
    layers_.push_back(L);
  }
  inputLimit_ = inputLimitFor(mlp.layers.front());
  inMeanOffset_ = append(padded8(size_t(inputSize_)), 0.f);
  inInvScaleOffset_ = append(padded8(size_t(inputSize_)), 1.f);
  for (int k = 0; k < inputSize_; ++k) {
    params_[inMeanOffset_ + k] = inputNorm.mean[k];
    params_[inInvScaleOffset_ + k] = float(std::min(1.0 / double(inputNorm.scale[k]), double(FLT_MAX)));
  }
  const size_t outPad = padded8(size_t(outputSize_));
  outScaleOffset_ = append(outPad, 1.f);
  outMeanOffset_ = append(outPad, 0.f);
  for (int o = 0; o < outputSize_; ++o) {
    params_[outScaleOffset_ + o] = outputNorm.scale[o];
    params_[outMeanOffset_ + o] = outputNorm.mean[o];
  }
}

const float* MlpEvaluator::runChunk(const float* theta, size_t count, float* bufA, float* bufB) const {
  const bool avx2 = kernel_ == CpuKernel::Avx2Fma;
  PackedInputNormalisation norm;
  norm.size = inputSize_;
  norm.mean = params_.data() + inMeanOffset_;
  norm.invScale = params_.data() + inInvScaleOffset_;
  norm.limit = inputLimit_;
  if (avx2)
    normaliseInputAvx2(norm, theta, count, bufA, stride_);
  else
    normaliseInputPortable(norm, theta, count, bufA, stride_);
  float* in = bufA;
  float* out = bufB;
  for (const Layer& L : layers_) {
    PackedDenseLayer p;
    p.inputs = L.inputs;
    p.outputsPadded = L.outputsPadded;
    p.weightsT = params_.data() + L.weightsOffset;
    p.bias = params_.data() + L.biasOffset;
    p.selu = L.selu;
    p.activationLimit = L.activationLimit;
    p.outScale = params_.data() + outScaleOffset_;
    p.outMean = params_.data() + outMeanOffset_;
    if (avx2)
      denseLayerAvx2(p, in, stride_, count, out, stride_);
    else
      denseLayerPortable(p, in, stride_, count, out, stride_);
    std::swap(in, out);
  }
  return in;
}

template <class Sink>
void MlpEvaluator::runBatch(std::span<const float> theta, size_t count, Sink&& sink) const {
  if (theta.size() != count * size_t(inputSize_))
    throw Error("mlp evaluator: theta holds " + n2s(theta.size()) + " floats, expected " + n2s(count) + " x " +
                n2s(inputSize_));
  alignas(64) float stackA[kStackFloats];
  alignas(64) float stackB[kStackFloats];
  std::vector<float> heap;
  float* bufA = stackA;
  float* bufB = stackB;
  size_t chunk = kStackFloats / stride_;
  if (chunk == 0) {  // a layer wider than the stack workspace: one instance at a time on the heap
    chunk = 1;
    heap.resize(2 * stride_);
    bufA = heap.data();
    bufB = heap.data() + stride_;
  }
  for (size_t first = 0; first < count; first += chunk) {
    const size_t n = std::min(chunk, count - first);
    const float* rows = runChunk(theta.data() + first * size_t(inputSize_), n, bufA, bufB);
    for (size_t i = 0; i < n; ++i) sink(first + i, rows + i * stride_);
  }
}

void MlpEvaluator::evaluate(std::span<const float> theta, std::span<float> lambda) const {
  evaluateBatch(theta, lambda, 1);
}

void MlpEvaluator::evaluateBatch(std::span<const float> theta, std::span<float> lambda, size_t count) const {
  const size_t out = size_t(outputSize_);
  if (lambda.size() != count * out)
    throw Error("mlp evaluator: lambda holds " + n2s(lambda.size()) + " floats, expected " + n2s(count) + " x " +
                n2s(outputSize_));
  runBatch(theta, count,
           [&](size_t i, const float* row) { std::memcpy(lambda.data() + i * out, row, out * sizeof(float)); });
}

void MlpEvaluator::evaluateBatchSplit(std::span<const float> theta, std::span<float> meshWeights,
                                      std::span<float> normalCodes, size_t count) const {
  const size_t k = size_t(meshComponents_), c = size_t(normalCodeDims());
  if (meshWeights.size() != count * k || normalCodes.size() != count * c)
    throw Error("mlp evaluator: split outputs hold " + n2s(meshWeights.size()) + " and " + n2s(normalCodes.size()) +
                " floats, expected " + n2s(count) + " x " + n2s(k) + " and " + n2s(count) + " x " + n2s(c));
  runBatch(theta, count, [&](size_t i, const float* row) {
    if (k) std::memcpy(meshWeights.data() + i * k, row, k * sizeof(float));
    if (c) std::memcpy(normalCodes.data() + i * c, row + k, c * sizeof(float));
  });
}

}  // namespace swish::runtime
