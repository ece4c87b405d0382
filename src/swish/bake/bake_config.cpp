#include "swish/bake/bake_config.hpp"

#include <cctype>
#include <fstream>
#include <set>
#include <sstream>

#include "swish/core/error.hpp"

namespace swish::bake {

namespace {
struct Checker {
  std::string source;
  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw Error(source + ": " + key + ": " + problem);
  }
  void onlyKeys(const nlohmann::json& obj, const std::string& prefix, const std::set<std::string>& allowed) const {
    if (!obj.is_object()) fail(prefix.empty() ? "(top level)" : prefix, "must be a JSON object");
    for (auto it = obj.begin(); it != obj.end(); ++it)
      if (!allowed.count(it.key())) {
        std::string list;
        for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
        fail(prefix + (prefix.empty() ? "" : ".") + it.key(), "unknown key (known: " + list + ")");
      }
  }
  double number(const nlohmann::json& obj, const std::string& prefix, const std::string& key, double lo, double hi,
                double fallback, bool integer = false) const {
    if (!obj.contains(key)) return fallback;
    const auto& v = obj.at(key);
    const std::string name = prefix + "." + key;
    if (!v.is_number()) fail(name, "must be a number");
    const double d = v.get<double>();
    if (integer && (!v.is_number_integer() && d != double(int64_t(d)))) fail(name, "must be an integer");
    if (!(d >= lo && d <= hi)) {
      std::ostringstream s;
      s << d << " is outside " << lo << ".." << hi;
      fail(name, s.str());
    }
    return d;
  }
  std::string string(const nlohmann::json& obj, const std::string& key, const std::string& fallback) const {
    if (!obj.contains(key)) return fallback;
    if (!obj.at(key).is_string() || obj.at(key).get<std::string>().empty()) fail(key, "must be a non-empty string");
    return obj.at(key).get<std::string>();
  }
};
}  // namespace

BakeConfig parseBakeConfig(const nlohmann::json& json, const std::string& source, const std::filesystem::path& baseDir) {
  const Checker c{source};
  c.onlyKeys(json, "", {"name", "output", "dataset", "part1", "train"});
  BakeConfig cfg;
  cfg.name = c.string(json, "name", "model");
  for (char ch : cfg.name)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.'))
      c.fail("name", "'" + cfg.name + "' may only hold letters, digits, '_', '-' and '.' (it names files)");
  if (!json.contains("output")) c.fail("output", "is required (the folder for the model and the report)");
  cfg.output = baseDir / c.string(json, "output", "");
  cfg.dataset = json.contains("dataset") ? baseDir / c.string(json, "dataset", "") : cfg.output / "dataset";
  if (json.contains("part1")) {
    if (!json.at("part1").is_object()) c.fail("part1", "must be a JSON object");
    cfg.part1 = json.at("part1");
  }
  const nlohmann::json train = json.value("train", nlohmann::json::object());
  c.onlyKeys(train, "train",
             {"mesh_components", "mesh_variance", "normal_code_dims", "database_size", "codebook_size",
              "vq_training_blocks", "vq_iterations", "hidden_layers", "hidden_width", "activation", "learning_rate",
              "batch_size", "max_epochs", "patience", "validation_fraction", "max_training_seconds", "test_fraction",
              "temporal_time_constant", "seed", "bc5_baseline"});
  BakeTrainSettings& t = cfg.train;
  const std::string p = "train";
  t.meshComponents = int(c.number(train, p, "mesh_components", 1, 4096, t.meshComponents, true));
  t.meshVariance = c.number(train, p, "mesh_variance", 0, 1, t.meshVariance);
  t.normalCodeDims = int(c.number(train, p, "normal_code_dims", 0, 256, t.normalCodeDims, true));
  t.databaseSize = int(c.number(train, p, "database_size", 1, 65536, t.databaseSize, true));
  t.vq.codebookSize = uint32_t(c.number(train, p, "codebook_size", 1, 65536, t.vq.codebookSize, true));
  t.vq.trainingBlocks = uint32_t(c.number(train, p, "vq_training_blocks", 0, 1e8, t.vq.trainingBlocks, true));
  t.vq.iterations = int(c.number(train, p, "vq_iterations", 0, 1000, t.vq.iterations, true));
  t.mlp.hiddenLayers = int(c.number(train, p, "hidden_layers", 0, 64, t.mlp.hiddenLayers, true));
  t.mlp.hiddenWidth = int(c.number(train, p, "hidden_width", 1, 4096, t.mlp.hiddenWidth, true));
  if (train.contains("activation")) {
    if (!train.at("activation").is_string()) c.fail("train.activation", "must be a string");
    try {
      t.mlp.activation = activationFromName(train.at("activation").get<std::string>());
    } catch (const Error& e) {
      c.fail("train.activation", e.what());
    }
    if (t.mlp.activation != Activation::Selu)
      c.fail("train.activation", "the .swish runtime evaluates SELU only; other activations are for experiments "
                                 "with the trainer, not for baked models");
  }
  t.mlp.learningRate = c.number(train, p, "learning_rate", 1e-7, 1.0, t.mlp.learningRate);
  t.mlp.batchSize = int(c.number(train, p, "batch_size", 1, 1 << 20, t.mlp.batchSize, true));
  t.mlp.maxEpochs = int(c.number(train, p, "max_epochs", 1, 1e7, t.mlp.maxEpochs, true));
  t.mlp.patience = int(c.number(train, p, "patience", 1, 1e7, t.mlp.patience, true));
  t.mlp.validationFraction = c.number(train, p, "validation_fraction", 0.01, 0.5, t.mlp.validationFraction);
  t.mlp.maxSeconds = c.number(train, p, "max_training_seconds", 0, 1e6, t.mlp.maxSeconds);
  t.testFraction = c.number(train, p, "test_fraction", 0, 0.49, t.testFraction);
  t.temporalTimeConstant = float(c.number(train, p, "temporal_time_constant", 0, 10, t.temporalTimeConstant));
  t.seed = uint64_t(c.number(train, p, "seed", 0, 9.007199254740992e15, double(t.seed), true));
  if (train.contains("bc5_baseline")) {
    if (!train.at("bc5_baseline").is_boolean()) c.fail("train.bc5_baseline", "must be true or false");
    t.bc5Baseline = train.at("bc5_baseline").get<bool>();
  }
  return cfg;
}

BakeConfig loadBakeConfig(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot open the bake config");
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file.string() + ": not valid JSON: " + e.what());
  }
  return parseBakeConfig(j, file.string(), file.parent_path());
}

}  // namespace swish::bake
