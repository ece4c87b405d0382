#include "swish/bake/poses/clip_list.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "swish/core/error.hpp"

namespace swish::bake {

namespace fs = std::filesystem;

namespace {

bool isAnimationFile(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".bvh" || ext == ".fbx" || ext == ".glb" || ext == ".gltf";
}

bool hasWildcard(const std::string& s) { return s.find_first_of("*?[") != std::string::npos; }

struct ClipListParser {
  std::string where;
  fs::path baseDir;

  [[noreturn]] void fail(const std::string& key, const std::string& problem) const {
    throw Error(where + key + ": " + problem);
  }

  std::string text(const nlohmann::json& v, const std::string& key) const {
    if (!v.is_string() || v.get<std::string>().empty()) fail(key, "must be a non-empty string");
    return v.get<std::string>();
  }

  std::vector<fs::path> folderFiles(const fs::path& dir, const std::string& pattern, const std::string& key) const {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) fail(key, "folder " + dir.string() + " does not exist");
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      if (!e.is_regular_file()) continue;
      const std::string name = e.path().filename().string();
      if (pattern.empty() ? isAnimationFile(e.path()) : fnmatch(pattern.c_str(), name.c_str(), 0) == 0)
        out.push_back(e.path());
    }
    if (ec) fail(key, "cannot list folder " + dir.string() + ": " + ec.message());
    std::sort(out.begin(), out.end());
    if (out.empty())
      fail(key, pattern.empty() ? "folder " + dir.string() + " holds no .bvh, .fbx, .glb or .gltf file"
                                : "no file in " + dir.string() + " matches '" + pattern + "'");
    return out;
  }

  std::vector<fs::path> globFiles(const std::string& glob, const std::string& key) const {
    const fs::path p = baseDir / glob;
    if (hasWildcard(p.parent_path().string())) fail(key, "'" + glob + "': wildcards are allowed in the file name only");
    return folderFiles(p.parent_path(), p.filename().string(), key);
  }

  // An index file's rows: file (required), subject and frames (when the header names them).
  std::vector<ClipSource> indexFiles(const fs::path& index, const fs::path& clipFolder, const std::string& key) const {
    std::ifstream in(index);
    if (!in) fail(key, "index file " + index.string() + " does not exist or cannot be read");
    std::string line;
    std::map<std::string, size_t> column;
    std::vector<ClipSource> out;
    size_t lineNo = 0;
    auto split = [](std::string s) {
      if (!s.empty() && s.back() == '\r') s.pop_back();
      std::vector<std::string> cells;
      std::stringstream ss(s);
      std::string cell;
      while (std::getline(ss, cell, '\t')) cells.push_back(cell);
      return cells;
    };
    const std::string at = index.string() + ":";
    while (std::getline(in, line)) {
      ++lineNo;
      if (line.empty() || line == "\r") continue;
      const auto cells = split(line);
      if (column.empty()) {
        for (size_t i = 0; i < cells.size(); ++i) column[cells[i]] = i;
        if (!column.count("file"))
          fail(key, at + std::to_string(lineNo) + ": the header row names no \"file\" column (tab-separated)");
        continue;
      }
      auto cell = [&](const char* name) -> std::string {
        auto it = column.find(name);
        return it == column.end() || it->second >= cells.size() ? std::string() : cells[it->second];
      };
      ClipSource c;
      const std::string file = cell("file");
      if (file.empty()) fail(key, at + std::to_string(lineNo) + ": no file name in the \"file\" column");
      c.file = clipFolder / file;
      if (!fs::is_regular_file(c.file))
        fail(key, at + std::to_string(lineNo) + ": clip file " + c.file.string() + " does not exist");
      c.subject = cell("subject").empty() ? subjectOfClipFile(c.file) : cell("subject");
      if (const std::string f = cell("frames"); !f.empty()) {
        char* end = nullptr;
        const unsigned long long n = std::strtoull(f.c_str(), &end, 10);
        if (end == f.c_str() || *end != '\0' || n == 0)
          fail(key, at + std::to_string(lineNo) + ": frames '" + f + "' is not a positive integer");
        c.expectedFrames = size_t(n);
      }
      out.push_back(std::move(c));
    }
    if (column.empty()) fail(key, "index file " + index.string() + " is empty");
    if (out.empty()) fail(key, "index file " + index.string() + " lists no clips");
    return out;
  }

