#include "swish/files/atomic_write.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <string>
#include <vector>

#include "swish/core/error.hpp"

namespace swish {

namespace fs = std::filesystem;

// A buffered streambuf over the writer's file descriptor. It cannot throw through the iostream
// machinery (which would swallow the exception into badbit), so it remembers the first errno and
// commit() turns it into an Error.
class AtomicFileWriter::FdStreamBuf : public std::streambuf {
 public:
  explicit FdStreamBuf(int fd) : fd_(fd) { setp(buf_.data(), buf_.data() + buf_.size()); }
  int error() const { return error_; }

  // Writes everything buffered so far; false (and error() set) on failure.
  bool drain() {
    const char* p = pbase();
    size_t left = size_t(pptr() - pbase());
    while (left > 0 && error_ == 0) {
      const ssize_t n = ::write(fd_, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
        break;
      }
      p += n;
      left -= size_t(n);
    }
    setp(buf_.data(), buf_.data() + buf_.size());
    return error_ == 0;
  }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  int fd_;
  int error_ = 0;
  std::array<char, 1 << 16> buf_;
};

namespace {

// Built with append rather than "'" + s: GCC 12 warns falsely (-Wrestrict) about the latter.
std::string quoted(const fs::path& p) {
  std::string s(1, '\'');
  s.append(p.string()).push_back('\'');
  return s;
}

// Unique per process and call, so that two threads writing the same target never share a temporary.
fs::path temporaryPathFor(const fs::path& target) {
  static std::atomic<uint64_t> counter{0};
  fs::path tmp = target;
  tmp += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
  return tmp;
}

}  // namespace

AtomicFileWriter::AtomicFileWriter(fs::path target) : target_(std::move(target)) {
  if (target_.empty() || !target_.has_filename()) throw Error("cannot write " + quoted(target_) + ": not a file name");
  std::error_code ec;
  if (fs::is_directory(target_, ec)) throw Error("cannot write " + quoted(target_) + ": it is a directory");
  temp_ = temporaryPathFor(target_);
  fd_ = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd_ < 0) {
    const int err = errno;
    throw Error("cannot write " + quoted(target_) + ": creating the temporary file " + quoted(temp_) +
                " failed: " + std::strerror(err));
  }
  buf_ = std::make_unique<FdStreamBuf>(fd_);
  stream_ = std::make_unique<std::ostream>(buf_.get());
}

AtomicFileWriter::~AtomicFileWriter() {
  if (!committed_) discard();
}

void AtomicFileWriter::discard() noexcept {
  stream_.reset();
  buf_.reset();
  if (fd_ >= 0) {
    ::close(fd_);
    fd_ = -1;
  }
  if (!temp_.empty()) {
    ::unlink(temp_.c_str());  // may already be gone; nothing else to do about it
    temp_.clear();
  }
}

void AtomicFileWriter::failAndDiscard(const std::string& action, int err) {
  const fs::path temp = temp_;
  discard();
  throw Error("cannot write " + quoted(target_) + ": " + action + " " + quoted(temp) +
              " failed: " + std::strerror(err));
}

void AtomicFileWriter::writeRaw(const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd_, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      failAndDiscard("writing", errno);
    }
    data += n;
    size -= size_t(n);
  }
}

void AtomicFileWriter::write(std::span<const uint8_t> bytes) {
  if (fd_ < 0) throw Error("cannot write " + quoted(target_) + ": the writer is already closed");
  // Keep the order of stream() text and raw bytes.
  if (!buf_->drain()) failAndDiscard("writing", buf_->error());
  writeRaw(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

std::ostream& AtomicFileWriter::stream() {
  if (!stream_) throw Error("cannot write " + quoted(target_) + ": the writer is already closed");
  return *stream_;
}

void AtomicFileWriter::commit() {
  if (fd_ < 0) throw Error("cannot write " + quoted(target_) + ": the writer is already closed");
  stream_->flush();
  if (!buf_->drain()) failAndDiscard("writing", buf_->error());
  if (stream_->fail()) failAndDiscard("writing", EIO);
  if (::fsync(fd_) != 0) failAndDiscard("syncing", errno);
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) failAndDiscard("closing", errno);
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    const int err = errno;
    const fs::path temp = temp_;
    discard();
    throw Error("cannot write " + quoted(target_) + ": renaming " + quoted(temp) +
                " over it failed: " + std::strerror(err));
  }
  committed_ = true;
  temp_.clear();
  stream_.reset();
  buf_.reset();
  // Make the rename itself durable. Best effort: some file systems refuse fsync on a folder, and the
  // data is already safe in the renamed file.
  const fs::path folder = target_.has_parent_path() ? target_.parent_path() : fs::path(".");
  const int dirFd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dirFd >= 0) {
    ::fsync(dirFd);
    ::close(dirFd);
  }
}

void writeFileAtomic(const fs::path& target, std::span<const uint8_t> bytes) {
  AtomicFileWriter w(target);
  w.write(bytes);
  w.commit();
}

void writeTextFileAtomic(const fs::path& target, std::string_view text) {
  writeFileAtomic(target, std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(text.data()), text.size()));
}

void writeFileAtomicWith(const fs::path& target, const std::function<void(std::ostream&)>& write) {
  AtomicFileWriter w(target);
  write(w.stream());  // an exception here leaves through ~AtomicFileWriter, which discards
  w.commit();
}

size_t removeStaleOutputs(const std::filesystem::path& folder, std::string_view prefix,
                          std::span<const std::string_view> suffixes, std::span<const std::filesystem::path> written) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<fs::path> stale;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    const std::string name = it->path().filename().string();
    if (!name.starts_with(prefix)) continue;
    if (std::none_of(suffixes.begin(), suffixes.end(), [&](std::string_view s) { return name.ends_with(s); })) continue;
    if (std::any_of(written.begin(), written.end(),
                    [&](const fs::path& w) { return w.filename() == it->path().filename(); }))
      continue;
    stale.push_back(it->path());
  }
  size_t removed = 0;
  for (const fs::path& p : stale) removed += fs::remove(p, ec) ? 1 : 0;  // ec: best effort, see the header
  return removed;
}

}  // namespace swish
