#pragma once
// The inner kernels of MlpEvaluator: one dense layer (with its fused epilogue) over a batch of instances,
// and the input normalisation. Two implementations with the same contract:
//   - portable: plain C++ loops, any x86-64 (or other) CPU; the compiler vectorises what it can.
//   - AVX2+FMA: 8-lane intrinsics compiled with __attribute__((target("avx2,fma"))) so the build stays
//     portable (no -march=native); MlpEvaluator calls it only after cpuHasAvx2Fma() said yes.
//
// Layout (prepared once by MlpEvaluator): activations are instance-major rows, one row per instance,
// each row padded to a multiple of 8 floats. Weights are stored transposed, row k holding input k's
// weight for every output, padded with zeros to outputsPadded columns. Each instance's result depends only
// on its own row and is computed by the same sequence of operations whatever its position in the batch,
// so a batch gives bitwise the results of evaluating its instances one by one (within one kernel).
#include <cstddef>

namespace swish::runtime {

struct PackedDenseLayer {
  int inputs = 0;                   // k runs over [0, inputs)
  int outputsPadded = 0;            // multiple of 8
  const float* weightsT = nullptr;  // inputs x outputsPadded
  const float* bias = nullptr;      // outputsPadded (zeros in the padding)
  // Hidden layer: SELU, then min(activationLimit, .) so the next layer's sums cannot overflow (see
  // MlpEvaluator). Output layer (selu == false): y = acc * outScale + outMean, clamped to +-FLT_MAX.
  bool selu = true;
  float activationLimit = 0.f;
  const float* outScale = nullptr;  // outputsPadded (ones in the padding); output layer only
  const float* outMean = nullptr;   // outputsPadded (zeros in the padding); output layer only
};

struct PackedInputNormalisation {
  int size = 0;                     // floats per input row (unpadded)
  const float* mean = nullptr;      // size rounded up to 8 (zeros in the padding)
  const float* invScale = nullptr;  // same; 1 / scale, clamped to FLT_MAX
  float limit = 0.f;                // normalised values are clamped to +-limit
};

// out[i] = clamp((x[i] - mean) * invScale) for `count` rows; x rows are `size` floats apart, out rows
// `outStride` floats apart (outStride >= size rounded up to 8; the padding is written as 0).
void normaliseInputPortable(const PackedInputNormalisation& n, const float* x, size_t count, float* out,
                            size_t outStride);
void denseLayerPortable(const PackedDenseLayer& layer, const float* in, size_t inStride, size_t count, float* out,
                        size_t outStride);

// Only callable when cpuHasAvx2Fma() is true.
void normaliseInputAvx2(const PackedInputNormalisation& n, const float* x, size_t count, float* out, size_t outStride);
void denseLayerAvx2(const PackedDenseLayer& layer, const float* in, size_t inStride, size_t count, float* out,
                    size_t outStride);
// The AVX2 exp on an array (n any size), for tests of the vector exp against std::exp.
void expArrayAvx2(const float* x, float* out, size_t n);

bool cpuHasAvx2Fma();

}  // namespace swish::runtime
