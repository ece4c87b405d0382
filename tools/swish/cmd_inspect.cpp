// swish inspect MODEL [--json]: what a .swish model holds, without running it. The file is fully
// loaded and validated first, so a model that inspects cleanly is one the runtime accepts; a bad file
// prints the loader's error (file, section, problem) and exits with code 1.
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>

#include "swish/command.hpp"
#include "swish/model/model_file.hpp"
#include "swish/runtime/quality_levels.hpp"

namespace swish::cli {

namespace {

struct InspectOptions {
  std::string path;
  bool json = false;
};

// Joints that carry a positive skin weight somewhere: what the skinning pass will actually read.
size_t skinnedJointCount(const Mesh& mesh) {
  std::set<uint16_t> used;
  for (size_t i = 0; i < mesh.skin.weights.size(); ++i)
    if (mesh.skin.weights[i] > 0.f) used.insert(mesh.skin.joints[i]);
  return used.size();
}

size_t mlpParameters(const Mlp& mlp) {
  size_t n = 0;
  for (const auto& l : mlp.layers) n += size_t(l.weight.size() + l.bias.size());
  return n;
}

std::string mlpShape(const Mlp& mlp) {
  std::string s = std::to_string(mlp.inputSize());
  for (const auto& l : mlp.layers) s += " -> " + std::to_string(l.weight.rows());
  return s;
}

nlohmann::json describe(const Model& m, const ModelFileInfo& info, uint64_t fileBytes) {
  using nlohmann::json;
  json j;
  j["file"] = {{"bytes", fileBytes},
               {"formatVersion", std::to_string(info.majorVersion) + "." + std::to_string(info.minorVersion)}};
  json sections = json::array();
  for (const auto& s : info.sections)
    sections.push_back({{"tag", s.tag}, {"payloadBytes", s.payloadBytes}, {"offset", s.offset}, {"known", s.known}});
  j["file"]["sections"] = sections;

  json inputs = json::array();
  for (uint32_t idx : m.inputJoints) inputs.push_back({{"index", idx}, {"name", m.skeleton.joints[idx].name}});
  j["skeleton"] = {{"joints", m.skeleton.size()},
                   {"inputJoints", inputs},
                   {"rootGravity", m.rootGravity},
                   {"jointsWithSkinWeight", skinnedJointCount(m.gameMesh)}};

  json layers = json::array();
  for (const auto& l : m.mlp.layers) layers.push_back({{"in", l.weight.cols()}, {"out", l.weight.rows()}});
  j["mlp"] = {{"thetaSize", m.thetaSize()},
              {"lambdaSize", m.lambdaSize()},
              {"layers", layers},
              {"activation", "SELU after every layer but the last"},
              {"parameters", mlpParameters(m.mlp)}};

  j["meshPca"] = {{"components", m.meshComponents()}};
  const Mesh& g = m.gameMesh;
  j["gameMesh"] = {{"vertices", g.vertexCount()},
                   {"triangles", g.triangleCount()},
                   {"influencesPerVertex", g.skin.influences},
                   {"hasNormals", g.normals.rows() > 0},
                   {"hasTangents", g.tangents.rows() > 0},
                   {"hasUvs", g.uvs.rows() > 0}};

  const auto& db = m.normalMaps;
  if (db.empty()) {
    j["normalMaps"] = nullptr;
  } else {
    j["normalMaps"] = {{"maps", db.mapCount()},
                       {"width", db.width},
                       {"height", db.height},
                       {"codeDims", db.codeDims()},
                       {"codebookEntries", db.codebookSize},
                       {"codebookBytes", db.codebook.size()},
                       {"blockIndices", db.indices.size()}};
  }
  j["temporalFilter"] = {{"timeConstantSeconds", m.temporalFilter.timeConstantSeconds}};
  j["qualityLevels"] = swish::runtime::toJson(swish::runtime::ladderOf(m));
  j["bodyAnchors"] = {{"anchored", m.bodyAnchors.anchored()},
                      {"secondAnchored", m.bodyAnchors.anchored(1)},
                      {"thirdAnchored", m.bodyAnchors.anchored(2)},
                      {"vertices", m.bodyAnchors.anchors.size()},
                      {"marginM", m.bodyAnchors.margin}};
  // Metadata is meant to be JSON; show it as such when it is, as text when it is not.
  const json meta = json::parse(m.metadata, nullptr, /*allow_exceptions=*/false);
  if (meta.is_discarded())
    j["metadataText"] = m.metadata;
  else
    j["metadata"] = meta;
  return j;
}

void printText(const std::string& path, const Model& m, const ModelFileInfo& info, uint64_t fileBytes) {
  std::ostringstream o;
  o << path << ": .swish format " << info.majorVersion << "." << info.minorVersion << ", " << fileBytes << " bytes\n";
  o << "  skeleton      " << m.skeleton.size() << " joints, " << skinnedJointCount(m.gameMesh)
    << " carry skin weight\n";
  o << "  input joints  " << m.inputJoints.size() << " (Theta = " << m.thetaSize() << " values):";
  for (uint32_t idx : m.inputJoints) o << " " << m.skeleton.joints[idx].name;
  if (m.rootGravity) o << ", then gravity in the root joint's frame (3)";
  o << "\n";
  o << "  mlp           " << mlpShape(m.mlp) << " (SELU; " << m.mlp.layers.size() << " layers, " << mlpParameters(m.mlp)
    << " parameters)\n";
  o << "  lambda        " << m.lambdaSize() << " = K " << m.meshComponents() << " mesh weights + " << m.normalCodeDims()
    << " normal-code dimensions\n";
  const Mesh& g = m.gameMesh;
  o << "  game mesh     " << g.vertexCount() << " vertices, " << g.triangleCount() << " triangles, "
    << g.skin.influences << " influences per vertex" << (g.uvs.rows() ? ", UVs" : "")
    << (g.normals.rows() ? ", rest normals" : "") << (g.tangents.rows() ? ", rest tangents" : "") << "\n";
  const auto& db = m.normalMaps;
  if (db.empty()) {
    o << "  normal maps   none\n";
  } else {
    o << "  normal maps   " << db.mapCount() << " maps of " << db.width << "x" << db.height << ", code of "
      << db.codeDims() << " dims, codebook " << db.codebookSize << " entries (" << db.codebook.size() << " bytes), "
      << db.indices.size() << " block indices\n";
  }
  o << "  temporal      time constant " << m.temporalFilter.timeConstantSeconds << " s\n";
  {
    const swish::runtime::QualityLadder ladder = swish::runtime::ladderOf(m);
    o << "  levels        " << ladder.size() << " quality levels"
      << (ladder.measured() ? " measured on " + ladder.measuredOn : std::string(" (not measured: the default ladder)"))
      << "\n";
    for (size_t l = 0; l < ladder.size(); ++l) {
      char line[200];
      std::snprintf(line, sizeof line, "    %zu %-10s k %3u%s  vertex mean %.2f mm, p95 %.2f mm; CPU %.1f us\n", l,
                    ladder[l].name.c_str(), ladder[l].meshComponents, ladder[l].normalMaps ? " + maps" : "        ",
                    ladder[l].vertexMeanMm, ladder[l].vertexP95Mm, ladder[l].cpuUsPerCharacter);
      o << line;
    }
  }
  if (m.bodyAnchors.empty()) {
    o << "  body anchors  none (no push-out at run time; swish body-proxy fits them)\n";
  } else {
    char line[240];
    std::snprintf(line, sizeof line,
                  "  body anchors  %zu of %zu vertices (%zu with a second one, %zu with a third), margin %.1f mm (the "
                  "run-time push-out keeps them off the body)\n",
                  m.bodyAnchors.anchored(), m.bodyAnchors.anchors.size(), m.bodyAnchors.anchored(1),
                  m.bodyAnchors.anchored(2), 1000.0 * double(m.bodyAnchors.margin));
    o << line;
  }
  o << "  sections\n";
  for (const auto& s : info.sections) {
    char line[128];
    std::snprintf(line, sizeof line, "    '%s' %12llu bytes%s\n", s.tag.c_str(),
                  static_cast<unsigned long long>(s.payloadBytes), s.known ? "" : "  (newer minor version, skipped)");
    o << line;
  }
  const auto meta = nlohmann::json::parse(m.metadata, nullptr, false);
  std::string metaText = meta.is_discarded() ? m.metadata : meta.dump(2);
  // Indent continuation lines under the first so the block reads as one field.
  for (size_t at = metaText.find('\n'); at != std::string::npos; at = metaText.find('\n', at + 1))
    metaText.insert(at + 1, "                ");
  o << "  metadata      " << metaText << "\n";
  std::cout << o.str();
}

RunFn setup(CLI::App& app) {
  auto opt = std::make_shared<InspectOptions>();
  app.add_option("model", opt->path, "The .swish model file")->required();
  app.add_flag("--json", opt->json, "Print a JSON object instead of text");
  return [opt]() {
    const std::vector<uint8_t> bytes = readFileBytes(opt->path);
    const Model model = deserializeModel(bytes, opt->path);  // full load: checks everything
    const ModelFileInfo info = readModelFileInfo(bytes, opt->path);
    if (opt->json)
      std::cout << describe(model, info, bytes.size()).dump(2) << "\n";
    else
      printText(opt->path, model, info, bytes.size());
    return 0;
  };
}

CommandRegistration registration{"inspect", "Summarise a .swish model: joints, MLP, mesh, normal maps, sections",
                                 setup};

}  // namespace

}  // namespace swish::cli
