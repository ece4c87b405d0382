#include "swish/replay/replay_plan.hpp"

#include <algorithm>
#include <cstdio>
#include <sstream>

#include "swish/core/error.hpp"
#include "swish/gpu/allocation_plan.hpp"

namespace swish::replay {

namespace {

std::string humanBytes(uint64_t b) {
  char s[64];
  if (b >= (1ull << 20))
    std::snprintf(s, sizeof s, "%.2f MiB", double(b) / double(1ull << 20));
  else if (b >= 1024)
    std::snprintf(s, sizeof s, "%.1f KiB", double(b) / 1024.0);
  else
    std::snprintf(s, sizeof s, "%llu B", static_cast<unsigned long long>(b));
  return s;
}

std::string joinNames(const std::vector<std::string>& names, size_t max = 8) {
  std::string s;
  for (size_t i = 0; i < names.size() && i < max; ++i) s += (i ? ", " : "") + names[i];
  if (names.size() > max) s += ", ... (" + std::to_string(names.size()) + " in all)";
  return s;
}

}  // namespace

ReplayPlan planReplay(const runtime::Scene& scene, const std::map<std::string, const Model*>& models,
                      const PlannerOptions& o) {
  const std::string where = scene.source.empty() ? std::string("scene") : scene.source.string();
  ReplayPlan plan;
  const runtime::SceneOutputs& out = scene.outputs;
  const bool wantMeshes = !o.leaveOut || out.render || out.meshes || out.normalMaps;
  const bool wantShading = !o.leaveOut || out.render || out.normalMaps;
  plan.gpuWork = wantMeshes;

  // Batches in order of first appearance, so instance order (and every figure) is deterministic.
  std::vector<std::string> order;
  std::map<std::string, std::vector<uint32_t>> onScreen;
  for (uint32_t c = 0; c < scene.characters.size(); ++c) {
    const runtime::SceneCharacter& ch = scene.characters[c];
    if (!models.count(ch.model) || !models.at(ch.model))
      throw Error(where + ": characters[" + std::to_string(c) + "].model: '" + ch.model + "' was not loaded");
    if (o.leaveOut && !scene.onScreen(c)) {
      plan.offScreen.push_back(c);
      continue;
    }
    if (!onScreen.count(ch.model)) order.push_back(ch.model);
    onScreen[ch.model].push_back(c);
  }
  if (!o.leaveOut) plan.offScreen.clear();

  for (const std::string& key : order) {
    const Model& m = *models.at(key);
    PlannedBatch b;
    b.model = key;
    b.characters = onScreen[key];
    b.tangentFrames = wantMeshes && wantShading;
    b.normalMaps = wantMeshes && wantShading && !m.normalMaps.empty();
    b.thetaJoints = uint32_t(m.inputJoints.size());
    b.skeletonJoints = uint32_t(m.skeleton.size());
    b.maxDecodedMaps = b.normalMaps ? std::min<uint32_t>(uint32_t(b.characters.size()), m.normalMaps.mapCount()) : 0;
    const uint64_t inst = b.characters.size(), n = m.gameMesh.vertexCount();

    plan.stages.push_back({"pose + forward kinematics", "CPU", key, 0, inst * b.skeletonJoints,
                           std::to_string(inst) + " characters x " + std::to_string(b.skeletonJoints) + " joints"});
    plan.stages.push_back(
        {"Theta (6D rotations)", "CPU", key, 0, inst * b.thetaJoints,
         std::to_string(b.thetaJoints) + " of " + std::to_string(b.skeletonJoints) + " joints per character"});
    plan.stages.push_back({"MLP inference", "CPU", key, 0, inst,
                           "one batch of " + std::to_string(inst) + " (" + std::to_string(m.thetaSize()) + " -> " +
                               std::to_string(m.lambdaSize()) + ")"});
    if (b.normalMaps)
      plan.stages.push_back(
          {"nearest code + temporal filter", "CPU", key, 0, inst,
           std::to_string(inst) + " lookups over " + std::to_string(m.normalMaps.mapCount()) + " maps"});
    if (wantMeshes) {
      plan.stages.push_back({"deform (PCA + skinning)", "GPU", key, 1, inst * n,
                             std::to_string(inst) + " instances x " + std::to_string(n) +
                                 " vertices, K = " + std::to_string(m.meshComponents())});
      if (b.tangentFrames)
        plan.stages.push_back({"normals + tangents", "GPU", key, 2, inst * n,
                               "triangle terms, then a per-vertex gather: " + std::to_string(inst) + " instances"});
      if (b.normalMaps) {
        const uint64_t texels = uint64_t(m.normalMaps.width) * m.normalMaps.height;
        plan.stages.push_back({"VQ decode", "GPU", key, 1, b.maxDecodedMaps * texels,
                               "each selected map once: at most " + std::to_string(b.maxDecodedMaps) + " maps of " +
                                   std::to_string(m.normalMaps.width) + "x" + std::to_string(m.normalMaps.height) +
                                   ", none on a frame whose maps earlier frames decoded"});
        plan.stages.push_back({"normal-map blend", "GPU", key, 1, inst * texels, std::to_string(inst) + " maps"});
      }
      for (const gpu::Allocation& a : gpu::modelAllocations(m, b.normalMaps))
        plan.allocations.push_back({key, a.name, a.bytes, a.image});
      for (uint32_t s = 0; s < o.framesInFlight; ++s)
        for (const gpu::Allocation& a :
             gpu::frameAllocations(m, uint32_t(inst), b.tangentFrames, b.normalMaps, o.normalMapsShareTexels))
          plan.allocations.push_back({key + " frame " + std::to_string(s), a.name, a.bytes, a.image});
    }

    if (!o.leaveOut) {
      plan.batches.push_back(std::move(b));
      continue;
    }
    std::vector<std::string> skipped;
    for (uint32_t j = 0; j < m.skeleton.size(); ++j)
      if (std::find(m.inputJoints.begin(), m.inputJoints.end(), j) == m.inputJoints.end())
        skipped.push_back(m.skeleton.joints[j].name);
    if (!skipped.empty())
      plan.leftOut.push_back(
          {key + ": 6D conversion of " + std::to_string(skipped.size()) + " of " + std::to_string(m.skeleton.size()) +
               " joints (" + joinNames(skipped) + ")",
           "the model's network reads only its " + std::to_string(m.inputJoints.size()) + " input joints"});
    if (inst > 1 && wantMeshes)
      plan.leftOut.push_back({key + ": " + std::to_string(inst - 1) + " of " + std::to_string(inst) +
                                  " per-character dispatches of each GPU pass, and " + std::to_string(inst - 1) +
                                  " MLP calls",
                              std::to_string(inst) + " characters share the model: one batch"});
    if (b.normalMaps && inst > b.maxDecodedMaps)
      plan.leftOut.push_back({key + ": at least " + std::to_string(inst - b.maxDecodedMaps) + " of " +
                                  std::to_string(inst) + " map decodes per frame",
                              "a map selected by several characters is decoded once (the database has " +
                                  std::to_string(m.normalMaps.mapCount()) + " maps)"});
    if (wantMeshes && !b.normalMaps && !m.normalMaps.empty()) {
      uint64_t saved = 0;  // what the database would cost on the GPU
      for (const gpu::Allocation& a : gpu::modelAllocations(m, true)) saved += a.bytes;
      for (const gpu::Allocation& a : gpu::modelAllocations(m, false)) saved -= a.bytes;
      plan.leftOut.push_back({key + ": normal-map lookup, VQ decode and blend; database not uploaded (" +
                                  humanBytes(saved) + ") and no per-character normal maps",
                              "no output wants normal maps (outputs.render and outputs.normalMaps are off)"});
    } else if (wantMeshes && m.normalMaps.empty()) {
      plan.leftOut.push_back({key + ": normal-map lookup, decode and blend", "the model has no normal-map database"});
    }
    if (wantMeshes && !b.tangentFrames)
      plan.leftOut.push_back({key + ": normals + tangents pass",
                              "no output shades the mesh (outputs.render and outputs.normalMaps are off)"});
    plan.batches.push_back(std::move(b));
  }
  if (o.leaveOut && !wantMeshes)
    plan.leftOut.push_back({"every GPU pass (deform, normals + tangents, normal maps)",
                            "no output wants meshes (outputs.render, outputs.meshes and outputs.normalMaps are off)"});
  for (uint32_t c : plan.offScreen) {
    const runtime::SceneCharacter& ch = scene.characters[c];
    const std::string why = !ch.visible ? std::string("marked off screen (visible: false)")
                                        : "placed " + std::to_string((ch.placement.translation - scene.camera).norm()) +
                                              " m from the camera, beyond cullDistance " +
                                              std::to_string(*scene.cullDistance) + " m";
    plan.leftOut.push_back({"character '" + ch.name + "': pose, Theta, MLP, lookup, mesh and normal-map work", why});
  }
  return plan;
}

uint32_t ReplayPlan::gpuDispatchesPerFrame() const {
  uint32_t d = 0;
  for (const auto& s : stages) d += s.dispatchesPerFrame;
  return d;
}

uint64_t ReplayPlan::gpuBytes() const {
  uint64_t b = 0;
  for (const auto& a : allocations) b += a.bytes;
  return b;
}

uint64_t ReplayPlan::rot6JointsPerFrame() const {
  uint64_t j = 0;
  for (const auto& b : batches) j += uint64_t(b.thetaJoints) * b.characters.size();
  return j;
}

const PlannedBatch* ReplayPlan::batchOf(const std::string& model) const {
  for (const auto& b : batches)
    if (b.model == model) return &b;
  return nullptr;
}

std::string ReplayPlan::describe() const {
  std::ostringstream s;
  s << "Stages per frame (at most " << gpuDispatchesPerFrame() << " GPU dispatches, " << rot6JointsPerFrame()
    << " joints to 6D):\n";
  for (const auto& st : stages) {
    s << "  [" << st.device << "] " << st.name;
    if (!st.batch.empty()) s << " <" << st.batch << ">";
    if (st.device == "GPU")
      s << ": " << st.dispatchesPerFrame << (st.dispatchesPerFrame == 1 ? " dispatch" : " dispatches");
    s << " -- " << st.detail << "\n";
  }
  if (stages.empty()) s << "  (none)\n";
  s << "GPU memory: " << humanBytes(gpuBytes()) << " in " << allocations.size() << " allocations\n";
  std::map<std::string, uint64_t> perOwner;
  for (const auto& a : allocations) perOwner[a.owner] += a.bytes;
  for (const auto& [owner, bytes] : perOwner) {
    s << "  " << owner << ": " << humanBytes(bytes) << "\n";
    for (const auto& a : allocations)
      if (a.owner == owner)
        s << "    " << (a.image ? "image  " : "buffer ") << a.name << ": " << humanBytes(a.bytes) << "\n";
  }
  s << "Left out (" << leftOut.size() << "):\n";
  for (const auto& l : leftOut) s << "  - " << l.what << "\n      because " << l.why << "\n";
  if (leftOut.empty()) s << "  (nothing)\n";
  return s.str();
}

nlohmann::json ReplayPlan::toJson() const {
  nlohmann::json j;
  j["gpuWork"] = gpuWork;
  j["gpuDispatchesPerFrame"] = gpuDispatchesPerFrame();
  j["gpuBytes"] = gpuBytes();
  j["rot6JointsPerFrame"] = rot6JointsPerFrame();
  j["batches"] = nlohmann::json::array();
  for (const auto& b : batches)
    j["batches"].push_back({{"model", b.model},
                            {"characters", b.characters},
                            {"tangentFrames", b.tangentFrames},
                            {"normalMaps", b.normalMaps},
                            {"thetaJoints", b.thetaJoints},
                            {"skeletonJoints", b.skeletonJoints},
                            {"maxDecodedMaps", b.maxDecodedMaps}});
  j["offScreen"] = offScreen;
  j["stages"] = nlohmann::json::array();
  for (const auto& s : stages)
    j["stages"].push_back({{"name", s.name},
                           {"device", s.device},
                           {"batch", s.batch},
                           {"dispatchesPerFrame", s.dispatchesPerFrame},
                           {"itemsPerFrame", s.itemsPerFrame},
                           {"detail", s.detail}});
  j["allocations"] = nlohmann::json::array();
  for (const auto& a : allocations)
    j["allocations"].push_back({{"owner", a.owner}, {"name", a.name}, {"bytes", a.bytes}, {"image", a.image}});
  j["leftOut"] = nlohmann::json::array();
  for (const auto& l : leftOut) j["leftOut"].push_back({{"what", l.what}, {"why", l.why}});
  return j;
}

}  // namespace swish::replay
