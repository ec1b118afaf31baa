// Atomic file output: write under a temporary name in the destination folder, rename on success.
#pragma once

#include <cstdio>
#include <string>
#include <string_view>

namespace qsmesh::io {

/// Owns the temporary name "<dir>/.<name>.tmp.<pid>" of an output file `path`. The writer creates and
/// writes temp_path(), then calls commit(), which renames it to path() (atomic within a file
/// system). If commit() is not reached (exception, early return), the destructor removes the
/// temporary; the requested name is then never touched. Not copyable nor movable.
class AtomicFile {
 public:
  /// Does not create anything; removes a stale temporary of the same name.
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  [[nodiscard]] const std::string& path() const { return path_; }
  [[nodiscard]] const std::string& temp_path() const { return temp_; }
  [[nodiscard]] bool committed() const { return committed_; }

  /// Renames the temporary to path(). Throws qsmesh::OutputError (temporary removed) on failure.
  void commit();

 private:
  std::string path_;
  std::string temp_;
  bool committed_ = false;
};

/// Commits two files that only make sense together (an HDF5 file and its XDMF description):
/// `first`, then `second`. An earlier file at first.path() is moved aside before and put back if
/// either rename fails, so that a failure leaves the earlier pair as it was; a run stopped between
/// the renames leaves the new `first` beside the earlier `second`, never `second` without `first`.
/// Throws qsmesh::OutputError on failure.
void commit_together(AtomicFile& first, AtomicFile& second);

/// Buffered text/binary output to a FILE* with every C library return code checked; errors throw
/// qsmesh::OutputError naming the file. close() must be called for the data to count as written.
class OutputFile {
 public:
  explicit OutputFile(const std::string& path);
  /// Writes `target`'s temporary; errors name the file the user asked for, target.path().
  explicit OutputFile(const AtomicFile& target);
  ~OutputFile();  ///< closes without checking (error path only)
  OutputFile(const OutputFile&) = delete;
  OutputFile& operator=(const OutputFile&) = delete;

  OutputFile& operator<<(std::string_view s);
  OutputFile& operator<<(char c);
  OutputFile& operator<<(long long v);
  OutputFile& operator<<(int v) { return *this << static_cast<long long>(v); }
  OutputFile& operator<<(long v) { return *this << static_cast<long long>(v); }
  OutputFile& operator<<(unsigned long v) { return *this << static_cast<long long>(v); }
  OutputFile& operator<<(unsigned v) { return *this << static_cast<long long>(v); }
  /// Shortest decimal form that reads back to the same double (std::to_chars).
  OutputFile& operator<<(double v);
  void write(const void* data, std::size_t bytes);
  /// Flushes and closes; throws qsmesh::Error on any failure.
  void close();

 private:
  OutputFile(const std::string& path, std::string shown);
  void flush();
  void put(const void* data, std::size_t bytes);  // straight to the FILE*, checked
  std::string name_;
  std::FILE* file_ = nullptr;
  std::string buffer_;
};

}  // namespace qsmesh::io
