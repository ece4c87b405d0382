#include "swish/replay/gltf_frame_writer.hpp"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "swish/core/error.hpp"
#include "swish/files/atomic_write.hpp"
#include "swish/io/gltf_export.hpp"

namespace swish::replay {

void writeGltfFrame(const std::filesystem::path& file, const std::vector<GltfCharacterMesh>& chars) {
  // The exporter takes whole meshes: gather each character's frame data (positions, normals) and its
  // model's UVs and triangles into one.
  std::vector<Mesh> meshes(chars.size());
  io::GltfScene scene;
  scene.generator = "swish replay";
  for (size_t i = 0; i < chars.size(); ++i) {
    const GltfCharacterMesh& c = chars[i];
    if (!c.positions || !c.triangles) throw Error(file.string() + ": character '" + c.name + "' has no mesh");
    if (!c.positions->allFinite()) throw Error(file.string() + ": character '" + c.name + "' has non-finite positions");
    Mesh& m = meshes[i];
    m.positions = *c.positions;
    if (c.normals && c.normals->rows() == c.positions->rows()) m.normals = *c.normals;
    if (c.uvs && c.uvs->rows() == c.positions->rows()) m.uvs = *c.uvs;
    m.triangles = *c.triangles;
    io::GltfMeshEntry e;
    e.name = c.name;
    e.mesh = &m;
    e.skinned = false;
    const double half = c.placement.yawDegrees * M_PI / 360.0;
    e.transform.rotation = Quatf(float(std::cos(half)), 0.f, float(std::sin(half)), 0.f);
    e.preciseTranslation = c.placement.translation;
    scene.meshes.push_back(std::move(e));
  }
  std::string text;
  try {
    text = io::encodeGltf(scene);
  } catch (const Error& e) {
    throw Error(file.string() + ": " + e.what());
  }
  writeTextFileAtomic(file, text);
}

}  // namespace swish::replay
