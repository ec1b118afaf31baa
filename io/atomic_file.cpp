#include "qsmesh/io/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <system_error>

#include "qsmesh/core/error.hpp"

namespace qsmesh::io {

namespace fs = std::filesystem;

namespace {

// "<dir>/.<name>.<tag>.<pid>" for `path`: in the same folder, so that rename() never crosses file
// systems; the pid keeps two processes writing the same name apart.
std::string hidden_sibling(const std::string& path, const char* tag) {
  const fs::path p(path);
  // Appended rather than "." + ...: GCC 12 reports a false -Wrestrict on that concatenation.
  std::string name = ".";
  name += p.filename().string();
  name += '.';
  name += tag;
  name += '.';
  name += std::to_string(::getpid());
  return (p.parent_path() / name).string();
}

}  // namespace

AtomicFile::AtomicFile(std::string path)
    : path_(std::move(path)), temp_(hidden_sibling(path_, "tmp")) {
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
  const std::string aside = hidden_sibling(first.path(), "old");
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
