#pragma once
// The trainable MLP of the bake: dense layers, an activation after every layer but the last (linear
// output), forward and backward passes written by hand over Eigen matrices (one column per sample).
// Scalar is double for gradient checks and float for training speed; both are instantiated.
#include <string>
#include <vector>

#include <Eigen/Core>

#include "swish/core/rng.hpp"

namespace swish::bake {

enum class Activation { Selu, Relu, Tanh };
Activation activationFromName(const std::string& name);  // "selu" | "relu" | "tanh"; throws Error
std::string activationName(Activation a);

template <class Scalar>
class MlpNetwork {
 public:
  using Mat = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vec = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;

  MlpNetwork() = default;
  // sizes = {input, hidden..., output}. LeCun-normal weights (variance 1 / fan-in, what SELU's
  // self-normalisation assumes), zero biases.
  MlpNetwork(const std::vector<int>& sizes, Activation activation, Rng& rng);

  std::vector<Mat> weights;  // layer l: sizes[l+1] x sizes[l]
  std::vector<Vec> biases;
  Activation activation = Activation::Selu;

  int layers() const { return int(weights.size()); }
  Mat forward(const Mat& x) const;
  // Weighted mean squared error over the batch: sum_i w_i (f(x) - y)_i^2 / (sum_i w_i * batch), and
  // its gradient with respect to every weight and bias (same shapes as weights/biases).
  Scalar lossAndGradient(const Mat& x, const Mat& y, const Vec& outputWeights, std::vector<Mat>& gradW,
                         std::vector<Vec>& gradB) const;
  Scalar loss(const Mat& x, const Mat& y, const Vec& outputWeights) const;
};

extern template class MlpNetwork<float>;
extern template class MlpNetwork<double>;

}  // namespace swish::bake
