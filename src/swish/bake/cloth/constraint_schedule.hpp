#pragma once
// The constraint sweep of the cloth solver in dependency levels, so that it runs eight constraints at
// a time (AVX2) and gives bitwise the answer of the plain sequential sweep.
//
// A Gauss-Seidel sweep projects its constraints one after another, each seeing what the ones before it
// moved. Two constraints that share no vertex touch disjoint data (their vertices' positions and their
// own multiplier), so swapping them changes nothing, not even a rounding. Give each constraint a level
// one above the highest level of the constraints before it in the sweep that share a vertex with it:
// constraints of one level share no vertex, and running the levels in order sees, for every constraint,
// exactly the positions the sequential sweep would have shown it. Within a level the constraints are
// independent, so eight of them run in the lanes of one AVX2 register. The vector kernels do the scalar
// projection's float operations in the scalar projection's order (cloth_constraints.hpp: no fused
// multiply-add, Eigen's order for a 3-vector's sums, x0 + (x1 + x2)); a unit test checks the results
// are bitwise equal, so the solver's answer, its fingerprint and every cached pose stay as they were.
//
// Where the solver spends its time (perf on a default-jersey pose, docs/baking.md): two thirds in these
// sweeps, the stretch, shear and bending blocks of every substep.
#include <cstdint>
#include <vector>

#include "swish/bake/cloth/cloth_constraints.hpp"

namespace swish::bake {

// Distance constraints (stretch or bending) in level order, with the per-constraint figures the
// projection reads laid out one array each (the vector kernel loads eight at a time).
struct DistanceSchedule {
  std::vector<DistanceConstraint> constraints;  // level by level
  std::vector<uint32_t> levelStart;             // constraints of level l: [levelStart[l], levelStart[l + 1])
  // Per scheduled constraint: 3 * i and 3 * j (offsets of the vertices' x in the row-major positions),
  // rest, both compliances, w_i, w_j and (w_i + w_j) / rest^2 as projectDistance computes it.
  std::vector<int32_t> i3, j3;
  std::vector<float> rest, tensionCompliance, compressionCompliance, wi, wj, wsum;
};

struct ShearSchedule {
  std::vector<ShearConstraint> constraints;
  std::vector<uint32_t> levelStart;
  std::vector<int32_t> v3[3];  // 3 * vertex, per corner
  std::vector<float> a, b, c, d, compliance, w[3];
};

// The solver's stretch, shear and bending blocks, each in dependency levels, with the inverse masses
// they were scheduled with (the vector kernels read them from the blocks' own arrays, the scalar
// projection from here, so the two cannot disagree).
struct ConstraintSchedule {
  DistanceSchedule stretch, bending;
  ShearSchedule shear;
  std::vector<float> inverseMass;
  // One sweep of the three blocks in the solver's order (stretch, shear, bending), as the sequential
  // loops over ClothConstraints would run it; lambda: total() multipliers, the blocks' in that order.
  // `vector`: the AVX2 kernels where the processor has them (false: the scalar projection alone). The
  // answer is bitwise the same either way.
  void sweep(float* x, float invDt2, float* lambda, bool vector = true) const;
  // How many constraints ran in vector lanes per sweep (the rest: levels' tails of fewer than eight).
  size_t vectorised() const;
  size_t total() const { return stretch.constraints.size() + shear.constraints.size() + bending.constraints.size(); }
};

// Levels for constraints given in sweep order, each as its vertices: level[k] for constraint k.
std::vector<uint32_t> dependencyLevels(size_t vertexCount, size_t constraintCount, int verticesPerConstraint,
                                       const uint32_t* vertices);

// The schedule of a constraint set; inverseMass is the one the sweeps will use (ClothConstraints').
ConstraintSchedule buildConstraintSchedule(const ClothConstraints& cc);

// Whether this processor runs the AVX2 kernels.
bool constraintSweepVectorised();

namespace detail {
// The AVX2 kernels (constraint_schedule_avx2.cpp): constraints [begin, end) of one level, end - begin
// a multiple of eight.
void sweepDistanceAvx2(const DistanceSchedule& s, size_t begin, size_t end, float* x, float invDt2, float* lambda);
void sweepShearAvx2(const ShearSchedule& s, size_t begin, size_t end, float* x, float invDt2, float* lambda);
bool avx2Available();
}  // namespace detail

}  // namespace swish::bake
