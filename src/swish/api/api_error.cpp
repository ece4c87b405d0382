// Public error codes, the mapping of internal errors onto them, and the plain-struct conversions.
#include <cstring>

#include "swish/api/api_impl.hpp"
#include "swish/core/skeleton.hpp"
#include "swish/runtime/quality_levels.hpp"

namespace swish::api {

const char* errorCodeName(ErrorCode code) {
  switch (code) {
    case ErrorCode::InvalidArgument:
      return "invalid argument";
    case ErrorCode::BadModel:
      return "bad model";
    case ErrorCode::DeviceUnsupported:
      return "device unsupported";
    case ErrorCode::FrameInFlight:
      return "frame in flight";
    case ErrorCode::VulkanFailure:
      return "Vulkan failure";
    case ErrorCode::Internal:
      return "internal error";
  }
  return "unknown error";
}

ErrorCode classify(const swish::Error& e, ErrorCode fallback) {
  // gpu/vk_check.cpp words every unexpected VkResult this way.
  if (std::strncmp(e.what(), "Vulkan call failed:", 19) == 0) return ErrorCode::VulkanFailure;
  return fallback;
}

Quatf toQuatf(const Quat& q) { return Quatf(q.w, q.x, q.y, q.z); }

Mat4f toMat4f(const Mat4& m) {
  Mat4f r;
  std::memcpy(r.data(), m.data(), sizeof(float) * 16);  // both column-major
  return r;
}

Mat4 toMat4(const Mat4f& m) {
  Mat4 r;
  std::memcpy(r.data(), m.data(), sizeof(float) * 16);
  return r;
}

ModelInfo describeModel(const swish::Model& m, const std::string& name) {
  ModelInfo info;
  info.name = name;
  for (const Joint& j : m.skeleton.joints) {
    info.jointNames.push_back(j.name);
    info.jointParents.push_back(j.parent);
    const Quatf& q = j.rest.rotation;
    info.restRotations.push_back({q.x(), q.y(), q.z(), q.w()});
    info.restTranslations.push_back({j.rest.translation.x(), j.rest.translation.y(), j.rest.translation.z()});
  }
  info.inputJoints = m.inputJoints;
  info.rootGravity = m.rootGravity;
  const Mesh& g = m.gameMesh;
  info.vertexCount = uint32_t(g.vertexCount());
  info.triangleCount = uint32_t(g.triangleCount());
  info.restPositions.assign(g.positions.data(), g.positions.data() + g.positions.size());
  info.triangleIndices.assign(g.triangles.data(), g.triangles.data() + g.triangles.size());
  if (size_t(g.uvs.rows()) == g.vertexCount()) info.uvs.assign(g.uvs.data(), g.uvs.data() + g.uvs.size());
  info.hasNormalMaps = !m.normalMaps.empty();
  info.normalMapWidth = m.normalMaps.width;
  info.normalMapHeight = m.normalMaps.height;
  info.normalMapDatabaseSize = m.normalMaps.mapCount();
  info.temporalFilterSeconds = m.temporalFilter.timeConstantSeconds;
  info.bodyAnchors = uint32_t(m.bodyAnchors.anchored());
  info.coveredBodyOf = m.bodyCoverage.bodyTriangles;
  info.coveredBodyTriangles = m.bodyCoverage.covered;
  info.hasNoveltyGuard = !m.noveltyGuard.empty();
  if (info.hasNoveltyGuard) {
    info.noveltyFlagAbove = m.noveltyGuard.flagAbove;
    info.noveltyBlendStart = m.noveltyGuard.blendStart;
    info.noveltyBlendEnd = m.noveltyGuard.blendEnd;
  }
  for (const runtime::QualityLevel& l : runtime::ladderOf(m).levels)
    info.qualityLevels.push_back({l.name, l.meshComponents, l.normalMaps, float(l.vertexMeanMm), float(l.vertexP95Mm),
                                  float(l.normalMeanDeg), float(l.cpuUsPerCharacter), float(l.gpuUsPerCharacter)});
  return info;
}

}  // namespace swish::api