  std::set<std::string> subjectSet(const nlohmann::json& obj, const std::string& key, const std::string& prefix) const {
    std::set<std::string> out;
    if (!obj.contains(key)) return out;
    const auto& v = obj.at(key);
    if (!v.is_array() || v.empty()) fail(prefix + "." + key, "must be a non-empty array of subjects (strings)");
    for (const auto& s : v) out.insert(normaliseSubject(text(s, prefix + "." + key)));
    return out;
  }

  double weightValue(const nlohmann::json& v, const std::string& key) const {
    if (!v.is_number() || !(v.get<double>() >= 0.01 && v.get<double>() <= 100.0))
      fail(key, "must be a number in 0.01..100");
    return v.get<double>();
  }

  std::vector<ClipSource> entry(const nlohmann::json& v, const std::string& q) const {
    if (v.is_string()) {
      const std::string s = v.get<std::string>();
      if (s.empty()) fail(q, "must be a non-empty string (a clip file, folder or glob)");
      if (hasWildcard(s)) return withSubjects(globFiles(s, q));
      const fs::path p = baseDir / s;
      if (fs::is_directory(p)) return withSubjects(folderFiles(p, "", q));
      if (!fs::is_regular_file(p)) fail(q, "file " + p.string() + " does not exist");
      return withSubjects({p});
    }
    static const std::set<std::string> known = {"file", "glob",   "folder",  "index",   "naming",   "joint_map",
                                                "fps",  "weight", "weights", "subject", "subjects", "exclude_subjects"};
    if (!v.is_object()) fail(q, "must be a clip file, folder or glob (string) or an object");
    for (auto it = v.begin(); it != v.end(); ++it)
      if (!known.count(it.key())) {
        std::string list;
        for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
        fail(q + "." + it.key(), "unknown key (known: " + list + ")");
      }
    // An index may name the folder its files are in ("folder"); otherwise they are beside it.
    const bool indexFolder = v.contains("index") && v.contains("folder");
    const int sources = int(v.contains("file")) + int(v.contains("glob")) + int(v.contains("folder") && !indexFolder) +
                        int(v.contains("index"));
    if (sources != 1)
      fail(q,
           "give exactly one of \"file\", \"glob\", \"folder\" and \"index\" (an index may add "
           "\"folder\": where its files are)");

    std::vector<ClipSource> clips;
    if (v.contains("file")) {
      const fs::path p = baseDir / text(v.at("file"), q + ".file");
      if (!fs::is_regular_file(p)) fail(q + ".file", "file " + p.string() + " does not exist");
      clips = withSubjects({p});
      if (v.contains("subject")) clips[0].subject = text(v.at("subject"), q + ".subject");
      for (const char* k : {"subjects", "exclude_subjects"})
        if (v.contains(k)) fail(q + "." + k, "applies to a glob, folder or index entry (use \"subject\" for a file)");
    } else {
      if (v.contains("subject")) fail(q + ".subject", "applies to a \"file\" entry only");
      if (v.contains("glob")) clips = withSubjects(globFiles(text(v.at("glob"), q + ".glob"), q + ".glob"));
      if (v.contains("folder") && !indexFolder)
        clips = withSubjects(folderFiles(baseDir / text(v.at("folder"), q + ".folder"), "", q + ".folder"));
      if (v.contains("index")) {
        const fs::path index = baseDir / text(v.at("index"), q + ".index");
        fs::path folder = index.parent_path();
        if (indexFolder) {
          folder = baseDir / text(v.at("folder"), q + ".folder");
          if (!fs::is_directory(folder)) fail(q + ".folder", "folder " + folder.string() + " does not exist");
        }
        clips = indexFiles(index, folder, q + ".index");
      }
    }

    const auto only = subjectSet(v, "subjects", q), without = subjectSet(v, "exclude_subjects", q);
    for (const auto& s : only)
      if (without.count(s)) fail(q, "subject '" + s + "' is both in \"subjects\" and in \"exclude_subjects\"");
    if (!only.empty() || !without.empty()) {
      std::set<std::string> seen;
      for (const auto& c : clips) seen.insert(normaliseSubject(c.subject));
      for (const auto& s : only)
        if (!seen.count(s)) fail(q + ".subjects", "no clip of subject '" + s + "' in this entry");
      std::erase_if(clips, [&](const ClipSource& c) {
        const std::string s = normaliseSubject(c.subject);
        return (!only.empty() && !only.count(s)) || without.count(s);
      });
      if (clips.empty()) fail(q, "no clip is left after the subject filter");
    }

    io::JointNaming naming = io::JointNaming::Auto;
    if (v.contains("naming")) {
      const std::string n = text(v.at("naming"), q + ".naming");
      if (n == "auto")
        naming = io::JointNaming::Auto;
      else if (n == "same")
        naming = io::JointNaming::Same;
      else if (n == "mixamo")
        naming = io::JointNaming::Mixamo;
      else if (n == "unreal")
        naming = io::JointNaming::Unreal;
      else
        fail(q + ".naming", "'" + n + "' is not one of auto, same, mixamo, unreal");
    }
    io::JointMapOptions map;
    if (v.contains("joint_map")) {
      const auto& m = v.at("joint_map");
      if (m.is_string()) {
        const fs::path f = baseDir / text(m, q + ".joint_map");
        if (!fs::is_regular_file(f)) fail(q + ".joint_map", "joint map file " + f.string() + " does not exist");
        try {
          map = io::readJointMapFile(f);
        } catch (const Error& e) {
          fail(q + ".joint_map", e.what());
        }
      } else {
        map = io::parseJointMap(m, where + q + ".joint_map");
      }
    }
    const double fps = v.contains("fps") ? v.at("fps").is_number() ? v.at("fps").get<double>() : -1.0 : 0.0;
    if (!(fps >= 0.0 && fps <= 1000.0)) fail(q + ".fps", "must be a number in 0..1000");
    const double weight = v.contains("weight") ? weightValue(v.at("weight"), q + ".weight") : 1.0;
    std::map<std::string, double> bySubject, byClip;
    if (v.contains("weights")) {
      const auto& w = v.at("weights");
      if (!w.is_object()) fail(q + ".weights", "must be an object {\"subject or clip\": weight}");
      std::set<std::string> stems, subjects;
      for (const auto& c : clips) {
        stems.insert(c.file.stem().string());
        subjects.insert(normaliseSubject(c.subject));
      }
      for (auto it = w.begin(); it != w.end(); ++it) {
        const double x = weightValue(it.value(), q + ".weights." + it.key());
        if (stems.count(it.key()))
          byClip[it.key()] = x;
        else if (subjects.count(normaliseSubject(it.key())))
          bySubject[normaliseSubject(it.key())] = x;
        else
          fail(q + ".weights." + it.key(), "names neither a clip (file stem) nor a subject of this entry");
      }
    }
    for (ClipSource& c : clips) {
      c.naming = naming;
      c.jointMap = map.explicitPairs;
      c.jointChains = map.chains;
      c.framesPerSecond = fps;
      c.weight = weight;
      if (auto it = byClip.find(c.file.stem().string()); it != byClip.end())
        c.weight *= it->second;
      else if (auto s = bySubject.find(normaliseSubject(c.subject)); s != bySubject.end())
        c.weight *= s->second;
    }
    return clips;
  }

