#include "swish/bake/character/default_character.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>

#include "swish/bake/character/default_character_jersey.hpp"
#include "swish/bake/character/default_character_tube.hpp"
#include "swish/core/error.hpp"
#include "swish/core/mesh_frames.hpp"

namespace swish::bake {
namespace {

Vec3f mirrorX(Vec3f v) {
  v.x() = -v.x();
  return v;
}

Skeleton buildSkeleton(const DefaultCharacterRecipe& r, std::map<std::string, Vec3f>& heads) {
  std::vector<RecipeJoint> joints = r.joints;
  if (r.mirrorSkeleton)
    for (const RecipeJoint& j : r.joints) {
      const std::string m = mirroredJointName(j.name);
      if (m == j.name) continue;
      joints.push_back({m, mirroredJointName(j.parent), mirrorX(j.head)});
    }
  // Depth-first order, children in recipe order (mirrored joints after the originals): the order in which a glTF
  // importer walks the exported nodes, so a round trip keeps indices.
  {
    std::vector<RecipeJoint> ordered;
    std::vector<std::string> stack{joints[0].name};
    while (!stack.empty()) {
      const std::string name = stack.back();
      stack.pop_back();
      for (const RecipeJoint& j : joints)
        if (j.name == name) ordered.push_back(j);
      for (auto it = joints.rbegin(); it != joints.rend(); ++it)
        if (it->parent == name) stack.push_back(it->name);
    }
    if (ordered.size() != joints.size()) throw Error("default character recipe: the skeleton has more than one root");
    joints = std::move(ordered);
  }
  Skeleton s;
  for (const RecipeJoint& j : joints) {
    heads[j.name] = j.head;
    Joint out;
    out.name = j.name;
    out.parent = j.parent.empty() ? -1 : s.find(j.parent);
    if (!j.parent.empty() && out.parent < 0)
      throw Error("default character recipe: joint '" + j.name + "' has unknown parent");
    out.rest.translation = out.parent < 0 ? j.head : Vec3f(j.head - heads.at(j.parent));
    s.joints.push_back(out);
  }
  s.validate("default character skeleton");
  s.computeInverseBindFromRest();
  return s;
}

struct BodyPart {
  std::string name;
  std::unique_ptr<SweptEllipseTube> tube;
  int ringsPerSpan, segments;
};

std::vector<BodyPart> buildParts(const DefaultCharacterRecipe& r, const Skeleton& s,
                                 const std::map<std::string, Vec3f>& heads) {
  std::vector<BodyPart> parts;
  auto make = [&](const RecipePart& p, bool mirrored) {
    std::vector<TubeStation> st;
    for (const RecipeStation& x : p.stations) {
      const std::string joint = mirrored ? mirroredJointName(x.joint) : x.joint;
      const std::string at = mirrored ? mirroredJointName(x.at) : x.at;
      Vec3f c = x.at.empty() ? x.center : Vec3f(heads.at(at) + (mirrored ? mirrorX(x.offset) : x.offset));
      if (x.at.empty() && mirrored) c = mirrorX(c);
      const int j = s.find(joint);
      if (j < 0) throw Error("default character recipe: part '" + p.name + "' refers to unknown joint '" + joint + "'");
      st.push_back({c, x.halfWidth, x.halfDepth, j});
    }
    parts.push_back({mirrored ? mirroredJointName(p.name) : p.name, std::make_unique<SweptEllipseTube>(std::move(st)),
                     p.ringsPerSpan, p.segments});
  };
  for (const RecipePart& p : r.parts) {
    make(p, false);
    if (p.mirror) make(p, true);
  }
  return parts;
}

// Per-vertex joint weights while building (sparse, merged by joint).
using WeightMap = std::map<int, float>;

void addWeight(WeightMap& w, int joint, float x) {
  if (x > 0.f) w[joint] += x;
}

Mesh meshParts(const std::vector<BodyPart>& parts, std::vector<WeightMap>& weights, std::vector<int>& partOf) {
  std::vector<Vec3f> pos;
  std::vector<std::array<uint32_t, 3>> tris;
  for (size_t pi = 0; pi < parts.size(); ++pi) {
    const BodyPart& part = parts[pi];
    const SweptEllipseTube& tube = *part.tube;
    const int rings = part.ringsPerSpan * int(tube.stationCount() - 1) + 1;
    const int seg = part.segments;
    const uint32_t base = uint32_t(pos.size());
    auto stationWeights = [&](float param) {
      WeightMap w;
      const int i = std::min(int(param), int(tube.stationCount()) - 2);
      const float t = param - float(i);
      const float s = t * t * (3.f - 2.f * t);
      addWeight(w, tube.station(size_t(i)).joint, 1.f - s);
      addWeight(w, tube.station(size_t(i) + 1).joint, s);
      return w;
    };
    for (int k = 0; k < rings; ++k) {
      const float param = float(k) / float(part.ringsPerSpan);
      const TubeSection sec = tube.section(param);
      const WeightMap w = stationWeights(param);
      for (int j = 0; j < seg; ++j) {
        const float psi = 2.f * float(M_PI) * float(j) / float(seg);
        pos.push_back(sec.center + sec.halfWidth * std::cos(psi) * sec.e1 + sec.halfDepth * std::sin(psi) * sec.e2);
        weights.push_back(w);
        partOf.push_back(int(pi));
      }
    }
    for (int k = 0; k + 1 < rings; ++k)
      for (int j = 0; j < seg; ++j) {
        const uint32_t a0 = base + uint32_t(k * seg + j), a1 = base + uint32_t(k * seg + (j + 1) % seg);
        const uint32_t b0 = a0 + uint32_t(seg), b1 = a1 + uint32_t(seg);
        tris.push_back({a0, a1, b1});
        tris.push_back({a0, b1, b0});
      }
    // Caps: a pole a little beyond each end ring, so the ends are rounded rather than flat.
    const TubeSection first = tube.section(0.f), last = tube.section(float(tube.stationCount() - 1));
    const uint32_t p0 = uint32_t(pos.size());
    pos.push_back(first.center - first.tangent * SweptEllipseTube::capLength(first));
    weights.push_back(stationWeights(0.f));
    partOf.push_back(int(pi));
    const uint32_t p1 = uint32_t(pos.size());
    pos.push_back(last.center + last.tangent * SweptEllipseTube::capLength(last));
    weights.push_back(stationWeights(float(tube.stationCount() - 1)));
    partOf.push_back(int(pi));
    const uint32_t lastRing = base + uint32_t((rings - 1) * seg);
    for (int j = 0; j < seg; ++j) {
      const uint32_t j1 = uint32_t((j + 1) % seg);
      tris.push_back({p0, base + j1, base + uint32_t(j)});
      tris.push_back({p1, lastRing + uint32_t(j), lastRing + j1});
    }
  }
  Mesh m;
  m.positions.resize(Eigen::Index(pos.size()), 3);
  for (size_t v = 0; v < pos.size(); ++v) m.positions.row(Eigen::Index(v)) = pos[v].transpose();
  m.triangles.resize(Eigen::Index(tris.size()), 3);
  for (size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) m.triangles(Eigen::Index(t), k) = tris[t][size_t(k)];
  return m;
}

SkinWeights packWeights(const std::vector<WeightMap>& weights, int influences) {
  SkinWeights s;
  s.influences = influences;
  s.joints.assign(weights.size() * size_t(influences), 0);
  s.weights.assign(weights.size() * size_t(influences), 0.f);
  for (size_t v = 0; v < weights.size(); ++v) {
    std::vector<std::pair<float, int>> w;
    for (const auto& [j, x] : weights[v]) w.push_back({x, j});
    // Heaviest first; ties by joint index so the order is deterministic.
    std::sort(w.begin(), w.end(),
              [](auto a, auto b) { return a.first != b.first ? a.first > b.first : a.second < b.second; });
    if (w.size() > size_t(influences)) w.resize(size_t(influences));
    float total = 0;
    for (auto& x : w) total += x.first;
    if (!(total > 0)) throw Error("default character: vertex " + std::to_string(v) + " received no skin weight");
    for (size_t k = 0; k < w.size(); ++k) {
      s.joints[v * size_t(influences) + k] = uint16_t(w[k].second);
      s.weights[v * size_t(influences) + k] = w[k].first / total;
    }
  }
  return s;
}

void computeFrames(Mesh& m) {
  const Points2f uvs = m.uvs.rows() == m.positions.rows() ? m.uvs : Points2f::Zero(m.positions.rows(), 2);
  const MeshFrameTopology topo = buildFrameTopology(m.triangles, m.positions);
  Points4f tangents;
  computeVertexFrames(m.positions, uvs, m.triangles, topo, m.normals, tangents);
  if (m.uvs.rows() == m.positions.rows()) m.tangents = tangents;
}

}  // namespace

Character makeDefaultCharacter(const DefaultCharacterRecipe& recipe) {
  std::map<std::string, Vec3f> heads;
  Character c;
  c.name = recipe.name;
  c.skeleton = buildSkeleton(recipe, heads);
  const std::vector<BodyPart> parts = buildParts(recipe, c.skeleton, heads);

  // Body: the parts' tubes, weights along each part's stations plus the recipe's blends.
  std::vector<WeightMap> bodyWeights;
  std::vector<int> partOf;
  c.body = meshParts(parts, bodyWeights, partOf);
  std::vector<RecipeBlend> blends;
  for (const RecipeBlend& b : recipe.blends) {
    blends.push_back(b);
    if (b.mirror)
      blends.push_back({mirroredJointName(b.joint), mirroredJointName(b.at), mirrorX(b.offset), b.radius, false});
  }
  for (size_t v = 0; v < bodyWeights.size(); ++v) {
    const Vec3f p = c.body.positions.row(Eigen::Index(v)).transpose();
    for (const RecipeBlend& b : blends) {
      const float d = (p - (heads.at(b.at) + b.offset)).norm() / b.radius;
      if (d >= 1.f) continue;
      const float x = (1.f - d) * (1.f - d);
      for (auto& [j, w] : bodyWeights[v]) w *= 1.f - x;
      addWeight(bodyWeights[v], c.skeleton.find(b.joint), x);
    }
  }
  c.body.skin = packWeights(bodyWeights, 4);
  computeFrames(c.body);

  // Jersey.
  std::vector<const SweptEllipseTube*> tubes;
  const SweptEllipseTube* torso = nullptr;
  std::vector<JerseyArm> arms;
  for (const BodyPart& p : parts) {
    tubes.push_back(p.tube.get());
    if (p.name == "torso") torso = p.tube.get();
    if (p.name == "LeftArmPart") arms.push_back({p.tube.get(), 1.f});
    if (p.name == "RightArmPart") arms.push_back({p.tube.get(), -1.f});
  }
  if (!torso || arms.size() != 2)
    throw Error("default character recipe: the jersey needs body parts named 'torso' and 'LeftArmPart' (mirrored)");
  c.garment = buildJersey(recipe.jersey, *torso, arms, tubes);

  // Skin transfer: inverse-distance blend of the nearest body vertices that are on the visible
  // surface (not buried inside another part, where parts overlap).
  std::vector<bool> visible(c.body.vertexCount(), true);
  for (size_t v = 0; v < visible.size(); ++v) {
    const Vec3f p = c.body.positions.row(Eigen::Index(v)).transpose();
    for (size_t pi = 0; pi < parts.size() && visible[v]; ++pi)
      if (int(pi) != partOf[v] && parts[pi].tube->normalisedRadius(p) < 0.98f) visible[v] = false;
  }
  const int k = recipe.jersey.skinTransferNeighbours;
  std::vector<WeightMap> garmentWeights(c.garment.vertexCount());
  for (size_t g = 0; g < garmentWeights.size(); ++g) {
    const Vec3f p = c.garment.positions.row(Eigen::Index(g)).transpose();
    std::vector<std::pair<float, uint32_t>> nearest;  // (squared distance, body vertex), k smallest
    for (size_t v = 0; v < visible.size(); ++v) {
      if (!visible[v]) continue;
      const float d2 = (c.body.positions.row(Eigen::Index(v)).transpose() - p).squaredNorm();
      if (nearest.size() < size_t(k) || d2 < nearest.back().first) {
        nearest.insert(std::upper_bound(nearest.begin(), nearest.end(), std::make_pair(d2, uint32_t(v))),
                       {d2, uint32_t(v)});
        if (nearest.size() > size_t(k)) nearest.pop_back();
      }
    }
    for (const auto& [d2, v] : nearest) {
      const float w = 1.f / (std::sqrt(d2) + 1e-3f);
      for (int i = 0; i < c.body.skin.influences; ++i) {
        const size_t at = size_t(v) * size_t(c.body.skin.influences) + size_t(i);
        addWeight(garmentWeights[g], c.body.skin.joints[at], w * c.body.skin.weights[at]);
      }
    }
  }
  // Smooth the transferred weights over the jersey's surface (seam copies welded, so both sides of a
  // seam get the same weights): each sweep moves a vertex halfway to its neighbours' mean.
  {
    const std::vector<uint32_t> rep = weldByPosition(c.garment.positions);
    const std::vector<std::vector<uint32_t>> neighbours =
        buildVertexNeighbours(c.garment.triangles, garmentWeights.size(), &rep);
    for (size_t g = 0; g < garmentWeights.size(); ++g) {  // one normalised map per welded vertex
      float total = 0.f;
      for (auto& [j, x] : garmentWeights[g]) total += x;
      for (auto& [j, x] : garmentWeights[g]) x /= total;
    }
    for (int sweep = 0; sweep < recipe.jersey.skinSmoothingIterations; ++sweep) {
      std::vector<WeightMap> next = garmentWeights;
      for (size_t g = 0; g < garmentWeights.size(); ++g) {
        if (rep[g] != g || neighbours[g].empty()) continue;
        WeightMap m;
        for (const auto& [j, x] : garmentWeights[g]) m[j] += 0.5f * x;
        const float share = 0.5f / float(neighbours[g].size());
        for (uint32_t n : neighbours[g])
          for (const auto& [j, x] : garmentWeights[n]) m[j] += share * x;
        next[g] = std::move(m);
      }
      for (size_t g = 0; g < garmentWeights.size(); ++g) next[g] = next[rep[g]];
      garmentWeights = std::move(next);
    }
  }
  c.garment.skin = packWeights(garmentWeights, recipe.jersey.maxInfluences);
  computeFrames(c.garment);

  c.body.validate("default character body", c.skeleton.size());
  c.garment.validate("default character jersey", c.skeleton.size());
  return c;
}

}  // namespace swish::bake
