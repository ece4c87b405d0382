#include "swish/runtime/quality_levels.hpp"

#include <cmath>

#include "swish/core/error.hpp"

namespace swish::runtime {
namespace {

using nlohmann::json;

json numberOrNull(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

double numberOrNaN(const json& j, const char* key, const std::string& where) {
  if (!j.contains(key) || j.at(key).is_null()) return std::numeric_limits<double>::quiet_NaN();
  if (!j.at(key).is_number()) throw Error(where + "." + key + ": not a number");
  return j.at(key).get<double>();
}

// "full", "k64" (with the model's maps), "k32-flat" (without), "skinned" (the mean shape, no network).
std::string levelName(uint32_t k, bool withMaps, uint32_t fullK, bool modelHasMaps) {
  if (k == 0 && !withMaps) return "skinned";
  const std::string base = k == fullK ? "full" : "k" + std::to_string(k);
  return base + (modelHasMaps && !withMaps ? "-flat" : "");
}

}  // namespace

QualityLadder defaultLadder(const Model& model) {
  const uint32_t k = uint32_t(model.meshComponents());
  const bool maps = !model.normalMaps.empty();
  QualityLadder ladder;
  const auto add = [&](uint32_t components, bool withMaps) {
    for (const QualityLevel& l : ladder.levels)
      if (l.meshComponents == components && l.normalMaps == withMaps) return;
    if (!ladder.levels.empty()) {  // each level must be cheaper than the one before it
      const QualityLevel& prev = ladder.levels.back();
      if (components > prev.meshComponents || (withMaps && !prev.normalMaps)) return;
    }
    QualityLevel l;
    l.name = levelName(components, withMaps, k, maps);
    l.meshComponents = components;
    l.normalMaps = withMaps;
    ladder.levels.push_back(l);
  };
  add(k, maps);
  add(k / 2, maps);
  add(k / 4, false);
  add(k / 8, false);
  add(0, false);
  return ladder;
}

QualityLadder ladderOf(const Model& model) {
  json meta;
  try {
    meta = json::parse(model.metadata);
  } catch (const json::exception&) {
    return defaultLadder(model);
  }
  if (!meta.is_object() || !meta.contains(kQualityLevelsKey)) return defaultLadder(model);
  return ladderFromJson(meta.at(kQualityLevelsKey), model, "model metadata quality_levels");
}

QualityLadder ladderOf(const Model& model, bool normalMaps) {
  QualityLadder ladder = ladderOf(model);
  if (!normalMaps)
    for (QualityLevel& l : ladder.levels) l.normalMaps = false;
  return ladder;
}

json toJson(const QualityLadder& ladder) {
  json levels = json::array();
  for (const QualityLevel& l : ladder.levels)
    levels.push_back({{"name", l.name},
                      {"mesh_components", l.meshComponents},
                      {"normal_maps", l.normalMaps},
                      {"vertex_mean_mm", numberOrNull(l.vertexMeanMm)},
                      {"vertex_p95_mm", numberOrNull(l.vertexP95Mm)},
                      {"vertex_max_mm", numberOrNull(l.vertexMaxMm)},
                      {"normal_mean_deg", numberOrNull(l.normalMeanDeg)},
                      {"cpu_us_per_character", numberOrNull(l.cpuUsPerCharacter)},
                      {"gpu_us_per_character", numberOrNull(l.gpuUsPerCharacter)}});
  return {
      {"levels", levels}, {"measured_on", ladder.measuredOn}, {"poses", ladder.poses}, {"timed_on", ladder.timedOn}};
}

QualityLadder ladderFromJson(const json& j, const Model& model, const std::string& what) {
  if (!j.is_object() || !j.contains("levels") || !j.at("levels").is_array())
    throw Error(what + ": expected an object with a \"levels\" array");
  QualityLadder ladder;
  if (j.contains("measured_on") && j.at("measured_on").is_string()) ladder.measuredOn = j.at("measured_on");
  if (j.contains("timed_on") && j.at("timed_on").is_string()) ladder.timedOn = j.at("timed_on");
  if (j.contains("poses")) {
    if (!j.at("poses").is_number_unsigned()) throw Error(what + ".poses: not a count");
    ladder.poses = j.at("poses").get<uint32_t>();
  }
  const uint32_t fullK = uint32_t(model.meshComponents());
  const auto& levels = j.at("levels");
  if (levels.empty()) throw Error(what + ".levels: empty (a ladder has at least its full level)");
  for (size_t i = 0; i < levels.size(); ++i) {
    const std::string where = what + ".levels[" + std::to_string(i) + "]";
    const json& e = levels[i];
    if (!e.is_object()) throw Error(where + ": not an object");
    QualityLevel l;
    if (!e.contains("name") || !e.at("name").is_string() || e.at("name").get<std::string>().empty())
      throw Error(where + ".name: missing or not a name");
    l.name = e.at("name");
    if (!e.contains("mesh_components") || !e.at("mesh_components").is_number_unsigned())
      throw Error(where + ".mesh_components: missing or not a count");
    l.meshComponents = e.at("mesh_components").get<uint32_t>();
    if (l.meshComponents > fullK)
      throw Error(where + ".mesh_components: " + std::to_string(l.meshComponents) + " is more than the model's " +
                  std::to_string(fullK));
    if (!e.contains("normal_maps") || !e.at("normal_maps").is_boolean())
      throw Error(where + ".normal_maps: missing or not true/false");
    l.normalMaps = e.at("normal_maps");
    if (l.normalMaps && model.normalMaps.empty())
      throw Error(where + ": asks for normal maps, but the model has no normal-map database");
    l.vertexMeanMm = numberOrNaN(e, "vertex_mean_mm", where);
    l.vertexP95Mm = numberOrNaN(e, "vertex_p95_mm", where);
    l.vertexMaxMm = numberOrNaN(e, "vertex_max_mm", where);
    l.normalMeanDeg = numberOrNaN(e, "normal_mean_deg", where);
    l.cpuUsPerCharacter = numberOrNaN(e, "cpu_us_per_character", where);
    l.gpuUsPerCharacter = numberOrNaN(e, "gpu_us_per_character", where);
    if (!ladder.levels.empty()) {
      const QualityLevel& prev = ladder.levels.back();
      if (l.meshComponents > prev.meshComponents || (l.normalMaps && !prev.normalMaps))
        throw Error(where + " (" + l.name + "): costs more than the level before it (" + prev.name +
                    "); levels go from full quality to the cheapest");
    }
    ladder.levels.push_back(std::move(l));
  }
  return ladder;
}

void storeLadder(Model& model, const QualityLadder& ladder) {
  json meta;
  try {
    meta = json::parse(model.metadata);
  } catch (const json::exception&) {
    meta = json::object();
  }
  if (!meta.is_object()) meta = json::object();
  meta[kQualityLevelsKey] = toJson(ladder);
  model.metadata = meta.dump(2);
}

}  // namespace swish::runtime
