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

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)) {
  const fs::path p(path_);
  // Same folder as the target, so that rename() never crosses file systems; the pid keeps two
  // processes writing the same name apart.
  // Appended rather than "." + ...: GCC 12 reports a false -Wrestrict on that concatenation.
  std::string name = ".";
  name += p.filename().string();
  name += ".tmp.";
  name += std::to_string(::getpid());
  const fs::path temp = p.parent_path() / name;
  temp_ = temp.string();
  std::error_code ec;
  fs::remove(temp, ec);
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

namespace {
constexpr std::size_t kFlushBytes = std::size_t{1} << 20;
}

OutputFile::OutputFile(const std::string& path, const std::string& shown)
    : name_(shown.empty() ? path : shown) {
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
  if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size()) {
    throw OutputError("cannot write " + name_ + ": " + std::strerror(errno));
  }
  buffer_.clear();
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
  if (std::fwrite(data, 1, bytes, file_) != bytes) {
    throw OutputError("cannot write " + name_ + ": " + std::strerror(errno));
  }
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
