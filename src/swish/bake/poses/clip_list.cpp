#include "swish/bake/poses/clip_list.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "swish/core/error.hpp"
#include "swish/files/json_reader.hpp"

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
  fs::path baseDir;

  std::vector<fs::path> folderFiles(const fs::path& dir, const std::string& pattern, const JsonReader& at) const {
    std::error_code ec;
    if (!fs::is_directory(dir, ec)) at.fail("folder " + dir.string() + " does not exist");
    std::vector<fs::path> out;
    for (const auto& e : fs::directory_iterator(dir, ec)) {
      if (!e.is_regular_file()) continue;
      const std::string name = e.path().filename().string();
      if (pattern.empty() ? isAnimationFile(e.path()) : fnmatch(pattern.c_str(), name.c_str(), 0) == 0)
        out.push_back(e.path());
    }
    if (ec) at.fail("cannot list folder " + dir.string() + ": " + ec.message());
    std::sort(out.begin(), out.end());
    if (out.empty())
      at.fail(pattern.empty() ? "folder " + dir.string() + " holds no .bvh, .fbx, .glb or .gltf file"
                              : "no file in " + dir.string() + " matches '" + pattern + "'");
    return out;
  }

  std::vector<fs::path> globFiles(const std::string& glob, const JsonReader& at) const {
    const fs::path p = baseDir / glob;
    if (hasWildcard(p.parent_path().string())) at.fail("'" + glob + "': wildcards are allowed in the file name only");
    return folderFiles(p.parent_path(), p.filename().string(), at);
  }

  // An index file's rows: file (required), subject and frames (when the header names them).
  std::vector<ClipSource> indexFiles(const fs::path& index, const fs::path& clipFolder, const JsonReader& at) const {
    std::ifstream in(index);
    if (!in) at.fail("index file " + index.string() + " does not exist or cannot be read");
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
    const std::string file = index.string() + ":";
    while (std::getline(in, line)) {
      ++lineNo;
      if (line.empty() || line == "\r") continue;
      const auto cells = split(line);
      if (column.empty()) {
        for (size_t i = 0; i < cells.size(); ++i) column[cells[i]] = i;
        if (!column.count("file"))
          at.fail(file + std::to_string(lineNo) + ": the header row names no \"file\" column (tab-separated)");
        continue;
      }
      auto cell = [&](const char* name) -> std::string {
        auto it = column.find(name);
        return it == column.end() || it->second >= cells.size() ? std::string() : cells[it->second];
      };
      ClipSource c;
      const std::string name = cell("file");
      if (name.empty()) at.fail(file + std::to_string(lineNo) + ": no file name in the \"file\" column");
      c.file = clipFolder / name;
      if (!fs::is_regular_file(c.file))
        at.fail(file + std::to_string(lineNo) + ": clip file " + c.file.string() + " does not exist");
      c.subject = cell("subject").empty() ? subjectOfClipFile(c.file) : cell("subject");
      if (const std::string f = cell("frames"); !f.empty()) {
        char* end = nullptr;
        const unsigned long long n = std::strtoull(f.c_str(), &end, 10);
        if (end == f.c_str() || *end != '\0' || n == 0)
          at.fail(file + std::to_string(lineNo) + ": frames '" + f + "' is not a positive integer");
        c.expectedFrames = size_t(n);
      }
      out.push_back(std::move(c));
    }
    if (column.empty()) at.fail("index file " + index.string() + " is empty");
    if (out.empty()) at.fail("index file " + index.string() + " lists no clips");
    return out;
  }

  // "subjects" / "exclude_subjects" of an entry, normalised (empty when the key is missing).
  static std::set<std::string> subjectSet(const JsonReader& e, const char* key) {
    std::set<std::string> out;
    if (!e.has(key)) return out;
    const JsonReader list = e.child(key);
    if (!list.value().is_array() || list.value().empty()) list.fail("must be a non-empty array of subjects (strings)");
    for (size_t i = 0; i < list.value().size(); ++i) out.insert(normaliseSubject(list.at(i).nonEmptyString()));
    return out;
  }

  std::vector<ClipSource> entry(const JsonReader& e) const {
    const nlohmann::json& v = e.value();
    if (v.is_string()) {
      const std::string s = v.get<std::string>();
      if (s.empty()) e.fail("must be a non-empty string (a clip file, folder or glob)");
      if (hasWildcard(s)) return withSubjects(globFiles(s, e));
      const fs::path p = baseDir / s;
      if (fs::is_directory(p)) return withSubjects(folderFiles(p, "", e));
      if (!fs::is_regular_file(p)) e.fail("file " + p.string() + " does not exist");
      return withSubjects({p});
    }
    if (!v.is_object()) e.fail("must be a clip file, folder or glob (string) or an object");
    e.requireObject({"file", "glob", "folder", "index", "naming", "joint_map", "fps", "weight", "weights", "subject",
                     "subjects", "exclude_subjects"});
    // An index may name the folder its files are in ("folder"); otherwise they are beside it.
    const bool indexFolder = e.has("index") && e.has("folder");
    const int sources =
        int(e.has("file")) + int(e.has("glob")) + int(e.has("folder") && !indexFolder) + int(e.has("index"));
    if (sources != 1)
      e.fail(
          "give exactly one of \"file\", \"glob\", \"folder\" and \"index\" (an index may add "
          "\"folder\": where its files are)");

    std::vector<ClipSource> clips;
    if (e.has("file")) {
      const fs::path p = baseDir / e.child("file").nonEmptyString();
      if (!fs::is_regular_file(p)) e.child("file").fail("file " + p.string() + " does not exist");
      clips = withSubjects({p});
      if (e.has("subject")) clips[0].subject = e.child("subject").nonEmptyString();
      for (const char* k : {"subjects", "exclude_subjects"})
        if (e.has(k)) e.child(k).fail("applies to a glob, folder or index entry (use \"subject\" for a file)");
    } else {
      if (e.has("subject")) e.child("subject").fail("applies to a \"file\" entry only");
      if (e.has("glob")) clips = withSubjects(globFiles(e.child("glob").nonEmptyString(), e.child("glob")));
      if (e.has("folder") && !indexFolder)
        clips = withSubjects(folderFiles(baseDir / e.child("folder").nonEmptyString(), "", e.child("folder")));
      if (e.has("index")) {
        const fs::path index = baseDir / e.child("index").nonEmptyString();
        fs::path folder = index.parent_path();
        if (indexFolder) {
          folder = baseDir / e.child("folder").nonEmptyString();
          if (!fs::is_directory(folder)) e.child("folder").fail("folder " + folder.string() + " does not exist");
        }
        clips = indexFiles(index, folder, e.child("index"));
      }
    }

    const auto only = subjectSet(e, "subjects"), without = subjectSet(e, "exclude_subjects");
    for (const auto& s : only)
      if (without.count(s)) e.fail("subject '" + s + "' is both in \"subjects\" and in \"exclude_subjects\"");
    if (!only.empty() || !without.empty()) {
      std::set<std::string> seen;
      for (const auto& c : clips) seen.insert(normaliseSubject(c.subject));
      for (const auto& s : only)
        if (!seen.count(s)) e.child("subjects").fail("no clip of subject '" + s + "' in this entry");
      std::erase_if(clips, [&](const ClipSource& c) {
        const std::string s = normaliseSubject(c.subject);
        return (!only.empty() && !only.count(s)) || without.count(s);
      });
      if (clips.empty()) e.fail("no clip is left after the subject filter");
    }

    io::JointNaming naming = io::JointNaming::Auto;
    if (e.has("naming")) {
      const std::string n = e.child("naming").nonEmptyString();
      if (n == "auto")
        naming = io::JointNaming::Auto;
      else if (n == "same")
        naming = io::JointNaming::Same;
      else if (n == "mixamo")
        naming = io::JointNaming::Mixamo;
      else if (n == "unreal")
        naming = io::JointNaming::Unreal;
      else
        e.child("naming").fail("'" + n + "' is not one of auto, same, mixamo, unreal");
    }
    io::JointMapOptions map;
    if (e.has("joint_map")) {
      const JsonReader m = e.child("joint_map");
      if (m.value().is_string()) {
        const fs::path f = baseDir / m.nonEmptyString();
        if (!fs::is_regular_file(f)) m.fail("joint map file " + f.string() + " does not exist");
        try {
          map = io::readJointMapFile(f);
        } catch (const Error& err) {
          m.fail(err.what());
        }
      } else {
        map = io::parseJointMap(m);
      }
    }
    const double fps = e.number("fps", 0.0, 1000.0, 0.0);
    const double weight = e.number("weight", 0.01, 100.0, 1.0);
    std::map<std::string, double> bySubject, byClip;
    if (e.has("weights")) {
      const JsonReader w = e.child("weights");
      if (!w.value().is_object()) w.fail("must be an object {\"subject or clip\": weight}");
      std::set<std::string> stems, subjects;
      for (const auto& c : clips) {
        stems.insert(c.file.stem().string());
        subjects.insert(normaliseSubject(c.subject));
      }
      for (const auto& [key, value] : w.value().items()) {
        const double x = w.child(key).number(0.01, 100.0);
        if (stems.count(key))
          byClip[key] = x;
        else if (subjects.count(normaliseSubject(key)))
          bySubject[normaliseSubject(key)] = x;
        else
          w.child(key).fail("names neither a clip (file stem) nor a subject of this entry");
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

std::vector<ClipSource> parseClipList(const JsonReader& clips, const fs::path& baseDir) {
  const ClipListParser p{baseDir};
  if (!clips.value().is_array() || clips.value().empty())
    clips.fail("must be a non-empty array of clip files, folders, globs or clip objects");
  std::vector<ClipSource> out;
  std::map<fs::path, size_t> entryOf;
  for (size_t i = 0; i < clips.value().size(); ++i) {
    for (ClipSource& c : p.entry(clips.at(i))) {
      const fs::path canonical = fs::weakly_canonical(c.file);
      if (auto [it, fresh] = entryOf.emplace(canonical, i); !fresh)
        clips.at(i).fail("clip " + c.file.string() + " is listed again (first by " + clips.at(it->second).path() +
                         "); give it a weight instead");
      out.push_back(std::move(c));
    }
  }
  return out;
}

std::vector<ClipSource> parseClipList(const nlohmann::json& clips, const std::string& where, const fs::path& baseDir) {
  // "<source>: " names the document; anything else starts the path.
  const bool named = where.size() >= 2 && where.compare(where.size() - 2, 2, ": ") == 0;
  return parseClipList(named ? JsonReader(clips, where.substr(0, where.size() - 2), "part1.clips")
                             : JsonReader(clips, "", where + "part1.clips"),
                       baseDir);
}

}  // namespace swish::bake
