#include "swish/bake/dataset/dataset_preview.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "swish/core/error.hpp"
#include "swish/core/mesh_frames.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/io/png.hpp"

namespace swish::bake {

PreviewImage renderShadedFrontView(const Mesh& g, const Points3f& pos, const NormalMapImage& map, uint32_t size) {
  if (pos.rows() != g.positions.rows() || g.uvs.rows() != g.positions.rows())
    throw Error("preview: positions or UVs do not match the garment");
  if (map.xy.size() != size_t(map.width) * map.height * 2 || map.width == 0)
    throw Error("preview: the normal map is empty or inconsistent");
  PreviewImage im;
  im.width = im.height = size;
  im.rgb.assign(size_t(size) * size * 3, 60);
  std::vector<float> depth(size_t(size) * size, -std::numeric_limits<float>::infinity());
  Points3f N;
  Points4f T;
  computeVertexFrames(pos, g.uvs, g.triangles, buildFrameTopology(g.triangles, g.positions), N, T);
  // Fit the mesh's x, y extent into the image with a margin.
  const Vec3f lo = pos.colwise().minCoeff().transpose(), hi = pos.colwise().maxCoeff().transpose();
  const float extent = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1e-6f});
  const float scale = 0.9f * float(size) / extent;
  const Vec2f centre(0.5f * (lo.x() + hi.x()), 0.5f * (lo.y() + hi.y()));
  auto toPixel = [&](const Vec3f& p) {
    return Vec2f(float(size) * 0.5f + (p.x() - centre.x()) * scale, float(size) * 0.5f - (p.y() - centre.y()) * scale);
  };
  const Vec3f light = Vec3f(0.3f, 0.5f, 1.f).normalized();
  for (Eigen::Index t = 0; t < g.triangles.rows(); ++t) {
    const uint32_t i[3] = {g.triangles(t, 0), g.triangles(t, 1), g.triangles(t, 2)};
    Vec2f s[3];
    for (int k = 0; k < 3; ++k) s[k] = toPixel(pos.row(i[k]).transpose());
    const float area = (s[1] - s[0]).x() * (s[2] - s[0]).y() - (s[2] - s[0]).x() * (s[1] - s[0]).y();
    if (std::abs(area) < 1e-12f) continue;
    const int x0 = std::max(0, int(std::floor(std::min({s[0].x(), s[1].x(), s[2].x()}))));
    const int x1 = std::min(int(size) - 1, int(std::ceil(std::max({s[0].x(), s[1].x(), s[2].x()}))));
    const int y0 = std::max(0, int(std::floor(std::min({s[0].y(), s[1].y(), s[2].y()}))));
    const int y1 = std::min(int(size) - 1, int(std::ceil(std::max({s[0].y(), s[1].y(), s[2].y()}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Vec2f p(float(x) + .5f, float(y) + .5f);
        const float b1 = ((p - s[0]).x() * (s[2] - s[0]).y() - (s[2] - s[0]).x() * (p - s[0]).y()) / area;
        const float b2 = ((s[1] - s[0]).x() * (p - s[0]).y() - (p - s[0]).x() * (s[1] - s[0]).y()) / area;
        const float b0 = 1.f - b1 - b2;
        if (b0 < 0.f || b1 < 0.f || b2 < 0.f) continue;
        const float w[3] = {b0, b1, b2};
        float z = 0.f;
        Vec3f n = Vec3f::Zero(), tan = Vec3f::Zero();
        Vec2f uv = Vec2f::Zero();
        float sign = 0.f;
        for (int k = 0; k < 3; ++k) {
          z += w[k] * pos(i[k], 2);
          n += w[k] * N.row(i[k]).transpose();
          tan += w[k] * T.row(i[k]).head<3>().transpose();
          sign += w[k] * T(i[k], 3);
          uv += w[k] * g.uvs.row(i[k]).transpose();
        }
        const size_t px = size_t(y) * size + size_t(x);
        if (z <= depth[px]) continue;
        depth[px] = z;
        n.normalize();
        tan = (tan - n * n.dot(tan)).normalized();
        const Vec3f bit = (sign < 0.f ? -1.f : 1.f) * n.cross(tan);
        const uint32_t tx = std::min(map.width - 1, uint32_t(std::clamp(uv.x(), 0.f, 1.f) * float(map.width)));
        const uint32_t ty = std::min(map.height - 1, uint32_t(std::clamp(uv.y(), 0.f, 1.f) * float(map.height)));
        const float X = map.xy[2 * (size_t(ty) * map.width + tx)], Y = map.xy[2 * (size_t(ty) * map.width + tx) + 1];
        const Vec3f shaded = (X * tan + Y * bit + std::sqrt(std::max(0.f, 1.f - X * X - Y * Y)) * n).normalized();
        const float lambert = 0.15f + 0.85f * std::max(0.f, shaded.dot(light));
        const float base[3] = {0.85f, 0.35f, 0.25f};  // jersey red
        for (int c = 0; c < 3; ++c) im.rgb[3 * px + c] = uint8_t(std::clamp(lambert * base[c] * 255.f, 0.f, 255.f));
      }
  }
  return im;
}

std::vector<std::filesystem::path> writeDatasetPreview(const Dataset& d, const std::filesystem::path& folder,
                                                       size_t maxPoses, uint32_t size) {
  std::error_code ec;
  std::filesystem::create_directories(folder, ec);
  if (ec) throw Error("preview " + folder.string() + ": cannot create the folder (" + ec.message() + ")");
  std::vector<std::filesystem::path> written;
  nlohmann::json summary = nlohmann::json::array();
  const size_t n = d.poses.size(), count = std::min(n, maxPoses);
  for (size_t k = 0; k < count; ++k) {
    const DatasetPose& p = d.poses[count > 1 ? k * (n - 1) / (count - 1) : 0];  // spread over the dataset
    char name[64];
    std::snprintf(name, sizeof name, "pose_%05u", p.id);
    const PreviewImage im = renderShadedFrontView(d.character.garment, p.gameMeshWorld, p.normalMap, size);
    io::PngImage png;
    png.width = im.width, png.height = im.height, png.channels = 3, png.bitDepth = 8;
    png.samples.assign(im.rgb.begin(), im.rgb.end());
    const auto front = folder / (std::string(name) + "_front.png");
    io::writePng(front, png);
    const auto nm = folder / (std::string(name) + "_normal_map.png");
    io::writePng(nm, io::encodeNormalMap(p.normalMap.width, p.normalMap.height, p.normalMap.xy, 8));
    written.push_back(front);
    written.push_back(nm);
    float maxTilt = 0.f;
    double meanTilt = 0.0;
    for (size_t t = 0; t < p.normalMap.xy.size() / 2; ++t) {
      const float s = std::hypot(p.normalMap.xy[2 * t], p.normalMap.xy[2 * t + 1]);
      maxTilt = std::max(maxTilt, s);
      meanTilt += s;
    }
    meanTilt /= double(std::max<size_t>(1, p.normalMap.xy.size() / 2));
    summary.push_back({{"id", p.id},
                       {"front", front.filename().string()},
                       {"normalMap", nm.filename().string()},
                       {"maxConstraintViolation", p.residuals.maxConstraintViolation},
                       {"maxPenetration", p.residuals.maxPenetration},
                       {"converged", p.residuals.converged},
                       {"iterations", p.residuals.iterations},
                       {"normalMapMeanTiltSin", meanTilt},
                       {"normalMapMaxTiltSin", maxTilt}});
  }
  const auto json = folder / "preview.json";
  writeTextFileAtomic(json, nlohmann::json{{"poses", summary}, {"datasetPoses", n}}.dump(2));
  written.push_back(json);
  // A re-bake previews other pose ids: the previous run's images must not linger beside these.
  constexpr std::string_view kSuffixes[] = {"_front.png", "_normal_map.png"};
  removeStaleOutputs(folder, "pose_", kSuffixes, written);
  return written;
}

}  // namespace swish::bake
