#include "swish/bake/training/body_anchor_fit.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "swish/bake/cloth/body_collider.hpp"
#include "swish/core/error.hpp"
#include "swish/runtime/reference_push_out.hpp"

namespace swish::bake {

namespace {

// Barycentric coordinates of p (on or near the triangle) in a, b, c; clamped to >= 0 and summing to 1.
Vec3f barycentric(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const Vec3f v0 = b - a, v1 = c - a, v2 = p - a;
  const float d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
  const float den = d00 * d11 - d01 * d01;
  if (!(std::abs(den) > 0.f)) return Vec3f(1.f, 0.f, 0.f);  // degenerate triangle: its first corner
  const float v = (d11 * d20 - d01 * d21) / den, w = (d00 * d21 - d01 * d20) / den;
  Vec3f bc(1.f - v - w, v, w);
  bc = bc.cwiseMax(0.f);
  const float s = bc.sum();
  return s > 0.f ? Vec3f(bc / s) : Vec3f(1.f, 0.f, 0.f);
}

// The radius of the largest ball inside the body's part `part` that touches its surface at `point`
// (centre point - r * normal): a ball fits when no surface of the part lies nearer its centre than r
// (less 1 mm: the interpolated normal is not exactly the surface's, and a ball that fits but for that
// is the body's shape all the same). Doubling from kMinAnchorRadius, then bisection to 0.5 mm: the
// small searches, which are cheap, come first.
float inscribedRadius(const BodyCollider& collider, const Vec3f& point, const Vec3f& normal, int part,
                      float maxRadius) {
  constexpr float kSlack = 0.001f;
  auto fits = [&](float r) { return !collider.closest(point - normal * r, r - kSlack, part).found; };
  float lo = kMinAnchorRadius, hi = 2.f * lo;
  while (hi < maxRadius && fits(hi)) lo = hi, hi *= 2.f;
  if (hi >= maxRadius) {
    if (fits(maxRadius)) return maxRadius;
    hi = maxRadius;
  }
  while (hi - lo > 0.0005f) {
    const float r = 0.5f * (lo + hi);
    (fits(r) ? lo : hi) = r;
  }
  return lo;
}

float percentile(std::vector<float> v, double q) {
  if (v.empty()) return 0.f;
  const size_t i = std::min(v.size() - 1, size_t(q * double(v.size() - 1) + 0.5));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(i), v.end());
  return v[i];
}

}  // namespace

