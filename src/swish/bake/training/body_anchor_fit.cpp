#include "swish/bake/training/body_anchor_fit.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <span>
#include <string>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

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
  const size_t i = std::min(v.size() - 1, size_t(std::lround(q * double(v.size() - 1))));
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(i), v.end());
  return v[i];
}

// The point `p` of the posed body's triangle t (posed corner positions `posed`) taken back to the rest body by
// its barycentric coordinates.
Vec3f restPointOf(const BodyCollider& rest, const Points3f& posed, int t, const Vec3f& p) {
  const Triangles& tris = rest.triangles();
  const Points3f& r = rest.positions();
  const uint32_t c[3] = {tris(t, 0), tris(t, 1), tris(t, 2)};
  const Vec3f bc =
      barycentric(p, posed.row(c[0]).transpose(), posed.row(c[1]).transpose(), posed.row(c[2]).transpose());
  return bc[0] * r.row(c[0]).transpose() + bc[1] * r.row(c[1]).transpose() + bc[2] * r.row(c[2]).transpose();
}

// The rest body's own answer at such a point of triangle t (its pseudo-normal, as the first anchors have), on
// `part`, from just outside it along the triangle's face normal; not found for a degenerate triangle.
BodyCollider::Hit restHitAt(const BodyCollider& rest, int t, const Vec3f& point, int part) {
  const Triangles& tris = rest.triangles();
  const Points3f& r = rest.positions();
  const Vec3f a = r.row(tris(t, 0)).transpose(), b = r.row(tris(t, 1)).transpose(), c = r.row(tris(t, 2)).transpose();
  const Vec3f fn = (b - a).cross(c - a);
  if (!(fn.norm() > 0.f)) return {};
  return rest.closest(point + 0.001f * fn.normalized(), 0.01f, part);
}

// Where the first balls miss the skin under the cloth, found once for the slide and the cover anchors:
// over the poses (evenly spread, at most slidePoses), per vertex with a first anchor whose garment vertex
// lies within slideContact of its first anchor's part of the POSED body, that body's closest point (the
// skin under the cloth) when it lies slideMinGap or more outside the first anchor's posed ball, with the
// same point on the rest body (by its triangle's barycentric coordinates) and that gap. Each vertex writes
// its own entries only, in pose order: the same answer on any thread count.
struct SkinMiss {
  size_t pose;
  Vec3f skin;  // posed
  Vec3f rest;  // the same point on the rest body
  int triangle;
  float gap;  // metres outside the ball(s)
};

// How far `skin` lies outside the anchor's ball in the pose of `mats` (its skinned centre).
float distanceOff(const BodyAnchor& a, const Vec3f& skin, std::span<const Mat4f> mats) {
  return (skin - runtime::skinAnchorCentre(a, mats)).norm() - a.radius;
}

std::vector<std::vector<SkinMiss>> firstBallMisses(BodyAnchorFit& fit, const BodyCollider& rest,
                                                   const std::vector<int>& firstPart,
                                                   const std::vector<BodyAnchorSlidePose>& poses,
                                                   const BodyAnchorFitSettings& s) {
  const size_t n = firstPart.size();
  std::vector<std::vector<SkinMiss>> misses(n);
  BodyCollider posed = rest;
  const size_t step =
      std::max<size_t>(1, (poses.size() + std::max<size_t>(1, s.slidePoses) - 1) / std::max<size_t>(1, s.slidePoses));
  for (size_t p = 0; p < poses.size(); p += step) {
    posed.pose(poses[p].skinMatrices);
    ++fit.slidePoses;
    const Points3f& g = *poses[p].garment;
    const Points3f& pos = posed.positions();
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& range) {
      for (size_t v = range.begin(); v < range.end(); ++v) {
        if (firstPart[v] < 0) continue;
        const Vec3f x = g.row(Eigen::Index(v)).transpose();
        if (!x.allFinite()) continue;
        const BodyCollider::Hit h = posed.closest(x, s.slideContact, firstPart[v]);
        if (!h.found || h.triangle < 0) continue;
        const float gap = distanceOff(fit.anchors.anchors[v], h.point, poses[p].skinMatrices);
        if (!(gap >= s.slideMinGap)) continue;
        misses[v].push_back({p, h.point, restPointOf(rest, pos, h.triangle, h.point), h.triangle, gap});
      }
    });
  }
  return misses;
}

