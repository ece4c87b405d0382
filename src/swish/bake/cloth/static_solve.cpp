#include "swish/bake/cloth/static_solve.hpp"

#include <Eigen/SparseCholesky>
#include <algorithm>
#include <array>
#include <cmath>

#include "swish/core/error.hpp"

namespace swish::bake {
namespace {

using Vec3d = Eigen::Vector3d;
using Mat3d = Eigen::Matrix3d;

// The proximal term's step length h (seconds): the first, the largest, and how it grows after a full
// step. Small at first so that the first steps stay near the path's shape (a pure Newton step from a
// shape far from equilibrium can fold the cloth through itself); large later, where it no longer slows
// the convergence (M / h^2 is then far below the stretch stiffness).
constexpr double kFirstStep = 0.05, kLargestStep = 100.0, kStepGrowth = 4.0;
// Stiffness of the one-sided springs, relative to the median edge's stretch stiffness: tethers and
// contacts as stiff as an edge. Contacts ten times stiffer left the tube-on-capsule test's solve (at
// 2000 simulation vertices) at 14x gravity's load after 40 steps, against 1.4x: the line search cut
// most steps short. What the load leaves within the thickness, the final projection of cloth_solver.cpp
// moves out.
constexpr double kTetherScale = 1.0, kContactScale = 1.0;
// The solve stops early when kStallSteps steps in a row lower the energy by less than kStallDecrease of
// it: what is left of the residual then is the contact's kinks (the signed distance to a triangle mesh
// turns its gradient at edges and corners) and the float positions' rounding, not a shape still moving.
constexpr int kStallSteps = 3;
constexpr double kStallDecrease = 1e-7;

Vec3d at(const Points3f& x, size_t v) { return x.row(Eigen::Index(v)).transpose().cast<double>(); }

struct Planes {
  std::vector<std::array<BodyCollider::Hit, kContactPlanes>> hits;
  std::vector<uint8_t> count;
};

class Energy {
 public:
  Energy(const StaticProblem& p, size_t n) : p_(p), n_(n), mass_(n) {
    const ClothConstraints& cc = *p.constraints;
    for (size_t v = 0; v < n; ++v) mass_[v] = cc.inverseMass[v] > 0.f ? 1.0 / double(cc.inverseMass[v]) : 0.0;
    std::vector<double> k;
    for (const DistanceConstraint& c : cc.stretch)
      k.push_back(1.0 / (std::max(double(c.tensionCompliance), 1e-20) * double(c.rest) * double(c.rest)));
    double median = 1.0;
    if (!k.empty()) {
      std::nth_element(k.begin(), k.begin() + std::ptrdiff_t(k.size() / 2), k.end());
      median = k[k.size() / 2];
    }
    tetherK_ = kTetherScale * median;
    contactK_ = kContactScale * median;
  }

  const std::vector<double>& mass() const { return mass_; }

  void findPlanes(const Points3f& x, Planes& planes) const {
    planes.hits.resize(n_);
    planes.count.assign(n_, 0);
    for (size_t v = 0; v < n_; ++v)
      planes.count[v] = uint8_t(p_.body->closestRegions(x.row(Eigen::Index(v)), p_.reach, std::span(planes.hits[v])));
  }

  // The energy at x, its contacts found at x.
  double value(const Points3f& x) const {
    Planes planes;
    findPlanes(x, planes);
    return value(x, planes);
  }

  // The energy at x with the contacts found there (findPlanes at the same x).
  double value(const Points3f& x, const Planes& planes) const {
    const ClothConstraints& cc = *p_.constraints;
    double e = 0.0;
    auto distance = [&](const DistanceConstraint& c) {
      const double len = (at(x, c.i) - at(x, c.j)).norm(), rest = double(c.rest);
      const double C = (len - rest) / rest;
      e += C * C / (2.0 * compliance(c, C));
    };
    for (const DistanceConstraint& c : cc.stretch) distance(c);
    for (const DistanceConstraint& c : cc.bending) distance(c);
    for (const ShearConstraint& c : cc.shear) {
      const Vec3d e1 = at(x, c.v[1]) - at(x, c.v[0]), e2 = at(x, c.v[2]) - at(x, c.v[0]);
      const double C = (double(c.a) * e1 + double(c.c) * e2).dot(double(c.b) * e1 + double(c.d) * e2);
      e += C * C / (2.0 * std::max(double(c.compliance), 1e-20));
    }
    for (size_t a = 0; a < p_.attached->size(); ++a) {
      const Vec3d d = at(x, (*p_.attached)[a]) - (*p_.attachTarget)[a].cast<double>();
      e += d.squaredNorm() / (2.0 * std::max(double((*p_.attachCompliance)[a]), 1e-20));
    }
    for (const Tether& t : *p_.tethers) {
      const double over = (at(x, t.v) - at(x, t.anchor)).norm() - double(t.length) * (1.0 + double(p_.tetherSlack));
      if (over > 0.0) e += 0.5 * tetherK_ * over * over;
    }
    const Vec3d g = p_.gravity.cast<double>();
    for (size_t v = 0; v < n_; ++v) {
      const Vec3d xv = at(x, v);
      e -= mass_[v] * g.dot(xv);
      for (size_t k = 0; k < planes.count[v]; ++k) {
        const double depth = depthOf(planes.hits[v][k]);
        if (depth > 0.0) e += 0.5 * contactK_ * depth * depth;
      }
    }
    return e;
  }

