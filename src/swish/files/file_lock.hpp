#pragma once
// An exclusive lock on a file (flock), held for as long as the FileLock lives, for work folders that two
// processes must not write at once (a bake's part 1: its manifest and pose files). The lock file holds
// who holds it ("pid <n> on <host> since <UTC time>: <what>") so that the process that waits, or is
// refused, can say so. The file is left in place when the lock is released (removing it would let a
// third process lock a new file while a second still waits on the old one).
//
// Released when the holder exits, however it exits (the kernel drops a dead process's flock). Two
// FileLocks on one file conflict within one process too (each opens its own file description).
// File systems that cannot lock (some network mounts answer ENOLCK or EOPNOTSUPP) give a FileLock that
// holds nothing and says so in unsupportedReason(): the caller decides whether to go on unlocked.
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

namespace swish {

class FileLock {
 public:
  // Blocks until the lock is held. `onWait` (if set) is called once, before waiting, with who holds it.
  // `what` is written into the lock file for others to read. Throws Error (naming the file) when the file
  // cannot be opened.
  static FileLock acquire(const std::filesystem::path& file, const std::string& what,
                          const std::function<void(const std::string& holder)>& onWait = {});
  // Takes the lock only if it is free: nullopt when another holds it, its holder in *holder.
  static std::optional<FileLock> tryAcquire(const std::filesystem::path& file, const std::string& what,
                                            std::string* holder = nullptr);

  FileLock(FileLock&& o) noexcept;
  FileLock& operator=(FileLock&& o) noexcept;
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;
  ~FileLock();

  bool held() const { return fd_ >= 0 && unsupported_.empty(); }
  // Non-empty when the file system refused to lock: nothing is held.
  const std::string& unsupportedReason() const { return unsupported_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  FileLock(std::filesystem::path path, int fd) : path_(std::move(path)), fd_(fd) {}
  static std::optional<FileLock> lock(const std::filesystem::path& file, const std::string& what, bool wait,
                                      const std::function<void(const std::string&)>& onWait, std::string* holder);
  void release() noexcept;

  std::filesystem::path path_;
  int fd_ = -1;
  std::string unsupported_;
};

}  // namespace swish