// The slide anchors (BodyAnchorFitSettings::slideMinGap): per vertex with a first anchor and no second, the
// first ball's largest miss (the first pose of it: the strict "larger", poses in order) gives the second
// anchor, the rest body's ball at that point.
template <class AnchorAt>
void fitSlideAnchors(BodyAnchorFit& fit, const BodyCollider& rest, const std::vector<int>& firstPart,
                     const std::vector<std::vector<SkinMiss>>& misses, const AnchorAt& anchorAt) {
  std::vector<float> slides, gaps;
  fit.isSlide.assign(firstPart.size(), 0);
  for (size_t v = 0; v < firstPart.size(); ++v) {
    if (firstPart[v] < 0 || fit.anchors.second[v].present()) continue;
    const SkinMiss* worst = nullptr;
    for (const SkinMiss& m : misses[v])
      if (m.gap > (worst ? worst->gap : 0.f)) worst = &m;
    if (!worst) continue;
    const BodyCollider::Hit h = restHitAt(rest, worst->triangle, worst->rest, firstPart[v]);
    if (!h.found || h.triangle < 0) continue;
    bool flipped = false;
    const BodyAnchor anchor = anchorAt(h, flipped);
    if (!anchor.present()) continue;
    fit.anchors.second[v] = anchor;
    ++fit.secondAnchored;
    ++fit.slideAnchored;
    fit.isSlide[v] = 1;
    slides.push_back(1000.f * (worst->rest - fit.anchors.anchors[v].position).norm());
    gaps.push_back(1000.f * worst->gap);
  }
  fit.slideMedianMm = percentile(slides, 0.5);
  fit.slideMaxMm = slides.empty() ? 0.f : *std::max_element(slides.begin(), slides.end());
  fit.slideGapMedianMm = percentile(gaps, 0.5);
}

// The cover anchors (BodyAnchorFitSettings::coverAnchors): per vertex, the first ball's misses that the
// second ball (where there is one) misses too, by slideMinGap or more (the gap then the smaller of the two);
// of up to coverCandidates balls under those misses, the one covering the largest summed gap. Each vertex
// writes its own entries only; candidates in ascending miss order and the strict "larger" keep it
// deterministic.
template <class AnchorAt>
void fitCoverAnchors(BodyAnchorFit& fit, const BodyCollider& rest, const std::vector<int>& firstPart,
                     const std::vector<BodyAnchorSlidePose>& poses, const std::vector<std::vector<SkinMiss>>& first,
                     const BodyAnchorFitSettings& s, const AnchorAt& anchorAt) {
  const size_t n = firstPart.size();
  fit.anchors.third.assign(n, BodyAnchor{});
  std::vector<size_t> missed(n, 0), covered(n, 0);
  const size_t most = std::max<size_t>(1, s.coverCandidates);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 16), [&](const tbb::blocked_range<size_t>& range) {
    std::vector<SkinMiss> m;
    std::vector<size_t> candidates;
    for (size_t v = range.begin(); v < range.end(); ++v) {
      m.clear();
      const BodyAnchor* second = fit.anchors.second[v].present() ? &fit.anchors.second[v] : nullptr;
      for (SkinMiss q : first[v]) {
        if (second) q.gap = std::min(q.gap, distanceOff(*second, q.skin, poses[q.pose].skinMatrices));
        if (q.gap >= s.slideMinGap) m.push_back(q);
      }
      missed[v] = m.size();
      if (m.empty()) continue;
      // The largest miss, and misses spread evenly over the poses.
      candidates.clear();
      size_t largest = 0;
      for (size_t i = 1; i < m.size(); ++i)
        if (m[i].gap > m[largest].gap) largest = i;
      candidates.push_back(largest);
      const size_t spread = std::min(m.size(), most > 1 ? most - 1 : size_t(0));
      for (size_t k = 0; k < spread; ++k) candidates.push_back(k * m.size() / spread);
      std::sort(candidates.begin(), candidates.end());
      candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
      double best = 0;
      size_t bestCovered = 0;
      BodyAnchor chosen;
      for (const size_t i : candidates) {
        const BodyCollider::Hit h = restHitAt(rest, m[i].triangle, m[i].rest, firstPart[v]);
        if (!h.found || h.triangle < 0) continue;
        bool flipped = false;
        const BodyAnchor candidate = anchorAt(h, flipped);
        if (!candidate.present()) continue;
        double weight = 0;
        size_t count = 0;
        for (const SkinMiss& q : m)
          if (distanceOff(candidate, q.skin, poses[q.pose].skinMatrices) <= s.coverReach)
            weight += double(q.gap), ++count;
        if (weight > best) best = weight, bestCovered = count, chosen = candidate;
      }
      if (!(best > 0)) continue;
      fit.anchors.third[v] = chosen;
      covered[v] = bestCovered;
    }
  });
  for (size_t v = 0; v < n; ++v) {
    fit.coverMisses += missed[v];
    fit.coverCovered += covered[v];
    fit.coverAnchored += fit.anchors.third[v].present() ? 1 : 0;
  }
}

}  // namespace

