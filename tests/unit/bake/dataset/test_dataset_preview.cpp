// Preview pictures: the front view shows the mesh, shaded by the normal map; files are written.
#include <gtest/gtest.h>

#include <filesystem>

#include "support/temp_dir.hpp"
#include "swish/bake/dataset/dataset_preview.hpp"
#include "swish/io/png.hpp"

using namespace swish;
using namespace swish::bake;

namespace {
Mesh quad() {
  Mesh m;
  m.positions.resize(4, 3);
  m.positions << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0;
  m.uvs.resize(4, 2);
  m.uvs << 0, 0, 1, 0, 1, 1, 0, 1;
  m.triangles.resize(2, 3);
  m.triangles << 0, 1, 2, 0, 2, 3;
  return m;
}
NormalMapImage constantMap(float x, float y) {
  NormalMapImage n;
  n.width = n.height = 8;
  n.xy.resize(128);
  for (size_t t = 0; t < 64; ++t) n.xy[2 * t] = x, n.xy[2 * t + 1] = y;
  return n;
}
}  // namespace

TEST(DatasetPreview, NormalMapChangesTheShadingOfTheMesh) {
  const Mesh m = quad();
  const PreviewImage flat = renderShadedFrontView(m, m.positions, constantMap(0, 0), 64);
  const PreviewImage tilted = renderShadedFrontView(m, m.positions, constantMap(0.6f, 0), 64);
  ASSERT_EQ(flat.rgb.size(), 64u * 64u * 3u);
  const size_t centre = 3 * (32 * 64 + 32), corner = 0;
  EXPECT_EQ(flat.rgb[corner], 60);                            // background outside the mesh (margin)
  EXPECT_GT(flat.rgb[centre], 100);                           // lit front face
  EXPECT_NE(flat.rgb[centre], tilted.rgb[centre]);            // the normal map shows
  EXPECT_EQ(flat.rgb[centre], flat.rgb[3 * (20 * 64 + 40)]);  // a flat map shades a flat quad evenly
}

TEST(DatasetPreview, WritesPicturesAndSummary) {
  Dataset d;
  d.character.garment = quad();
  for (uint32_t id : {2u, 5u, 9u}) {
    DatasetPose p;
    p.id = id;
    p.gameMeshWorld = d.character.garment.positions;
    p.normalMap = constantMap(0.1f * float(id) / 9.f, 0);
    p.residuals.converged = true;
    d.poses.push_back(p);
  }
  const test::TempDir tmp("test_preview");
  const auto dir = tmp / "preview";  // not there yet: writeDatasetPreview makes it
  const auto files = writeDatasetPreview(d, dir, 2, 32);
  ASSERT_EQ(files.size(), 5u);  // 2 poses x 2 pictures + preview.json
  EXPECT_EQ(files[0].filename(), "pose_00002_front.png");
  EXPECT_EQ(files[2].filename(), "pose_00009_front.png");  // spread: first and last
  const io::PngImage im = io::readPng(files[0]);
  EXPECT_EQ(im.width, 32u);
  EXPECT_TRUE(std::filesystem::exists(dir / "preview.json"));
}
