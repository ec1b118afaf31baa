#include "qsmesh/io/atomic_file.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <system_error>

#include "qsmesh/core/error.hpp"

namespace qsmesh::io {

namespace fs = std::filesystem;

namespace {

constexpr const char* kTemporaryTag = "tmp";
constexpr const char* kAsideTag = "old";

// ".<name>.<tag>." of a file name: the hidden siblings of one output differ only by the pid after
// it.
std::string hidden_prefix(const std::string& filename, const char* tag) {
  // Appended rather than "." + ...: GCC 12 reports a false -Wrestrict on that concatenation.
  std::string name = ".";
  name += filename;
  name += '.';
  name += tag;
  name += '.';
  return name;
}

// "<dir>/.<name>.<tag>.<pid>" for `path`: in the same folder, so that rename() never crosses file
// systems; the pid keeps two processes writing the same name apart.
std::string hidden_sibling(const std::string& path, const char* tag, long pid) {
  const fs::path p(path);
  return (p.parent_path() / (hidden_prefix(p.filename().string(), tag) + std::to_string(pid)))
      .string();
}

// The pid of `filename` when it is `prefix` followed by decimal digits only.
std::optional<long> pid_after(const std::string& filename, const std::string& prefix) {
  if (filename.size() <= prefix.size() || filename.compare(0, prefix.size(), prefix) != 0)
    return std::nullopt;
  const char* first = filename.data() + prefix.size();
  const char* last = filename.data() + filename.size();
  long pid = 0;
  const auto r = std::from_chars(first, last, pid);
  if (r.ec != std::errc() || r.ptr != last || *first < '0' || *first > '9') return std::nullopt;
  return pid;
}

}  // namespace

std::string temporary_path(const std::string& path, long pid) {
  return hidden_sibling(path, kTemporaryTag, pid);
}

std::string aside_path(const std::string& path, long pid) {
  return hidden_sibling(path, kAsideTag, pid);
}

std::vector<LeftoverFile> find_leftovers(const std::string& output,
                                         const std::function<bool(long)>& is_alive) {
  const fs::path p(output);
  const std::string filename = p.filename().string();
  std::vector<LeftoverFile> found;
  if (filename.empty()) return found;
  const std::string temp_prefix = hidden_prefix(filename, kTemporaryTag);
  const std::string aside_prefix = hidden_prefix(filename, kAsideTag);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  fs::directory_iterator it(dir, ec);
  // A folder that cannot be read has nothing this process could clean either.
  for (; !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    bool aside = false;
    std::optional<long> pid = pid_after(name, temp_prefix);
    if (!pid) {
      pid = pid_after(name, aside_prefix);
      aside = true;
    }
    if (!pid || is_alive(*pid)) continue;
    found.push_back({(p.parent_path() / name).string(), *pid, aside});
  }
  std::sort(found.begin(), found.end(),
            [](const LeftoverFile& a, const LeftoverFile& b) { return a.path < b.path; });
  return found;
}

bool process_exists(long pid) {
  if (pid <= 0 || pid > std::numeric_limits<pid_t>::max()) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH;
}

std::vector<std::string> clean_leftovers(const std::string& output,
                                         const std::vector<LeftoverFile>& leftovers) {
  std::vector<std::string> lines;
  for (const LeftoverFile& f : leftovers) {
    const std::string of_run = " of an interrupted run (process " + std::to_string(f.pid) + ")";
    std::error_code ec;
    if (f.aside && !fs::exists(output, ec) && !ec) {
      fs::rename(f.path, output, ec);
      lines.push_back(ec ? "could not put back " + f.path + of_run + " as " + output + ": " +
                               ec.message()
                         : "put back " + output + " from " + f.path + of_run);
      continue;
    }
    fs::remove(f.path, ec);
    const char* what = f.aside ? "set-aside copy " : "temporary ";
    lines.push_back(ec ? "could not remove stale " + std::string(what) + f.path + of_run + ": " +
                             ec.message()
                       : "removed stale " + std::string(what) + f.path + of_run);
  }
  return lines;
}

AtomicFile::AtomicFile(std::string path)
    : path_(std::move(path)), temp_(temporary_path(path_, ::getpid())) {
  std::error_code ec;
  fs::remove(fs::path(temp_), ec);
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    std::error_code ec;
    fs::remove(fs::path(temp_), ec);  // best effort: a destructor must not throw
  }
}