BodyAnchorFit fitBodyAnchors(const Mesh& body, const Skeleton& skeleton, const Mesh& garment,
                             const BodyAnchorFitSettings& s, const std::vector<BodyAnchorSlidePose>& poses) {
  body.validate("body anchor fit: body", skeleton.size());
  if (body.triangleCount() == 0) throw Error("body anchor fit: the body has no triangles");
  if (body.skin.vertexCount() != body.vertexCount()) throw Error("body anchor fit: the body has no skin weights");
  if (!garment.positions.allFinite()) throw Error("body anchor fit: the garment has non-finite positions");
  if (!(s.maxDistance > 0.f) || !std::isfinite(s.maxDistance))
    throw Error("body anchor fit: the largest anchor distance must be a positive number of metres");
  if (!(s.margin >= 0.f && s.margin <= kMaxAnchorMargin))
    throw Error("body anchor fit: the margin must be in [0, 0.05] metres");
  for (size_t p = 0; p < poses.size(); ++p) {
    if (poses[p].skinMatrices.size() != skeleton.size())
      throw Error("body anchor fit: slide pose " + std::to_string(p) + " has " +
                  std::to_string(poses[p].skinMatrices.size()) + " skinning matrices for " +
                  std::to_string(skeleton.size()) + " joints");
    if (!poses[p].garment || poses[p].garment->rows() != garment.positions.rows())
      throw Error("body anchor fit: slide pose " + std::to_string(p) + " has a garment of " +
                  std::to_string(poses[p].garment ? poses[p].garment->rows() : 0) + " vertices for " +
                  std::to_string(garment.vertexCount()));
  }

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
  // The anchor at a closest-point answer: normal, skin and inscribed ball there (see the header).
  auto anchorAt = [&](const BodyCollider::Hit& hit, bool& flipped) {
    BodyAnchor a;
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
    flipped = normal.dot(hit.normal) < 0.f;
    if (flipped) normal = -normal;

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
    if (!(sum > 0.f)) return a;  // a corner without weights (Mesh::validate refuses those): no anchor
    a.position = hit.point;
    a.normal = normal;
    a.radius = inscribedRadius(collider, hit.point, normal, hit.part, s.maxRadius);
    a.clearance = s.margin;
    for (size_t i = 0; i < ranked.size(); ++i) {
      a.joints[i] = ranked[i].first;
      a.weights[i] = ranked[i].second / sum;
    }
    return a;
  };

  const size_t n = garment.vertexCount();
  BodyAnchorFit fit;
  fit.anchors.margin = s.margin;
  fit.maxDistanceMm = 1000.f * s.maxDistance;
  fit.anchors.anchors.assign(n, BodyAnchor{});
  if (s.secondAnchors) fit.anchors.second.assign(n, BodyAnchor{});
  std::vector<float> distances, radii;
  std::vector<int> firstPart(n, -1);  // the part of each vertex's first anchor (-1: none)
  for (size_t v = 0; v < n; ++v) {
    const Vec3f x = garment.positions.row(Eigen::Index(v)).transpose();
    const BodyCollider::Hit hit = collider.closest(x, s.maxDistance);
    bool flipped = false;
    BodyAnchor a = hit.found && hit.triangle >= 0 ? anchorAt(hit, flipped) : BodyAnchor{};
    if (!a.present()) {
      ++fit.tooFar;
      continue;
    }
    fit.flippedNormals += flipped ? 1 : 0;
    fit.anchors.anchors[v] = a;
    firstPart[v] = hit.part;
    ++fit.anchored;
    if (hit.signedDistance < 0.f) ++fit.insideAtRest;
    if ((x - a.centre()).norm() - a.radius < s.margin) ++fit.withinMargin;
    distances.push_back(1000.f * (x - a.position).norm());
    radii.push_back(1000.f * a.radius);
    if (!s.secondAnchors) continue;
    // The nearest point of any other part within the bound (none on a one-part body).
    const BodyCollider::Hit other = collider.closest(x, s.maxDistance, -1, hit.part);
    if (!other.found || other.triangle < 0 || other.part == hit.part) continue;
    const BodyAnchor b = anchorAt(other, flipped);
    if (!b.present()) continue;
    fit.anchors.second[v] = b;
    ++fit.secondAnchored;
  }
  if (s.secondAnchors && !poses.empty()) {
    const std::vector<std::vector<SkinMiss>> misses = firstBallMisses(fit, collider, firstPart, poses, s);
    fitSlideAnchors(fit, collider, firstPart, misses, anchorAt);
    if (s.coverAnchors) fitCoverAnchors(fit, collider, firstPart, poses, misses, s, anchorAt);
  }
  if (s.garmentJoints && garment.skin.vertexCount() == n) onGarmentJoints(fit, garment.skin);
  // A model without them, not N empty ones (a third set needs a second one before it, empty or not).
  if (fit.coverAnchored == 0) fit.anchors.third.clear();
  if (fit.secondAnchored == 0 && fit.coverAnchored == 0) fit.anchors.second.clear();
  fit.medianMm = percentile(distances, 0.5);
  fit.p95Mm = percentile(distances, 0.95);
  fit.maxMm = distances.empty() ? 0.f : *std::max_element(distances.begin(), distances.end());
  fit.radiusP10Mm = percentile(radii, 0.1);
  fit.radiusMedianMm = percentile(radii, 0.5);
  return fit;
}

