#pragma once
// A bake recipe's clip list (part1.clips), expanded into one ClipSource per clip file. Entries:
//
//   "a.bvh"                                   one file
//   "../shared/mocap/cmu/*.bvh"               a glob (wildcards * ? [..] in the file name only), sorted
//   "../shared/mocap/cmu"                     a folder: every .bvh .fbx .glb .gltf in it, sorted
//   {"file": "b.fbx", ...}                    one file with options (below)
//   {"glob": "dir/*.bvh", ...} / {"folder": "dir", ...}
//   {"index": "../shared/mocap/cmu-daz/index.tsv", ...}   (with "folder": "dir", the index's files are
//                                             in dir, e.g. {"index": "mocap/index.tsv", "folder": "mocap/cmu"})
//                                             a tab-separated index with a header row naming its columns:
//                                             "file" (relative to the index's folder or "folder") is required;
//                                             "subject" and "frames" are read when present (the frame
//                                             count is checked against the file when the clip is read)
//
// Options of an object entry (every key optional except the one that names the clips):
//   "naming": "auto|same|mixamo|unreal"       joint-name convention (io/joint_map.hpp)
//   "joint_map": {..} | "map.json"            pairs and chains inline, or a joint map file
//   "fps": 0                                  resampling rate of key-framed formats
//   "weight": 1                               sampling density of these clips (0.01..100): 2 samples a
//                                             clip twice as densely as weight 1 (pose_sampling.hpp)
//   "weights": {"13": 0.5, "13_01": 2}        per subject or per clip (file stem), times "weight"
//   "subject": "13"                           the subject of a "file" entry (default: the file stem up
//                                             to its first '_', as in CMU's SS_TT names)
//   "subjects": ["10", "13"]                  glob/folder/index: only these subjects' clips
//   "exclude_subjects": ["14"]                glob/folder/index: all but these
//
// Subjects compare as written, with leading zeros of numbers ignored ("01" is "1"). A file listed by
// two entries is an error naming both (give it a weight instead). Errors name the config, the entry
// (part1.clips[3].index) and the file, before any clip is read: "<config>: <json.path>: <problem>"
// (files/json_reader.hpp), e.g. "bake.json: part1.clips[3].weights.13_01: 0 is outside 0.01..100".
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "swish/bake/pipeline/part1_dataset.hpp"

namespace swish {
class JsonReader;
}

namespace swish::bake {

// The clip list at `clips`'s node (a bake config's part1.clips, whose path its errors show); paths
// resolve against baseDir.
std::vector<ClipSource> parseClipList(const JsonReader& clips, const std::filesystem::path& baseDir);
// The same for a list read as "part1.clips" of the document `where` names: `where` is "<document>: " (or
// empty) and starts every error ("recipe.json: part1.clips[0].fps: ...").
std::vector<ClipSource> parseClipList(const nlohmann::json& clips, const std::string& where,
                                      const std::filesystem::path& baseDir);

// The subject a clip file's name implies: its stem up to the first '_' ("13_01.bvh" -> "13").
std::string subjectOfClipFile(const std::filesystem::path& file);
// "013" -> "13", "0" -> "0", "S1" -> "S1": the form subjects are compared in.
std::string normaliseSubject(const std::string& subject);

}  // namespace swish::bake