  static std::vector<ClipSource> withSubjects(const std::vector<fs::path>& files) {
    std::vector<ClipSource> out;
    for (const auto& f : files) {
      ClipSource c;
      c.file = f;
      c.subject = subjectOfClipFile(f);
      out.push_back(std::move(c));
    }
    return out;
  }
};

}  // namespace

std::string subjectOfClipFile(const fs::path& file) {
  const std::string stem = file.stem().string();
  return stem.substr(0, stem.find('_'));
}

std::string normaliseSubject(const std::string& s) {
  if (s.empty() || !std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); })) return s;
  const size_t first = s.find_first_not_of('0');
  return first == std::string::npos ? "0" : s.substr(first);
}

std::vector<ClipSource> parseClipList(const nlohmann::json& clips, const std::string& where, const fs::path& baseDir) {
  const ClipListParser p{where, baseDir};
  const std::string key = "part1.clips";
  if (!clips.is_array() || clips.empty())
    p.fail(key, "must be a non-empty array of clip files, folders, globs or clip objects");
  std::vector<ClipSource> out;
  std::map<fs::path, size_t> entryOf;
  for (size_t i = 0; i < clips.size(); ++i) {
    const std::string q = key + "[" + std::to_string(i) + "]";
    for (ClipSource& c : p.entry(clips[i], q)) {
      const fs::path canonical = fs::weakly_canonical(c.file);
      if (auto [it, fresh] = entryOf.emplace(canonical, i); !fresh)
        p.fail(q, "clip " + c.file.string() + " is listed again (first by part1.clips[" + std::to_string(it->second) +
                      "]); give it a weight instead");
      out.push_back(std::move(c));
    }
  }
  return out;
}

}  // namespace swish::bake
