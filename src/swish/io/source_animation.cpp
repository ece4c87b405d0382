#include "swish/io/source_animation.hpp"

#include <assimp/anim.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "swish/core/error.hpp"
#include "swish/io/assimp_scene.hpp"

namespace swish::io {
namespace {

std::vector<RigidTransform> globalsOf(const SourceAnimation& a, const std::vector<RigidTransform>& locals) {
  std::vector<RigidTransform> g(locals.size());
  for (size_t j = 0; j < locals.size(); ++j) g[j] = a.parents[j] < 0 ? locals[j] : g[size_t(a.parents[j])] * locals[j];
  return g;
}

RigidTransform rigidOf(const Eigen::Matrix4d& m) {
  Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  for (int c = 0; c < 3; ++c) {
    const double n = r.col(c).norm();
    if (n > 1e-12) r.col(c) /= n;
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  r = svd.matrixU() * svd.matrixV().transpose();
  RigidTransform t;
  t.rotation = Quatf(Eigen::Quaterniond(r).normalized().cast<float>());
  t.translation = m.topRightCorner<3, 1>().cast<float>();
  return t;
}

// Value of a key track at `time` (ticks): linear for positions, shortest-arc slerp for rotations.
Vec3f sampleVector(const aiVectorKey* keys, unsigned n, double time) {
  if (n == 1 || time <= keys[0].mTime) return {keys[0].mValue.x, keys[0].mValue.y, keys[0].mValue.z};
  for (unsigned k = 1; k < n; ++k)
    if (time <= keys[k].mTime) {
      const double span = keys[k].mTime - keys[k - 1].mTime;
      const float t = span > 0 ? float((time - keys[k - 1].mTime) / span) : 1.f;
      const Vec3f a(keys[k - 1].mValue.x, keys[k - 1].mValue.y, keys[k - 1].mValue.z);
      const Vec3f b(keys[k].mValue.x, keys[k].mValue.y, keys[k].mValue.z);
      return a + t * (b - a);
    }
  return {keys[n - 1].mValue.x, keys[n - 1].mValue.y, keys[n - 1].mValue.z};
}

Quatf sampleRotation(const aiQuatKey* keys, unsigned n, double time) {
  auto q = [&](unsigned k) {
    return Quatf(keys[k].mValue.w, keys[k].mValue.x, keys[k].mValue.y, keys[k].mValue.z).normalized();
  };
  if (n == 1 || time <= keys[0].mTime) return q(0);
  for (unsigned k = 1; k < n; ++k)
    if (time <= keys[k].mTime) {
      const double span = keys[k].mTime - keys[k - 1].mTime;
      const float t = span > 0 ? float((time - keys[k - 1].mTime) / span) : 1.f;
      Quatf a = q(k - 1), b = q(k);
      if (a.dot(b) < 0) b.coeffs() = -b.coeffs();
      return a.slerp(t, b).normalized();
    }
  return q(n - 1);
}

}  // namespace

int SourceAnimation::find(const std::string& n) const {
  for (size_t j = 0; j < jointNames.size(); ++j)
    if (jointNames[j] == n) return int(j);
  return -1;
}

std::vector<RigidTransform> SourceAnimation::restGlobals() const { return globalsOf(*this, rest); }

std::vector<RigidTransform> SourceAnimation::frameGlobals(size_t frame) const {
  if (frame >= frames.size()) throw Error("animation '" + name + "': frame " + std::to_string(frame) + " out of range");
  return globalsOf(*this, frames[frame]);
}

SourceAnimation readAnimationWithAssimp(const std::filesystem::path& path, double fps) {
  const std::string file = path.string();
  Assimp::Importer importer;
  const aiScene& scene = readAssimpScene(importer, path, /*animationOnly=*/true);
  if (scene.mNumAnimations == 0 || scene.mAnimations[0]->mNumChannels == 0)
    throw Error(file + ": no node animation in the file");
  const aiAnimation& anim = *scene.mAnimations[0];

  SourceAnimation out;
  out.name = anim.mName.length ? anim.mName.C_Str() : path.stem().string();
  // Every node becomes a joint (parents first); animated or not, its transform is needed for the
  // positions of its children.
  std::vector<const aiNode*> nodes;
  std::vector<std::pair<const aiNode*, int>> stack{{scene.mRootNode, -1}};
  while (!stack.empty()) {
    auto [node, parent] = stack.back();
    stack.pop_back();
    const int index = int(nodes.size());
    nodes.push_back(node);
    out.jointNames.push_back(node->mName.C_Str());
    out.parents.push_back(parent);
    out.rest.push_back(rigidOf(toEigen(node->mTransformation)));
    for (unsigned c = node->mNumChildren; c-- > 0;) stack.push_back({node->mChildren[c], index});
  }
  std::unordered_map<std::string, int> channelOf;
  for (unsigned c = 0; c < anim.mNumChannels; ++c) channelOf[anim.mChannels[c]->mNodeName.C_Str()] = int(c);

  const double ticksPerSecond = anim.mTicksPerSecond > 0 ? anim.mTicksPerSecond : 25.0;
  // Rate: the caller's, else the density of the densest rotation track, capped.
  double rate = fps;
  if (rate <= 0) {
    unsigned most = 1;
    for (unsigned c = 0; c < anim.mNumChannels; ++c) most = std::max(most, anim.mChannels[c]->mNumRotationKeys);
    const double seconds = anim.mDuration / ticksPerSecond;
    rate = seconds > 0 ? std::clamp(double(most - 1) / seconds, 1.0, 240.0) : 30.0;
  }
  out.framesPerSecond = rate;
  const double seconds = anim.mDuration / ticksPerSecond;
  const size_t count = size_t(std::floor(seconds * rate + 1e-6)) + 1;
  out.frames.resize(count);
  for (size_t f = 0; f < count; ++f) {
    const double tick = std::min(double(f) / rate * ticksPerSecond, anim.mDuration);
    auto& locals = out.frames[f];
    locals = out.rest;
    for (size_t j = 0; j < nodes.size(); ++j) {
      auto it = channelOf.find(out.jointNames[j]);
      if (it == channelOf.end()) continue;
      const aiNodeAnim& ch = *anim.mChannels[it->second];
      if (ch.mNumRotationKeys) locals[j].rotation = sampleRotation(ch.mRotationKeys, ch.mNumRotationKeys, tick);
      if (ch.mNumPositionKeys) locals[j].translation = sampleVector(ch.mPositionKeys, ch.mNumPositionKeys, tick);
      if (!locals[j].rotation.coeffs().allFinite() || !locals[j].translation.allFinite())
        throw Error(file + ": node '" + out.jointNames[j] + "' has non-finite animation keys");
    }
  }
  return out;
}

}  // namespace swish::io