void AtomicFile::commit() {
  QSMESH_CHECK(!committed_, "output " << path_ << " committed twice");
  if (std::rename(temp_.c_str(), path_.c_str()) != 0) {
    const int err = errno;
    std::error_code ec;
    fs::remove(fs::path(temp_), ec);
    throw OutputError("cannot rename " + temp_ + " to " + path_ + ": " + std::strerror(err));
  }
  committed_ = true;
}

void commit_together(AtomicFile& first, AtomicFile& second) {
  std::error_code ec;
  const std::string aside = aside_path(first.path(), ::getpid());
  const bool had_earlier = fs::exists(first.path(), ec);
  if (had_earlier) {
    fs::rename(first.path(), aside, ec);
    if (ec) throw OutputError("cannot replace " + first.path() + ": " + ec.message());
  }
  auto restore = [&] {
    std::error_code ignored;
    if (had_earlier) fs::rename(aside, first.path(), ignored);
  };
  try {
    first.commit();
  } catch (...) {
    restore();
    throw;
  }
  try {
    second.commit();
  } catch (...) {
    std::error_code ignored;
    fs::remove(first.path(), ignored);
    restore();
    throw;
  }
  if (had_earlier) fs::remove(aside, ec);
}

namespace {
constexpr std::size_t kFlushBytes = std::size_t{1} << 20;
}

OutputFile::OutputFile(const std::string& path) : OutputFile(path, path) {}

OutputFile::OutputFile(const AtomicFile& target) : OutputFile(target.temp_path(), target.path()) {}

OutputFile::OutputFile(const std::string& path, std::string shown) : name_(std::move(shown)) {
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    throw OutputError("cannot open " + name_ + " for writing: " + std::strerror(errno));
  }
  buffer_.reserve(kFlushBytes + 4096);
}

OutputFile::~OutputFile() {
  if (file_ != nullptr) std::fclose(file_);
}

void OutputFile::flush() {
  QSMESH_CHECK(file_ != nullptr, "write to closed file " << name_);
  if (buffer_.empty()) return;
  put(buffer_.data(), buffer_.size());
  buffer_.clear();
}

void OutputFile::put(const void* data, std::size_t bytes) {
  if (std::fwrite(data, 1, bytes, file_) != bytes) {
    throw OutputError("cannot write " + name_ + ": " + std::strerror(errno));
  }
}

OutputFile& OutputFile::operator<<(std::string_view s) {
  buffer_.append(s);
  if (buffer_.size() >= kFlushBytes) flush();
  return *this;
}

OutputFile& OutputFile::operator<<(char c) {
  buffer_.push_back(c);
  if (buffer_.size() >= kFlushBytes) flush();
  return *this;
}

OutputFile& OutputFile::operator<<(long long v) {
  char tmp[24];
  const auto r = std::to_chars(tmp, tmp + sizeof tmp, v);
  return *this << std::string_view(tmp, static_cast<std::size_t>(r.ptr - tmp));
}

OutputFile& OutputFile::operator<<(double v) {
  char tmp[32];
  const auto r = std::to_chars(tmp, tmp + sizeof tmp, v);
  QSMESH_CHECK(r.ec == std::errc(), "cannot format a double for " << name_);
  return *this << std::string_view(tmp, static_cast<std::size_t>(r.ptr - tmp));
}

void OutputFile::write(const void* data, std::size_t bytes) {
  if (bytes < kFlushBytes) {
    *this << std::string_view(static_cast<const char*>(data), bytes);
    return;
  }
  // A large block (an HDF5 file image) goes straight out rather than through a copy in the buffer.
  flush();
  put(data, bytes);
}

void OutputFile::close() {
  flush();
  std::FILE* f = file_;
  file_ = nullptr;
  const bool ok = std::fflush(f) == 0 && ::fsync(::fileno(f)) == 0;
  const int err = errno;
  if (std::fclose(f) != 0 || !ok) {
    throw OutputError("cannot write " + name_ + ": " + std::strerror(ok ? errno : err));
  }
}

}  // namespace qsmesh::io
