// Vector helpers of the tangent-frame kernels, written out in the operation order of Eigen as
// core/mesh_frames.cpp uses it, so that results round like the CPU definition. `precise` forbids FMA
// contraction.

// Eigen's cross product, component by component.
vec3 crossCpu(vec3 a, vec3 b) {
  precise vec3 c = vec3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
  return c;
}
float dotCpu(vec3 a, vec3 b) {
  precise float d = (a.x * b.x + a.y * b.y) + a.z * b.z;
  return d;
}
float normCpu(vec3 a) { return sqrt(dotCpu(a, a)); }
bool isFinite(float x) { return !isnan(x) && !isinf(x); }

// core/mesh_frames.cpp anyPerpendicular: normalize(cross(n, e)), e the axis least aligned with n
// (Eigen's normalized(): unchanged when the squared norm is 0).
vec3 anyPerpendicular(vec3 n) {
  const vec3 a = abs(n);
  vec3 e = (a.x <= a.y && a.x <= a.z) ? vec3(1, 0, 0) : (a.y <= a.z ? vec3(0, 1, 0) : vec3(0, 0, 1));
  precise vec3 c = crossCpu(n, e);
  const float z = dotCpu(c, c);
  if (z > 0.0) c = c / sqrt(z);
  return c;
}

// The end of computeVertexFrames for one vertex: normal from the summed face terms, tangent
// Gram-Schmidt-orthogonalised against it (any perpendicular when degenerate), bitangent sign.
void finishVertexFrame(vec3 nsum, vec3 tsum, vec3 bsum, out vec3 nrm, out vec4 tangent) {
  const float nl = normCpu(nsum);
  precise vec3 n = nl > 0.0 ? nsum / nl : vec3(0, 0, 1);
  precise vec3 tan = tsum - n * dotCpu(n, tsum);
  const float tl = normCpu(tan);
  tan = (tl > 1e-20 && isFinite(tl)) ? tan / tl : anyPerpendicular(n);
  const float w = dotCpu(crossCpu(n, tan), bsum) < 0.0 ? -1.0 : 1.0;
  nrm = n;
  tangent = vec4(tan, w);
}