BodyAnchorFit fitBodyAnchors(const Mesh& body, const Skeleton& skeleton, const Mesh& garment,
                             const BodyAnchorFitSettings& s) {
  body.validate("body anchor fit: body", skeleton.size());
  if (body.triangleCount() == 0) throw Error("body anchor fit: the body has no triangles");
  if (body.skin.vertexCount() != body.vertexCount()) throw Error("body anchor fit: the body has no skin weights");
  if (!garment.positions.allFinite()) throw Error("body anchor fit: the garment has non-finite positions");
  if (!(s.maxDistance > 0.f) || !std::isfinite(s.maxDistance))
    throw Error("body anchor fit: the largest anchor distance must be a positive number of metres");
  if (!(s.margin >= 0.f && s.margin <= kMaxAnchorMargin))
    throw Error("body anchor fit: the margin must be in [0, 0.05] metres");

  // The rest body (skinning matrices all identity), searched with cells about the bound's size.
  BodyCollider collider(body, std::clamp(s.maxDistance, 0.01f, 0.1f), "body anchor fit: body");
  collider.pose(std::vector<Mat4f>(skeleton.size(), Mat4f::Identity()));
  const Triangles& tris = collider.triangles();  // welded: seam copies share their first vertex's index
  const Points3f& pos = body.positions;

  // Area-weighted vertex normals over the welded surface (a seam is not a crease).
  std::vector<Vec3f> vertexNormals(body.vertexCount(), Vec3f::Zero());
  for (Eigen::Index t = 0; t < tris.rows(); ++t) {
    const Vec3f a = pos.row(tris(t, 0)).transpose(), b = pos.row(tris(t, 1)).transpose(),
                c = pos.row(tris(t, 2)).transpose();
    const Vec3f areaNormal = (b - a).cross(c - a);  // twice the area, along the face normal
    for (int k = 0; k < 3; ++k) vertexNormals[size_t(tris(t, k))] += areaNormal;
  }

  const int inf = body.skin.influences;
  const size_t n = garment.vertexCount();
  BodyAnchorFit fit;
  fit.anchors.margin = s.margin;
  fit.maxDistanceMm = 1000.f * s.maxDistance;
  fit.anchors.anchors.assign(n, BodyAnchor{});
  std::vector<float> distances, radii;
  for (size_t v = 0; v < n; ++v) {
    const Vec3f x = garment.positions.row(Eigen::Index(v)).transpose();
    const BodyCollider::Hit hit = collider.closest(x, s.maxDistance);
    if (!hit.found || hit.triangle < 0) {
      ++fit.tooFar;
      continue;
    }
    const int t = hit.triangle;
    const uint32_t corner[3] = {tris(t, 0), tris(t, 1), tris(t, 2)};
    const Vec3f bc = barycentric(hit.point, pos.row(corner[0]).transpose(), pos.row(corner[1]).transpose(),
                                 pos.row(corner[2]).transpose());
    Vec3f normal = Vec3f::Zero();
    for (int k = 0; k < 3; ++k) {
      const Vec3f& vn = vertexNormals[corner[k]];
      const float len = vn.norm();
      if (len > 0.f) normal += bc[k] * (vn / len);
    }
    if (!(normal.norm() > 1e-6f)) normal = hit.normal;  // corners' normals cancel (a degenerate sliver)
    normal.normalize();
    if (normal.dot(hit.normal) < 0.f) {
      normal = -normal;
      ++fit.flippedNormals;
    }

    // The body's skin at the point: (joint -> weight) summed over the corners, largest first.
    std::map<uint16_t, float> skin;
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < inf; ++i) {
        const size_t e = size_t(corner[k]) * size_t(inf) + size_t(i);
        if (body.skin.weights[e] > 0.f) skin[body.skin.joints[e]] += bc[k] * body.skin.weights[e];
      }
    std::vector<std::pair<uint16_t, float>> ranked(skin.begin(), skin.end());  // ascending joint
    std::stable_sort(ranked.begin(), ranked.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    if (ranked.size() > size_t(kAnchorInfluences)) ranked.resize(size_t(kAnchorInfluences));
    float sum = 0.f;
    for (const auto& r : ranked) sum += r.second;
    if (!(sum > 0.f)) {  // a corner without weights (Mesh::validate refuses those): no anchor
      ++fit.tooFar;
      continue;
    }
    BodyAnchor& a = fit.anchors.anchors[v];
    a.position = hit.point;
    a.normal = normal;
    a.radius = inscribedRadius(collider, hit.point, normal, hit.part, s.maxRadius);
    a.clearance = s.margin;
    for (size_t i = 0; i < ranked.size(); ++i) {
      a.joints[i] = ranked[i].first;
      a.weights[i] = ranked[i].second / sum;
    }
    ++fit.anchored;
    if (hit.signedDistance < 0.f) ++fit.insideAtRest;
    if ((x - a.centre()).norm() - a.radius < s.margin) ++fit.withinMargin;
    distances.push_back(1000.f * (x - a.position).norm());
    radii.push_back(1000.f * a.radius);
  }
  fit.medianMm = percentile(distances, 0.5);
  fit.p95Mm = percentile(distances, 0.95);
  fit.maxMm = distances.empty() ? 0.f : *std::max_element(distances.begin(), distances.end());
  fit.radiusP10Mm = percentile(radii, 0.1);
  fit.radiusMedianMm = percentile(radii, 0.5);
  return fit;
}