  // The gradient (3N) and the Gauss-Newton Hessian's triplets at x. The triplets come in the same
  // positions at every call (inactive terms as zeros), so the sparsity pattern never changes.
  void gradientAndHessian(const Points3f& x, const Planes& planes, Eigen::VectorXd& grad,
                          std::vector<Eigen::Triplet<double>>& h) const {
    const ClothConstraints& cc = *p_.constraints;
    grad.setZero(Eigen::Index(3 * n_));
    h.clear();
    auto block = [&](size_t i, size_t j, const Mat3d& m) {
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) h.emplace_back(int(3 * i) + r, int(3 * j) + c, m(r, c));
    };
    auto addGrad = [&](size_t v, const Vec3d& g) { grad.segment<3>(Eigen::Index(3 * v)) += g; };
    auto distance = [&](const DistanceConstraint& c) {
      const Vec3d d = at(x, c.i) - at(x, c.j);
      const double len = d.norm(), rest = double(c.rest);
      Mat3d k = Mat3d::Zero();
      if (len > 1e-12) {
        const double C = (len - rest) / rest, alpha = compliance(c, C);
        const Vec3d dc = d / (len * rest);  // dC/dx_i
        addGrad(c.i, (C / alpha) * dc);
        addGrad(c.j, -(C / alpha) * dc);
        k = dc * dc.transpose() / alpha;
        // Under tension, the edge's geometric stiffness too (its second derivative, positive there):
        // it is what holds a stretched sheet in its plane. Under compression it is negative and left
        // out, so that the Hessian stays positive semidefinite.
        if (C > 0.0) {
          const Vec3d u = d / len;
          k += (C / (alpha * rest * len)) * (Mat3d::Identity() - u * u.transpose());
        }
      }
      block(c.i, c.i, k);
      block(c.j, c.j, k);
      block(c.i, c.j, -k);
      block(c.j, c.i, -k);
    };
    for (const DistanceConstraint& c : cc.stretch) distance(c);
    for (const DistanceConstraint& c : cc.bending) distance(c);
    for (const ShearConstraint& c : cc.shear) {
      const Vec3d e1 = at(x, c.v[1]) - at(x, c.v[0]), e2 = at(x, c.v[2]) - at(x, c.v[0]);
      const Vec3d f0 = double(c.a) * e1 + double(c.c) * e2, f1 = double(c.b) * e1 + double(c.d) * e2;
      const double C = f0.dot(f1), alpha = std::max(double(c.compliance), 1e-20);
      std::array<Vec3d, 3> g;
      g[1] = double(c.a) * f1 + double(c.b) * f0;
      g[2] = double(c.c) * f1 + double(c.d) * f0;
      g[0] = -(g[1] + g[2]);
      for (int a = 0; a < 3; ++a) {
        addGrad(c.v[a], (C / alpha) * g[size_t(a)]);
        for (int b = 0; b < 3; ++b) block(c.v[a], c.v[b], g[size_t(a)] * g[size_t(b)].transpose() / alpha);
      }
    }
    for (const Tether& t : *p_.tethers) {
      const Vec3d d = at(x, t.v) - at(x, t.anchor);
      const double len = d.norm(), over = len - double(t.length) * (1.0 + double(p_.tetherSlack));
      Mat3d k = Mat3d::Zero();
      if (over > 0.0 && len > 1e-12) {
        const Vec3d u = d / len;
        addGrad(t.v, tetherK_ * over * u);
        addGrad(t.anchor, -tetherK_ * over * u);
        k = tetherK_ * u * u.transpose() + (tetherK_ * over / len) * (Mat3d::Identity() - u * u.transpose());
      }
      block(t.v, t.v, k);
      block(t.anchor, t.anchor, k);
      block(t.v, t.anchor, -k);
      block(t.anchor, t.v, -k);
    }
    // Per vertex: its diagonal block holds the band's spring and the contacts (always present).
    std::vector<Mat3d> diag(n_, Mat3d::Zero());
    for (size_t a = 0; a < p_.attached->size(); ++a) {
      const uint32_t v = (*p_.attached)[a];
      const double alpha = std::max(double((*p_.attachCompliance)[a]), 1e-20);
      addGrad(v, (at(x, v) - (*p_.attachTarget)[a].cast<double>()) / alpha);
      diag[v] += Mat3d::Identity() / alpha;
    }
    const Vec3d g = p_.gravity.cast<double>();
    for (size_t v = 0; v < n_; ++v) {
      addGrad(v, -mass_[v] * g);
      for (size_t k = 0; k < planes.count[v]; ++k) {
        const double depth = depthOf(planes.hits[v][k]);
        if (!(depth > 0.0)) continue;
        const Vec3d n = planes.hits[v][k].normal.cast<double>();
        addGrad(v, -contactK_ * depth * n);
        diag[v] += contactK_ * n * n.transpose();
      }
      block(v, v, diag[v]);
    }
  }