void onGarmentJoints(BodyAnchorFit& fit, const SkinWeights& skin) {
  BodyAnchors& anchors = fit.anchors;
  const size_t influences = size_t(std::max(skin.influences, 0));
  double dropped = 0;
  for (uint32_t set = 0; set < anchors.slots(); ++set) {
    std::vector<BodyAnchor>& all = anchors.slot(set);
    if (all.size() != skin.vertexCount())
      throw Error("body anchor fit: " + std::to_string(all.size()) + " " + anchorSlotName(set) + " anchors for " +
                  std::to_string(skin.vertexCount()) + " skinned garment vertices");
    for (size_t v = 0; v < all.size(); ++v) {
      BodyAnchor& a = all[v];
      if (!a.present()) continue;
      BodyAnchor kept = a;
      kept.joints.fill(0);
      kept.weights.fill(0.f);
      size_t n = 0;
      float sum = 0.f;
      bool changed = false;
      for (size_t i = 0; i < size_t(kAnchorInfluences); ++i) {
        if (a.weights[i] == 0.f) continue;
        bool own = false;
        for (size_t k = 0; k < influences && !own; ++k) own = skin.joints[v * influences + k] == a.joints[i];
        if (!own) {
          changed = true;
          ++fit.garmentJointsDropped;
          dropped += a.weights[i];
          fit.garmentJointsMaxDropped = std::max(fit.garmentJointsMaxDropped, a.weights[i]);
          continue;
        }
        kept.joints[n] = a.joints[i];
        kept.weights[n++] = a.weights[i];
        sum += a.weights[i];
      }
      if (!changed) continue;
      ++fit.garmentJointsChanged;
      if (!(sum > 0.f)) {
        a = BodyAnchor{};
        ++fit.garmentJointsRemoved;
        size_t& count = set == 0 ? fit.anchored : set == 1 ? fit.secondAnchored : fit.coverAnchored;
        count -= count > 0 ? 1 : 0;
        if (set == 1 && v < fit.isSlide.size() && fit.isSlide[v]) {
          fit.isSlide[v] = 0;
          fit.slideAnchored -= fit.slideAnchored > 0 ? 1 : 0;
        }
        continue;
      }
      for (size_t i = 0; i < n; ++i) kept.weights[i] /= sum;
      a = kept;
    }
  }
  fit.garmentJointsMeanDropped = fit.garmentJointsDropped ? float(dropped / double(fit.garmentJointsDropped)) : 0.f;
}

