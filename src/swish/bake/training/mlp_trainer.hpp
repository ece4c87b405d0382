#pragma once
// Trains the regressor Lambda = R(Theta) of the paper (5 hidden layers of 32, SELU by default) with
// Adam (optionally with decoupled weight decay) on standardised inputs and outputs, a held-out validation split and
// early stopping (the best validation epoch is kept). Deterministic for a seed: one thread, fixed shuffles from
// swish::Rng.
#include <cstdint>
#include <span>
#include <vector>

#include "swish/bake/training/mlp_network.hpp"
#include "swish/core/rng.hpp"
#include "swish/model/model.hpp"

namespace swish::bake {

struct MlpTrainOptions {
  int hiddenLayers = 5;
  int hiddenWidth = 32;
  Activation activation = Activation::Selu;
  double learningRate = 2e-3;
  double minLearningRate = 2e-5;
  // Decoupled weight decay (AdamW, Loshchilov & Hutter 2019): each step shrinks the weight matrices
  // (not the biases) by learningRate * weightDecay of themselves. 0: plain Adam.
  double weightDecay = 0.0;
  // Gaussian noise added to every training batch's standardised inputs (standard deviation, in units
  // of each input's own spread; 0: none): the network sees each pose as a small cloud of poses and
  // cannot memorise single samples. Validation inputs are never perturbed.
  double inputNoise = 0.0;
  int batchSize = 32;
  int maxEpochs = 3000;
  int patience = 300;      // epochs without a better validation loss before stopping
  int plateauEpochs = 60;  // epochs without improvement before the learning rate halves
  double validationFraction = 0.1;
  // The samples that share is of (0: all of them): the bake's distilled samples (train.distill), always
  // trained on, do not count, so the validation poses stay those of a bake without them.
  size_t validationPool = 0;
  double maxSeconds = 0.0;  // wall-clock cap (0: none); stopping early keeps the best epoch
  uint64_t seed = 1;
  // Per output weight in the loss (empty: all 1). The bake weights mesh components by their variance
  // so that the loss follows the vertex error the PCA basis turns them into.
  std::vector<double> outputWeights;
  // Samples (input columns) never drawn into the validation split: poses the network must fit, such
  // as the rest pose (part1_dataset.hpp, includeRestPose).
  std::vector<uint32_t> alwaysTrain;
  // One key per sample (the bake passes its pose ids), or empty. With keys the validation split is
  // keyed (keyedSplit below): a sample's side depends on its key and the seed, not on its column, so a
  // dataset that gains or loses a few poses keeps the validation poses of the others.
  std::vector<uint64_t> sampleKeys;
};

// A seeded split of the indices 0..n-1: `held` of them drawn by a Fisher-Yates shuffle, the rest
// kept; both lists ascending. `pinned` indices are always kept (never drawn); with none pinned the
// draw is that of shuffling all n. At most n - pinned are held.
struct IndexSplit {
  std::vector<uint32_t> held, kept;
};
IndexSplit seededSplit(size_t n, size_t held, Rng& rng, std::span<const uint32_t> pinned = {});

// A split by key: index i is ordered by a seeded hash of keys[i] (ties by key, then index) and the
// first `held` unpinned ones are held. Which side a key falls on depends only on the key, the
// generator's state and how many are held, not on which other keys are there: two datasets of the same
// recipe that differ by a few poses (a retry kept more) hold out the same poses of the rest, so their
// held-out figures compare pose for pose. Draws one number from rng.
IndexSplit keyedSplit(std::span<const uint64_t> keys, size_t held, Rng& rng, std::span<const uint32_t> pinned = {});

struct TrainingEpoch {
  int epoch = 0;
  double trainLoss = 0.0;  // on standardised outputs, weighted
  double validationLoss = 0.0;
  double learningRate = 0.0;
};

struct MlpTrainResult {
  Mlp mlp;  // model.hpp form (float), best validation epoch
  Normalisation inputNorm, outputNorm;
  Activation activation = Activation::Selu;
  std::vector<TrainingEpoch> curve;
  int bestEpoch = 0;
  double bestValidationLoss = 0.0;
  int epochsRun = 0;
  double seconds = 0.0;
  std::vector<uint32_t> trainingSamples, validationSamples;  // column indices of the inputs
};

// inputs: Din x N (Theta per column), outputs: Dout x N (Lambda per column). Throws Error on bad sizes,
// non-finite data or options out of range.
MlpTrainResult trainMlp(const MatXf& inputs, const MatXf& outputs, const MlpTrainOptions& options);

// Per-dimension mean and standard deviation of the columns; a dimension that does not vary gets scale 1
// (so constant inputs, e.g. a joint that never moves, stay finite).
Normalisation standardisation(const MatXf& samples);

// Lambda for one Theta through a trained model's MLP and norms (the same arithmetic as the runtime:
// normalise, layers with SELU between, denormalise). For evaluation in the bake.
VecXf evaluateMlp(const Mlp& mlp, const Normalisation& inputNorm, const Normalisation& outputNorm, const VecXf& theta,
                  Activation activation = Activation::Selu);

}  // namespace swish::bake
