#include "swish/files/file_lock.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <utility>

#include "swish/core/error.hpp"

namespace swish {
namespace {

std::string systemReason(int err) { return std::strerror(err); }

// What the lock file says of its holder (what it wrote when it took the lock), on one line.
std::string holderOf(int fd) {
  char buf[512];
  const ssize_t n = ::pread(fd, buf, sizeof buf - 1, 0);
  std::string s = n > 0 ? std::string(buf, size_t(n)) : std::string();
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  return s.empty() ? std::string("another process (it has not written who it is yet)") : s;
}

std::string whoAmI(const std::string& what) {
  char host[256] = "?";
  if (::gethostname(host, sizeof host - 1) != 0) std::strcpy(host, "?");
  host[sizeof host - 1] = '\0';
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  char when[32] = "?";
  if (::gmtime_r(&now, &tm)) std::strftime(when, sizeof when, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return "pid " + std::to_string(::getpid()) + " on " + host + " since " + when + (what.empty() ? "" : ": " + what) +
         "\n";
}

bool cannotLockHere(int err) { return err == ENOLCK || err == EOPNOTSUPP || err == ENOSYS || err == EINVAL; }

}  // namespace

std::optional<FileLock> FileLock::lock(const std::filesystem::path& file, const std::string& what, bool wait,
                                       const std::function<void(const std::string&)>& onWait, std::string* holder) {
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) {
    const int err = errno;
    throw Error(file.string() + ": cannot open the lock file: " + systemReason(err));
  }
  FileLock l(file, fd);
  int rc = ::flock(fd, LOCK_EX | LOCK_NB);
  if (rc != 0 && errno == EWOULDBLOCK) {
    const std::string who = holderOf(fd);
    if (holder) *holder = who;
    if (!wait) return std::nullopt;  // (l closes the file)
    if (onWait) onWait(who);
    do rc = ::flock(fd, LOCK_EX);
    while (rc != 0 && errno == EINTR);
  }
  if (rc != 0) {
    const int err = errno;
    if (cannotLockHere(err)) {
      l.unsupported_ = "the file system cannot lock " + file.string() + " (" + systemReason(err) + ")";
      return l;
    }
    throw Error(file.string() + ": cannot lock: " + systemReason(err));
  }
  // Held: say who holds it (best effort: a lock whose note cannot be written still locks).
  const std::string me = whoAmI(what);
  if (::ftruncate(fd, 0) == 0) {
    [[maybe_unused]] const ssize_t written = ::pwrite(fd, me.data(), me.size(), 0);
  }
  return l;
}

FileLock FileLock::acquire(const std::filesystem::path& file, const std::string& what,
                           const std::function<void(const std::string&)>& onWait) {
  return std::move(*lock(file, what, true, onWait, nullptr));
}

std::optional<FileLock> FileLock::tryAcquire(const std::filesystem::path& file, const std::string& what,
                                             std::string* holder) {
  return lock(file, what, false, {}, holder);
}

FileLock::FileLock(FileLock&& o) noexcept
    : path_(std::move(o.path_)), fd_(std::exchange(o.fd_, -1)), unsupported_(std::move(o.unsupported_)) {}

FileLock& FileLock::operator=(FileLock&& o) noexcept {
  if (this != &o) {
    release();
    path_ = std::move(o.path_);
    fd_ = std::exchange(o.fd_, -1);
    unsupported_ = std::move(o.unsupported_);
  }
  return *this;
}

FileLock::~FileLock() { release(); }

void FileLock::release() noexcept {
  if (fd_ < 0) return;
  // The holder's note is cleared first, so that a waiter that reads it before it locks does not name a
  // process that has let go; closing the file releases the lock.
  if (held()) {
    [[maybe_unused]] const int rc = ::ftruncate(fd_, 0);
  }
  ::close(fd_);
  fd_ = -1;
}

}  // namespace swish