BodyAnchorCalibration calibrateBodyAnchors(BodyAnchors& anchors, const std::vector<BodyAnchorCalibrationPose>& poses,
                                           const BodyAnchorCalibrationSettings& s) {
  if (!(s.step > 0.f) || !std::isfinite(s.step)) throw Error("body anchor calibration: the step must be > 0 metres");
  if (!(s.tolerance >= 0.f) || !std::isfinite(s.tolerance))
    throw Error("body anchor calibration: the tolerance must be >= 0 metres");
  const size_t n = anchors.anchors.size();
  for (uint32_t slot = 1; slot < anchors.slots(); ++slot)
    if (anchors.slot(slot).size() != n)
      throw Error("body anchor calibration: " + std::to_string(anchors.slot(slot).size()) + " " + anchorSlotName(slot) +
                  " anchors for " + std::to_string(n) + " anchors");
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
    float d;   // the vertex's distance off the ball's surface (negative inside)
    Vec3f c;   // the ball's skinned centre
    size_t k;  // index into the vertex's (x, t) pairs
  };
  // Per calibration pose with finite values: the vertex so far, the truth, the pose.
  std::vector<Vec3f> xs, ts;
  std::vector<size_t> at;
  std::vector<Sample> samples;
  std::vector<float> lowered;
  double without = 0, with = 0;
  size_t pairs = 0, pushed = 0;
  for (size_t v = 0; v < n; ++v) {
    xs.clear(), ts.clear(), at.clear();
    for (size_t p = 0; p < poses.size(); ++p) {
      const Vec3f x = poses[p].predicted->row(Eigen::Index(v)).transpose();
      const Vec3f t = poses[p].truth->row(Eigen::Index(v)).transpose();
      if (!x.allFinite() || !t.allFinite()) continue;
      xs.push_back(x), ts.push_back(t), at.push_back(p);
      without += double((x - t).norm()), ++pairs;
    }
    const std::vector<Vec3f> start = xs;
    // Each anchor set in the run time's order, each calibrated on where the sets before it leave the vertex.
    for (uint32_t slot = 0; slot < anchors.slots(); ++slot) {
      BodyAnchor& an = anchors.slot(slot)[v];
      if (!an.present()) continue;
      samples.clear();
      for (size_t k = 0; k < xs.size(); ++k) {
        const Vec3f centre = runtime::skinAnchorCentre(an, poses[at[k]].skinMatrices);
        if (centre.allFinite()) samples.push_back({(xs[k] - centre).norm() - an.radius, centre, k});
      }
      std::sort(samples.begin(), samples.end(), [](const Sample& a, const Sample& b) { return a.d < b.d; });
      // The change of the summed error when every sample is pushed to clearance cl (only those with d < cl move).
      auto change = [&](float cl) {
        double sum = 0;
        for (const Sample& q : samples) {
          if (!(q.d < cl)) break;
          sum += double((runtime::pushedOutOfBall(xs[q.k], q.c, an.radius + cl) - ts[q.k]).norm()) -
                 double((xs[q.k] - ts[q.k]).norm());
        }
        return sum;
      };
      // The highest clearance whose push adds at most the tolerance (a second anchor left uncalibrated
      // keeps its own).
      bool found = true;
      float chosen = an.clearance;
      if (slot == 0 || s.second) {
        found = false;
        for (int step = 0;; ++step) {
          const float cl = anchors.margin - float(step) * s.step;
          if (cl < -kMaxAnchorDepth || !(an.radius + cl > 0.f)) break;
          if (change(cl) <= double(s.tolerance) * double(samples.size())) {
            chosen = cl, found = true;
            break;
          }
        }
      }
      if (!found) {
        an = BodyAnchor{};
        ++c.dropped;
        c.secondDropped += slot ? 1 : 0;
        continue;
      }
      if (chosen < an.clearance) {
        an.clearance = chosen;
        ++c.lowered;
        lowered.push_back(1000.f * chosen);
      }
      for (const Sample& q : samples) xs[q.k] = runtime::pushedOutOfBall(xs[q.k], q.c, an.reach());
    }
    for (size_t k = 0; k < xs.size(); ++k) {
      pushed += xs[k] != start[k] ? 1 : 0;
      with += double((xs[k] - ts[k]).norm());
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
          {"second_dropped", c.secondDropped},
          {"median_lowered_mm", c.medianLoweredMm},
          {"vertex_mean_mm_without", c.meanMmWithout},
          {"vertex_mean_mm_with", c.meanMmWith},
          {"pushed_share", c.pushedShare}};
}

nlohmann::json toJson(const BodyAnchorFit& f) {
  return {{"anchored", f.anchored},
          {"second_anchored", f.secondAnchored},
          {"slide_anchored", f.slideAnchored},
          {"slide_poses", f.slidePoses},
          {"slide_median_mm", f.slideMedianMm},
          {"slide_max_mm", f.slideMaxMm},
          {"slide_gap_median_mm", f.slideGapMedianMm},
          {"cover_anchored", f.coverAnchored},
          {"cover_misses", f.coverMisses},
          {"cover_covered", f.coverCovered},
          {"too_far", f.tooFar},
          {"garment_joints",
           {{"anchors_changed", f.garmentJointsChanged},
            {"influences_dropped", f.garmentJointsDropped},
            {"anchors_removed", f.garmentJointsRemoved},
            {"dropped_weight_mean", f.garmentJointsMeanDropped},
            {"dropped_weight_max", f.garmentJointsMaxDropped}}},
          {"margin_mm", std::round(1e6 * double(f.anchors.margin)) / 1e3},  // in micrometre steps: 6, not 6.000000052
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
