#pragma once
// The XPBD constraint set of a simulation mesh for one material: stretch (every edge), shear (every
// triangle, against the garment's grain) and bending (every interior edge, as the distance between
// the two vertices opposite it), plus per-vertex masses. Built once per character and material, read
// by every pose's solve.
#include <vector>

#include "swish/bake/cloth/cloth_material.hpp"
#include "swish/bake/cloth/simulation_mesh.hpp"

namespace swish::bake {

// A distance constraint in strain form, C = (|x_i - x_j| - rest) / rest, with compliance per sign:
// cloth resists stretching much more than compression (it buckles into folds instead).
struct DistanceConstraint {
  uint32_t i, j;
  float rest;
  float tensionCompliance;  // 1/J: 1 / (modulus * area the constraint stands for)
  float compressionCompliance;
};

// In-plane shear of a triangle: C = F0 . F1, where F is the deformation gradient in a rest frame whose
// second axis is the garment's "up" (world +Y projected into the triangle: the warp of a garment cut
// the usual way). coeff holds Dm^-1 so that F0 = a e1 + c e2 and F1 = b e1 + d e2, e_k = x_k - x_0.
struct ShearConstraint {
  uint32_t v[3];
  float a, b, c, d;
  float compliance;
};

struct ClothConstraints {
  std::vector<DistanceConstraint> stretch;  // one per edge; order = first visit over triangles
  std::vector<DistanceConstraint> bending;  // one per interior edge
  std::vector<ShearConstraint> shear;       // one per non-degenerate triangle
  std::vector<float> inverseMass;           // 1 / (density * one third of the incident area)
  std::vector<float> vertexArea;            // m^2, for attachment stiffness
};

// A long-range attachment ("tether", Kim et al. 2012): vertex v may be no farther from its nearest
// attached vertex than the rest geodesic distance times (1 + slack). One-sided, it only ever pulls v
// in, and it is what keeps a hanging garment from stretching while Gauss-Seidel sweeps are still
// carrying the weight up a hundred rows of edges.
struct Tether {
  uint32_t v, anchor;
  float length;  // rest geodesic distance along the mesh edges
};

// Tethers from every vertex connected to `attached` (multi-source Dijkstra over the rest edges;
// ties broken by vertex index, so the result is deterministic). Attached vertices get none.
std::vector<Tether> buildTethers(const SimulationMesh& mesh, const Points3f& restPositions,
                                 const std::vector<uint32_t>& attached);

// Throws Error if the rest mesh has a vertex on no triangle or zero total area.
ClothConstraints buildClothConstraints(const SimulationMesh& mesh, const Points3f& restPositions,
                                       const ClothMaterial& material);

// One XPBD step of a constraint (Macklin et al. 2016): moves the positions (row-major N x 3, raw
// floats) by the inverse masses w and accumulates the multiplier `lambda` (zero it per substep).
// invDt2 = 1 / dt^2. Inline: the solver calls these ~10^8 times per bake.
inline void projectDistance(const DistanceConstraint& c, float* x, const float* w, float invDt2, float& lambda) {
  Eigen::Map<Vec3f> xi(x + 3 * size_t(c.i)), xj(x + 3 * size_t(c.j));
  const Vec3f d = xi - xj;
  const float len = d.norm();
  if (!(len > 1e-9f)) return;  // coincident: no direction to push along
  const float strain = (len - c.rest) / c.rest;
  const bool tension = strain > 0.f;
  // The multiplier belongs to one compliance: when the strain has changed sign since it was
  // accumulated (a later sweep of the same substep), carrying it over into the other branch's
  // alpha * lambda term overshoots by the compliance ratio (10x for a knit). Start that branch afresh.
  if (tension ? lambda > 0.f : lambda < 0.f) lambda = 0.f;
  const float alpha = (tension ? c.tensionCompliance : c.compressionCompliance) * invDt2;
  const float wsum = (w[c.i] + w[c.j]) / (c.rest * c.rest);
  const float dl = (-strain - alpha * lambda) / (wsum + alpha);
  lambda += dl;
  const Vec3f g = d * (dl / (len * c.rest));
  xi += w[c.i] * g;
  xj -= w[c.j] * g;
}

inline void projectShear(const ShearConstraint& c, float* x, const float* w, float invDt2, float& lambda) {
  Eigen::Map<Vec3f> x0(x + 3 * size_t(c.v[0])), x1(x + 3 * size_t(c.v[1])), x2(x + 3 * size_t(c.v[2]));
  const Vec3f e1 = x1 - x0, e2 = x2 - x0;
  const Vec3f f0 = c.a * e1 + c.c * e2, f1 = c.b * e1 + c.d * e2;
  const float C = f0.dot(f1);
  const Vec3f g1 = c.a * f1 + c.b * f0, g2 = c.c * f1 + c.d * f0, g0 = -(g1 + g2);
  const float w0 = w[c.v[0]], w1 = w[c.v[1]], w2 = w[c.v[2]];
  const float wsum = w0 * g0.squaredNorm() + w1 * g1.squaredNorm() + w2 * g2.squaredNorm();
  if (!(wsum > 1e-20f)) return;
  const float alpha = c.compliance * invDt2;
  const float dl = (-C - alpha * lambda) / (wsum + alpha);
  lambda += dl;
  x0 += (w0 * dl) * g0;
  x1 += (w1 * dl) * g1;
  x2 += (w2 * dl) * g2;
}

inline void projectTether(const Tether& t, float slack, float* x) {
  Eigen::Map<Vec3f> xv(x + 3 * size_t(t.v));
  const Eigen::Map<const Vec3f> xa(x + 3 * size_t(t.anchor));
  const Vec3f d = xv - xa;
  const float len = d.norm(), limit = t.length * (1.f + slack);
  if (len > limit) xv -= d * ((len - limit) / len);
}

// Shear strain F0 . F1 of a triangle at positions x (for tests and residuals).
inline float shearStrain(const ShearConstraint& c, const float* x) {
  Eigen::Map<const Vec3f> x0(x + 3 * size_t(c.v[0])), x1(x + 3 * size_t(c.v[1])), x2(x + 3 * size_t(c.v[2]));
  const Vec3f e1 = x1 - x0, e2 = x2 - x0;
  return (c.a * e1 + c.c * e2).dot(c.b * e1 + c.d * e2);
}

}  // namespace swish::bake
