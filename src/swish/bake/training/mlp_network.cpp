#include "swish/bake/training/mlp_network.hpp"

#include <cmath>

#include "swish/core/error.hpp"

namespace swish::bake {

namespace {
constexpr double kSeluLambda = 1.0507009873554804934193349852946;
constexpr double kSeluAlpha = 1.6732632423543772848170429916717;

template <class M>
void activate(Activation a, M& z) {
  using S = typename M::Scalar;
  switch (a) {
    case Activation::Selu:
      z = z.unaryExpr(
          [](S v) { return v > S(0) ? S(kSeluLambda) * v : S(kSeluLambda * kSeluAlpha) * (std::exp(v) - S(1)); });
      break;
    case Activation::Relu:
      z = z.cwiseMax(S(0));
      break;
    case Activation::Tanh:
      z = z.array().tanh().matrix();
      break;
  }
}

// Derivative from the pre-activation z.
template <class M>
M activationDerivative(Activation a, const M& z) {
  using S = typename M::Scalar;
  switch (a) {
    case Activation::Selu:
      return z.unaryExpr([](S v) { return v > S(0) ? S(kSeluLambda) : S(kSeluLambda * kSeluAlpha) * std::exp(v); });
    case Activation::Relu:
      return z.unaryExpr([](S v) { return v > S(0) ? S(1) : S(0); });
    case Activation::Tanh:
      return (S(1) - z.array().tanh().square()).matrix();
  }
  return z;
}
}  // namespace

Activation activationFromName(const std::string& name) {
  if (name == "selu") return Activation::Selu;
  if (name == "relu") return Activation::Relu;
  if (name == "tanh") return Activation::Tanh;
  throw Error("activation '" + name + "' unknown (selu, relu or tanh)");
}

std::string activationName(Activation a) {
  switch (a) {
    case Activation::Selu:
      return "selu";
    case Activation::Relu:
      return "relu";
    case Activation::Tanh:
      return "tanh";
  }
  return "?";
}

template <class Scalar>
MlpNetwork<Scalar>::MlpNetwork(const std::vector<int>& sizes, Activation act, Rng& rng) : activation(act) {
  if (sizes.size() < 2) throw Error("MLP: needs at least an input and an output size");
  for (int s : sizes)
    if (s < 1) throw Error("MLP: layer sizes must be >= 1");
  for (size_t l = 0; l + 1 < sizes.size(); ++l) {
    Mat w(sizes[l + 1], sizes[l]);
    const double sd = 1.0 / std::sqrt(double(sizes[l]));
    for (Eigen::Index j = 0; j < w.cols(); ++j)
      for (Eigen::Index i = 0; i < w.rows(); ++i) w(i, j) = Scalar(rng.normal() * sd);
    weights.push_back(std::move(w));
    biases.push_back(Vec::Zero(sizes[l + 1]));
  }
}

template <class Scalar>
typename MlpNetwork<Scalar>::Mat MlpNetwork<Scalar>::forward(const Mat& x) const {
  Mat a = x;
  for (int l = 0; l < layers(); ++l) {
    Mat z = (weights[size_t(l)] * a).colwise() + biases[size_t(l)];
    if (l + 1 < layers()) activate(activation, z);
    a = std::move(z);
  }
  return a;
}

template <class Scalar>
Scalar MlpNetwork<Scalar>::loss(const Mat& x, const Mat& y, const Vec& w) const {
  const Mat d = forward(x) - y;
  return (w.asDiagonal() * d.cwiseAbs2()).sum() / (w.sum() * Scalar(x.cols()));
}

template <class Scalar>
Scalar MlpNetwork<Scalar>::lossAndGradient(const Mat& x, const Mat& y, const Vec& w, std::vector<Mat>& gradW,
                                           std::vector<Vec>& gradB) const {
  const int L = layers();
  std::vector<Mat> pre(static_cast<size_t>(L)), act(static_cast<size_t>(L + 1));
  act[0] = x;
  for (int l = 0; l < L; ++l) {
    pre[size_t(l)] = (weights[size_t(l)] * act[size_t(l)]).colwise() + biases[size_t(l)];
    act[size_t(l + 1)] = pre[size_t(l)];
    if (l + 1 < L) activate(activation, act[size_t(l + 1)]);
  }
  const Scalar norm = w.sum() * Scalar(x.cols());
  const Mat diff = act[size_t(L)] - y;
  const Scalar value = (w.asDiagonal() * diff.cwiseAbs2()).sum() / norm;
  Mat delta = (Scalar(2) / norm) * (w.asDiagonal() * diff);  // dLoss / dpre of the last layer
  gradW.resize(size_t(L));
  gradB.resize(size_t(L));
  for (int l = L - 1; l >= 0; --l) {
    gradW[size_t(l)].noalias() = delta * act[size_t(l)].transpose();
    gradB[size_t(l)] = delta.rowwise().sum();
    if (l > 0) {
      Mat back = weights[size_t(l)].transpose() * delta;
      delta = back.cwiseProduct(activationDerivative(activation, pre[size_t(l - 1)]));
    }
  }
  return value;
}

template class MlpNetwork<float>;
template class MlpNetwork<double>;

}  // namespace swish::bake