 private:
  // How far the cloth is within the thickness of the body part the hit found (its signed distance, so
  // that the energy is the same function of x wherever it is evaluated: a plane fixed at one step
  // would change the energy between steps and the line search's decrease with it).
  double depthOf(const BodyCollider::Hit& hit) const { return double(p_.thickness) - double(hit.signedDistance); }
  static double compliance(const DistanceConstraint& c, double strain) {
    return std::max(double(strain > 0.0 ? c.tensionCompliance : c.compressionCompliance), 1e-20);
  }

  const StaticProblem& p_;
  size_t n_;
  std::vector<double> mass_;
  double tetherK_ = 0.0, contactK_ = 0.0;
};

}  // namespace

StaticSolveResult solveStatic(const StaticProblem& p, Points3f& x, float tolerance, int maxIterations) {
  if (!p.constraints || !p.attached || !p.attachCompliance || !p.attachTarget || !p.tethers || !p.body)
    throw Error("static solve: incomplete problem");
  const size_t n = size_t(x.rows());
  if (p.constraints->inverseMass.size() != n || p.attachTarget->size() != p.attached->size() ||
      p.attachCompliance->size() != p.attached->size())
    throw Error("static solve: the problem does not fit the shape");
  StaticSolveResult r;
  const Energy energy(p, n);
  const std::vector<double>& mass = energy.mass();
  double massSum = 0.0;
  for (double m : mass) massSum += m;
  const double g = p.gravity.norm() > 0.f ? double(p.gravity.norm()) : 9.81;
  // The residual: each vertex's net force over its weight, RMS over the mass (the unbalanced share of
  // gravity's load, as the path's equilibrium residual), and the worst vertex's.
  auto measure = [&](const Eigen::VectorXd& grad) {
    double sum = 0.0, worst = 0.0;
    for (size_t v = 0; v < n; ++v) {
      if (!(mass[v] > 0.0)) continue;
      const double share = grad.segment<3>(Eigen::Index(3 * v)).norm() / (mass[v] * g);
      sum += mass[v] * share * share;
      worst = std::max(worst, share);
    }
    r.residual = float(std::sqrt(sum / std::max(massSum, 1e-30)));
    r.residualMax = float(worst);
  };

  Planes planes;
  Eigen::VectorXd grad;
  std::vector<Eigen::Triplet<double>> triplets;
  Eigen::SparseMatrix<double> hessian(Eigen::Index(3 * n), Eigen::Index(3 * n));
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  bool analysed = false;
  double h = kFirstStep;
  int stalled = 0;  // steps in a row that lowered the energy by less than its rounding
  for (int it = 0;; ++it) {
    energy.findPlanes(x, planes);
    energy.gradientAndHessian(x, planes, grad, triplets);
    measure(grad);
    if (!std::isfinite(r.residual)) {
      r.failure = "the static solve met a non-finite force";
      return r;
    }
    if (r.residual <= tolerance) {
      r.converged = true;
      return r;
    }
    if (it == maxIterations || stalled >= kStallSteps) return r;
    // The proximal term M / h^2 on the diagonal.
    for (size_t v = 0; v < n; ++v)
      for (int c = 0; c < 3; ++c) triplets.emplace_back(int(3 * v) + c, int(3 * v) + c, mass[v] / (h * h));
    hessian.setFromTriplets(triplets.begin(), triplets.end());
    if (!analysed) {
      ldlt.analyzePattern(hessian);
      analysed = true;
    }
    ldlt.factorize(hessian);
    if (ldlt.info() != Eigen::Success) {
      r.failure = "the static solve's linear system could not be factorised";
      return r;
    }
    const Eigen::VectorXd step = ldlt.solve(-grad);
    const double slope = grad.dot(step);
    if (!step.allFinite() || !(slope < 0.0)) {
      r.failure = "the static solve found no descent direction";
      return r;
    }
    // Backtracking line search on the energy (Armijo), its contacts found at each trial shape.
    const double e0 = energy.value(x, planes);  // (the contacts found for this step's gradient, at x)
    double s = 1.0;
    Points3f trial;
    bool accepted = false;
    double e1 = e0;
    for (int k = 0; k < 12; ++k, s *= 0.5) {
      trial = x;
      for (size_t v = 0; v < n; ++v)
        trial.row(Eigen::Index(v)) += (s * step.segment<3>(Eigen::Index(3 * v))).cast<float>().transpose();
      e1 = energy.value(trial);
      if (e1 <= e0 + 1e-4 * s * slope) {
        accepted = true;
        break;
      }
    }
    stalled = accepted && e0 - e1 > kStallDecrease * std::abs(e0) ? 0 : stalled + 1;
    r.iterations = it + 1;
    if (!accepted) {  // no decrease along the step: a shorter proximal step next time
      h = std::max(1e-4, h / kStepGrowth);
      continue;
    }
    x = trial;
    if (s == 1.0) h = std::min(kLargestStep, h * kStepGrowth);
  }
}

}  // namespace swish::bake
