#include "symoro/io/atomic_file.hpp"

#include <atomic>
#include <cerrno>
#include <climits>
#include <cstring>
#include <streambuf>
#include <string_view>
#include <vector>

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include "symoro/error.hpp"

namespace symoro::io {

namespace {

std::atomic<unsigned> temp_counter{0};
constexpr std::string_view temp_tag = ".symoro-tmp.";

std::string host_name() {
  char name[HOST_NAME_MAX + 1] = {};
  if (::gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "localhost";
  return name;
}

bool all_digits(std::string_view s) {
  if (s.empty() || s.size() > 10) return false;  // a pid_t fits in 10 digits
  for (char c : s)
    if (c < '0' || c > '9') return false;
  return true;
}

// Removes the ".<name>.symoro-tmp.<host>.<pid>.<n>" files of this host in the target's folder,
// whatever their target, whose process is gone: writers killed (kill -9, a crash) before they
// could remove their own (a 332 MB one stayed when another file was written beside it). ESRCH is
// the only proof; a process we may not signal (EPERM) is alive.
void remove_stale_temps(const std::filesystem::path& target) {
  namespace fs = std::filesystem;
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  const std::string mark = std::string(temp_tag) + host_name() + ".";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    const std::size_t at = name.rfind(mark);
    if (name.empty() || name[0] != '.' || at == std::string::npos || at < 2) continue;
    const std::string_view rest = std::string_view(name).substr(at + mark.size());  // "<pid>.<n>"
    const std::size_t dot = rest.find('.');
    if (dot == std::string_view::npos || !all_digits(rest.substr(0, dot)) || !all_digits(rest.substr(dot + 1)))
      continue;
    const long pid = std::stol(std::string(rest.substr(0, dot)));
    if (pid <= 0 || pid > INT_MAX || pid == static_cast<long>(::getpid())) continue;  // not a pid, or ours
    if (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;
    std::error_code ignored;
    if (it->is_regular_file(ignored)) fs::remove(it->path(), ignored);
  }
}

// "No space left on device" as this project's messages say it; other reasons as the system does.
std::string reason(int error) {
  if (error == ENOSPC) return "no space left on device";
  if (error == EDQUOT) return "disk quota exceeded";
  return std::strerror(error);
}

}  // namespace

// Writes to the temporary file's descriptor and keeps the first error's errno (an ofstream
// loses it, and a full disk then read as an unexplained failure).
class AtomicFile::Buffer : public std::streambuf {
 public:
  explicit Buffer(int fd) : fd_(fd), data_(1 << 16) { setp(data_.data(), data_.data() + data_.size()); }
  ~Buffer() override { close_fd(); }
  int error() const { return error_; }
  int fd() const { return fd_; }
  void close_fd() {
    if (fd_ >= 0 && ::close(fd_) != 0 && error_ == 0) error_ = errno;
    fd_ = -1;
  }
  bool drain() {
    const char* p = pbase();
    const bool ok = write_all(p, static_cast<std::size_t>(pptr() - p));
    setp(data_.data(), data_.data() + data_.size());
    return ok;
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
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    if (n >= epptr() - pptr()) {  // a large block goes straight to the file
      if (!drain() || !write_all(s, static_cast<std::size_t>(n))) return 0;
      return n;
    }
    std::memcpy(pptr(), s, static_cast<std::size_t>(n));
    pbump(static_cast<int>(n));
    return n;
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  bool write_all(const char* p, std::size_t n) {
    if (error_ != 0) return false;
    while (n > 0) {
      const ssize_t done = ::write(fd_, p, n);
      if (done < 0 && errno == EINTR) continue;
      if (done <= 0) {
        error_ = done < 0 ? errno : EIO;
        return false;
      }
      p += done;
      n -= static_cast<std::size_t>(done);
    }
    return true;
  }
  int fd_;
  std::vector<char> data_;
  int error_ = 0;
};

std::filesystem::path AtomicFile::temp_path(const std::filesystem::path& target, long pid, unsigned n) {
  return target.parent_path() / ("." + target.filename().string() + std::string(temp_tag) + host_name() + "." +
                                 std::to_string(pid) + "." + std::to_string(n));
}

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)), out_(nullptr) {
  remove_stale_temps(target_);
  temp_ = temp_path(target_, static_cast<long>(::getpid()), temp_counter++);
  const int fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0)
    throw DataError(target_.string(), 0, "cannot create a temporary file for writing (" + reason(errno) + ")");
  buffer_ = std::make_unique<Buffer>(fd);
  out_.rdbuf(buffer_.get());
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  buffer_->close_fd();
  std::error_code ec;
  std::filesystem::remove(temp_, ec);
}

void AtomicFile::finish() {
  if (finished_) return;
  out_.flush();
  int error = buffer_->error();
  if (error == 0 && !out_) error = EIO;
  // fsync: the rename must publish complete content (and a full disk may only show here).
  if (error == 0 && ::fsync(buffer_->fd()) != 0) error = errno;
  buffer_->close_fd();
  if (error == 0) error = buffer_->error();
  if (error != 0) {
    std::error_code ec;
    std::filesystem::remove(temp_, ec);
    const bool previous = std::filesystem::exists(target_, ec);
    throw DataError(target_.string(), 0,
                    "writing failed: " + reason(error) +
                        (previous ? "; the previous file is left as it was" : "; nothing is written under this name"));
  }
  finished_ = true;
}

void AtomicFile::commit() {
  finish();
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec) {
    const std::string why = ec.value() == ENOSPC ? reason(ENOSPC) : ec.message();  // before remove() resets ec
    std::filesystem::remove(temp_, ec);
    throw DataError(target_.string(), 0, "cannot rename the written file into place: " + why);
  }
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& target, const std::string& content) {
  AtomicFile f(target);
  f.stream() << content;
  f.commit();
}

void write_files_atomically(const std::vector<std::pair<std::filesystem::path, std::string>>& files) {
  std::vector<std::unique_ptr<AtomicFile>> open;
  for (const auto& [target, content] : files) {
    open.push_back(std::make_unique<AtomicFile>(target));
    open.back()->stream() << content;
  }
  // Every file complete on disk before the first takes its name: a full disk fails here, and the
  // destructors remove every temporary file.
  for (auto& f : open) f->finish();
  for (auto& f : open) f->commit();
}

}  // namespace symoro::io
