#pragma once
// The static solve of the cloth (issue 18: "an equilibrium, not a time"): from the shape the
// transition left, the garment's static equilibrium on the posed body, found by minimising its
// potential energy with Newton's method, and a residual that says how far from it the result is.
//
// The energy is the one whose minimum XPBD's constraints reach only with converged sweeps
// (cloth_constraints.hpp): each constraint's C^2 / (2 alpha) with its compliance alpha (stretch and
// bending per sign of the strain, shear), the top band's springs to their targets, the tethers as
// one-sided springs, gravity, and contact as a one-sided quadratic penalty. Friction is left
// out: a static equilibrium with friction is not a property of the pose (any point of the friction cone
// is one), and the frictionless one is the shape the tolerance and the substeps cannot move.
//
// The method: Gauss-Newton steps (the constraints' Hessian without their second derivatives, so it is
// positive semidefinite), each damped by a proximal term M / h^2 (an implicit time step of length h
// from the current shape, which keeps flat regions' out-of-plane directions solvable) that grows h as
// the steps succeed, a sparse LDLT per step, and a backtracking line search on the energy. Contact is a
// penalty on the signed distance to each body part within reach (BodyCollider::closestRegions, as the
// path's contact planes), found wherever the energy is evaluated. Sequential and deterministic.
#include <string>
#include <vector>

#include "swish/bake/cloth/body_collider.hpp"
#include "swish/bake/cloth/cloth_constraints.hpp"

namespace swish::bake {

// Contact planes kept per cloth vertex, by the path (cloth_solver.cpp) and the static solve alike: one
// per body part (or contact region of a one-surface body), the deepest first (see closestParts,
// closestRegions).
inline constexpr size_t kContactPlanes = 2;

struct StaticProblem {
  const ClothConstraints* constraints = nullptr;
  const std::vector<uint32_t>* attached = nullptr;       // the top band's vertices
  const std::vector<float>* attachCompliance = nullptr;  // per attached vertex (m/N)
  const std::vector<Vec3f>* attachTarget = nullptr;      // per attached vertex, posed
  const std::vector<Tether>* tethers = nullptr;
  float tetherSlack = 0.f;
  const BodyCollider* body = nullptr;  // posed
  float thickness = 0.f;               // m: the cloth keeps this far off the body
  float reach = 0.f;                   // m: contact planes of body parts within this distance
  Vec3f gravity = Vec3f(0.f, -9.81f, 0.f);
};

struct StaticSolveResult {
  int iterations = 0;        // Newton steps taken
  float residual = -1.f;     // at the end: mass-weighted RMS of |force| / (m g) (unbalanced share of gravity)
  float residualMax = -1.f;  // the worst vertex's |force| / (m g)
  bool converged = false;    // residual <= tolerance
  std::string failure;       // non-empty: the solve could not proceed (x is left at its last good shape)
};

// Minimises the energy above from `x` (N x 3, the solve's coordinates) until the residual is at most
// `tolerance` or `maxIterations` steps are spent.
StaticSolveResult solveStatic(const StaticProblem& problem, Points3f& x, float tolerance, int maxIterations);

}  // namespace swish::bake
