#pragma once
// Reading a JSON file (scene files, pose streams, bake configs, character recipes) with errors that
// name the file: "<file>: cannot open the <what>" and "<file>: not valid JSON: <parser message>".
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace swish {

nlohmann::json readJsonFile(const std::filesystem::path& file, const std::string& what);

}  // namespace swish
