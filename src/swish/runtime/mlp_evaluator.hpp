#pragma once
// MLP inference on the CPU (paper section 2.3, step 2): Lambda = denormalise(MLP(normalise(Theta))).
// Every layer but the last is followed by SELU (lambda = 1.0507009873554805, alpha = 1.6732632423543772);
// the last is linear. Lambda splits into the mesh weights (first K values) and the normal code (last C).
//
// Built once from a Model (or from an MLP and its normalisations): the weights are re-laid out for the
// kernel at construction (transposed, padded to 8 lanes) and the kernel is chosen once: AVX2+FMA when the
// CPU has it, else a portable one. Evaluation allocates nothing for batches that fit in its on-stack
// workspace and is const: one evaluator may serve several threads.
//
// Results: within a kernel, a batch gives bitwise the results of evaluating its instances one at a time.
// The two kernels differ in rounding (FMA or not); both match a double-precision evaluation within the
// forward error bound that tests/unit/test_runtime_mlp.cpp derives.
//
// Inputs that are not NaN never produce NaN or Inf: the normalised input and every hidden activation are
// clamped to bounds computed at construction from the next layer's weights, small enough that no sum in
// the next layer can overflow (they are far beyond any value a trained network sees: at most 1e30), and
// the final Lambda is clamped to +-FLT_MAX. This holds for any finite weights whose biases stay below
// FLT_MAX / 4. A NaN input is not hidden: it propagates to the outputs it reaches.
// A scale below 1 / FLT_MAX (which Model::validate allows, as it is positive) is treated as 1 / FLT_MAX.
#include <cstddef>
#include <span>
#include <vector>

#include "swish/model/model.hpp"

namespace swish::runtime {

enum class CpuKernel {
  Auto,      // AVX2+FMA when the CPU has it, else Portable
  Portable,  // plain C++, any CPU
  Avx2Fma,   // throws Error at construction when the CPU lacks AVX2 or FMA
};
const char* toString(CpuKernel k);
// Auto -> the best kernel this CPU runs; Avx2Fma on a CPU without AVX2/FMA -> Error
// "<user>: the AVX2+FMA kernel was asked for but this CPU lacks it". Shared by every CPU kernel user.
CpuKernel resolveCpuKernel(CpuKernel requested, const char* user);
// Every kernel this CPU can run: Portable always, Avx2Fma when the CPU has it (tests try each).
std::vector<CpuKernel> availableCpuKernels();

class MlpEvaluator {
 public:
  // Checks that the shapes chain (Theta -> ... -> Lambda), that values are finite and scales positive,
  // and that 0 <= meshComponents <= output size; throws Error naming the problem.
  MlpEvaluator(const Mlp& mlp, const Normalisation& inputNorm, const Normalisation& outputNorm, int meshComponents,
               CpuKernel kernel = CpuKernel::Auto);
  explicit MlpEvaluator(const Model& model, CpuKernel kernel = CpuKernel::Auto);

  int inputSize() const { return inputSize_; }
  int outputSize() const { return outputSize_; }
  int meshComponents() const { return meshComponents_; }
  int normalCodeDims() const { return outputSize_ - meshComponents_; }
  CpuKernel kernel() const { return kernel_; }  // the one in use (never Auto)

  // One instance: theta holds inputSize() floats, lambda outputSize().
  void evaluate(std::span<const float> theta, std::span<float> lambda) const;
  // `count` instances, row-major: theta is count x inputSize(), lambda count x outputSize().
  void evaluateBatch(std::span<const float> theta, std::span<float> lambda, size_t count) const;
  // The same, writing Lambda already split: meshWeights count x K (instance i at i*K), normalCodes
  // count x C. Either may be empty when its part has size 0.
  void evaluateBatchSplit(std::span<const float> theta, std::span<float> meshWeights, std::span<float> normalCodes,
                          size_t count) const;

  // Views of one instance's Lambda.
  std::span<const float> meshWeightsOf(std::span<const float> lambda) const {
    return lambda.first(size_t(meshComponents_));
  }
  std::span<const float> normalCodeOf(std::span<const float> lambda) const {
    return lambda.subspan(size_t(meshComponents_), size_t(normalCodeDims()));
  }

 private:
  struct Layer {
    int inputs = 0, outputs = 0, outputsPadded = 0;
    bool selu = true;
    float activationLimit = 0.f;
    size_t weightsOffset = 0, biasOffset = 0;
  };
  // Runs the network on up to chunk rows, through two ping-pong buffers of `stride`-float rows, and
  // leaves the padded output rows in the returned buffer.
  const float* runChunk(const float* theta, size_t count, float* bufA, float* bufB) const;
  template <class Sink>
  void runBatch(std::span<const float> theta, size_t count, Sink&& sink) const;

  int inputSize_ = 0, outputSize_ = 0, meshComponents_ = 0;
  CpuKernel kernel_ = CpuKernel::Portable;
  size_t stride_ = 0;  // widest padded row, in floats
  std::vector<Layer> layers_;
  std::vector<float> params_;  // all packed weights, biases, and the normalisation vectors
  size_t inMeanOffset_ = 0, inInvScaleOffset_ = 0, outScaleOffset_ = 0, outMeanOffset_ = 0;
  float inputLimit_ = 0.f;
};

}  // namespace swish::runtime