BodyAnchorCalibration calibrateBodyAnchors(BodyAnchors& anchors, const std::vector<BodyAnchorCalibrationPose>& poses,
                                           const BodyAnchorCalibrationSettings& s) {
  if (!(s.step > 0.f) || !std::isfinite(s.step)) throw Error("body anchor calibration: the step must be > 0 metres");
  const size_t n = anchors.anchors.size();
  for (size_t p = 0; p < poses.size(); ++p) {
    const BodyAnchorCalibrationPose& cp = poses[p];
    for (const Points3f* g : {cp.truth, cp.predicted})
      if (!g || size_t(g->rows()) != n)
        throw Error("body anchor calibration: pose " + std::to_string(p) + " has a garment of " +
                    std::to_string(g ? g->rows() : 0) + " vertices for " + std::to_string(n) + " anchors");
  }
  BodyAnchorCalibration c;
  c.poses = poses.size();
  if (poses.empty() || n == 0) return c;
  struct Sample {
    float d;  // the network's vertex's distance off the ball's surface (negative inside)
    Vec3f x, c, t;
    double error;  // |x - t|
  };
  std::vector<Sample> samples;
  std::vector<float> lowered;
  double without = 0, with = 0;
  size_t pairs = 0, pushed = 0;
  for (size_t v = 0; v < n; ++v) {
    BodyAnchor& an = anchors.anchors[v];
    samples.clear();
    for (const BodyAnchorCalibrationPose& cp : poses) {
      const Vec3f x = cp.predicted->row(Eigen::Index(v)).transpose(), t = cp.truth->row(Eigen::Index(v)).transpose();
      if (!x.allFinite() || !t.allFinite()) continue;
      const double e = double((x - t).norm());
      without += e, ++pairs;
      const Vec3f c = an.present() ? runtime::skinAnchorCentre(an, cp.skinMatrices) : Vec3f::Zero();
      if (an.present() && c.allFinite())
        samples.push_back({(x - c).norm() - an.radius, x, c, t, e});
      else
        with += e;
    }
    if (!an.present()) continue;
    std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.d < b.d; });
    // The change of the summed error when every sample is pushed to clearance cl (only those with d < cl move).
    auto change = [&](float cl) {
      double sum = 0;
      for (const Sample& q : samples) {
        if (!(q.d < cl)) break;
        sum += double((runtime::pushedOutOfBall(q.x, q.c, an.radius + cl) - q.t).norm()) - q.error;
      }
      return sum;
    };
    bool found = false;
    float chosen = 0.f;
    for (int k = 0;; ++k) {
      const float cl = anchors.margin - float(k) * s.step;
      if (cl < -kMaxAnchorDepth || !(an.radius + cl > 0.f)) break;
      if (change(cl) <= 0.0) {
        chosen = cl, found = true;
        break;
      }
    }
    if (!found) {
      an = BodyAnchor{};
      ++c.dropped;
      for (const Sample& q : samples) with += q.error;
      continue;
    }
    if (chosen < an.clearance) {
      an.clearance = chosen;
      ++c.lowered;
      lowered.push_back(1000.f * chosen);
    }
    for (const Sample& q : samples) {
      const Vec3f y = runtime::pushedOutOfBall(q.x, q.c, an.reach());
      pushed += y != q.x ? 1 : 0;
      with += double((y - q.t).norm());
    }
  }
  c.medianLoweredMm = percentile(lowered, 0.5);
  if (pairs > 0) {
    c.meanMmWithout = 1000.0 * without / double(pairs);
    c.meanMmWith = 1000.0 * with / double(pairs);
    c.pushedShare = double(pushed) / double(pairs);
  }
  return c;
}

nlohmann::json toJson(const BodyAnchorCalibration& c) {
  return {{"poses", c.poses},
          {"lowered", c.lowered},
          {"dropped", c.dropped},
          {"median_lowered_mm", c.medianLoweredMm},
          {"vertex_mean_mm_without", c.meanMmWithout},
          {"vertex_mean_mm_with", c.meanMmWith},
          {"pushed_share", c.pushedShare}};
}

nlohmann::json toJson(const BodyAnchorFit& f) {
  return {{"anchored", f.anchored},
          {"too_far", f.tooFar},
          {"margin_mm", 1000.0 * double(f.anchors.margin)},
          {"max_distance_mm", f.maxDistanceMm},
          {"inside_at_rest", f.insideAtRest},
          {"within_margin_at_rest", f.withinMargin},
          {"flipped_normals", f.flippedNormals},
          {"distance_median_mm", f.medianMm},
          {"distance_p95_mm", f.p95Mm},
          {"distance_max_mm", f.maxMm},
          {"radius_p10_mm", f.radiusP10Mm},
          {"radius_median_mm", f.radiusMedianMm}};
}

}  // namespace swish::bake
