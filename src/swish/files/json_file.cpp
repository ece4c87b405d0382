#include "swish/files/json_file.hpp"

#include <fstream>

#include "swish/core/error.hpp"

namespace swish {

nlohmann::json readJsonFile(const std::filesystem::path& file, const std::string& what) {
  std::ifstream in(file);
  if (!in) throw Error(file.string() + ": cannot open the " + what);
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(file.string() + ": not valid JSON: " + e.what());
  }
}

}  // namespace swish
