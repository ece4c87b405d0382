#pragma once
// Writing files so that a reader never sees half of one: the bytes go to a temporary file in the same
// folder ("<name>.tmp-<pid>-<n>"), are flushed and fsync'ed, and only then renamed over the target
// (rename is atomic within one file system). On any failure the temporary file is removed, the old
// target is left exactly as it was, and swish::Error names the path and the system's reason.
//
// Every file swish writes (models, reports, images, meshes) goes through here.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <ostream>
#include <span>
#include <string_view>

namespace swish {

void writeFileAtomic(const std::filesystem::path& target, std::span<const uint8_t> bytes);
void writeTextFileAtomic(const std::filesystem::path& target, std::string_view text);
// For writers that produce their output through a std::ostream (JSON, OBJ, CSV...). If `write`
// throws, or leaves the stream failed, nothing replaces the target and the exception propagates
// (a failed stream becomes an Error).
void writeFileAtomicWith(const std::filesystem::path& target, const std::function<void(std::ostream&)>& write);

// After a writer has replaced its set of numbered outputs (pose_00012_front.png...), removes the files
// of an earlier run in `folder` that it did not write this time: regular files whose name starts with
// `prefix` and ends with one of `suffixes`, and whose name is not that of a file in `written`. Files of other names are
// never touched. Returns how many were removed; a file that cannot be removed is left (best effort).
size_t removeStaleOutputs(const std::filesystem::path& folder, std::string_view prefix,
                          std::span<const std::string_view> suffixes, std::span<const std::filesystem::path> written);

// The mechanism behind the functions above, for writers that stream large outputs piece by piece:
//   AtomicFileWriter w(path);
//   w.write(bytes); w.stream() << "text";   // any mix
//   w.commit();                             // fsync + rename; without it the destructor discards
// Not copyable; one writer per target at a time in a process is the caller's business (two writers
// get different temporary names, and the last commit wins).
class AtomicFileWriter {
 public:
  explicit AtomicFileWriter(std::filesystem::path target);
  ~AtomicFileWriter();  // removes the temporary file unless commit() succeeded
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  void write(std::span<const uint8_t> bytes);
  std::ostream& stream();
  // Flushes, fsyncs, closes and renames over the target, then fsyncs the folder (best effort: some
  // file systems cannot). Throws Error on failure, after removing the temporary file.
  void commit();

  const std::filesystem::path& target() const { return target_; }
  const std::filesystem::path& temporaryPath() const { return temp_; }

 private:
  class FdStreamBuf;
  void writeRaw(const char* data, size_t size);
  [[noreturn]] void failAndDiscard(const std::string& action, int err);
  void discard() noexcept;

  std::filesystem::path target_;
  std::filesystem::path temp_;
  int fd_ = -1;
  bool committed_ = false;
  std::unique_ptr<FdStreamBuf> buf_;
  std::unique_ptr<std::ostream> stream_;
};

}  // namespace swish
