// Atomic file output: write under a temporary name in the destination folder, rename on success.
#pragma once

#include <cstdio>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace qsmesh::io {

/// Owns the temporary name "<dir>/.<name>.tmp.<pid>" of an output file `path`. The writer creates
/// and writes temp_path(), then calls commit(), which renames it to path() (atomic within a file
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

/// "<dir>/.<name>.tmp.<pid>": the temporary an AtomicFile of `path` writes in process `pid`.
[[nodiscard]] std::string temporary_path(const std::string& path, long pid);
/// "<dir>/.<name>.old.<pid>": where commit_together moves an earlier `path` aside in process `pid`.
[[nodiscard]] std::string aside_path(const std::string& path, long pid);

/// A hidden sibling of an output (temporary_path or aside_path) whose process no longer runs: what
/// a run killed outright (SIGKILL, power loss) leaves behind, since no handler of its own can run.
struct LeftoverFile {
  std::string path;    ///< the file, in the output's folder
  long pid = 0;        ///< the process that made it (from the name)
  bool aside = false;  ///< ".old." (an earlier output moved aside), else ".tmp." (a partial write)
};

/// Lists the files ".<name>.tmp.<pid>" and ".<name>.old.<pid>" in the folder of `output` (file
/// name <name>), with <pid> decimal digits, for which `is_alive(pid)` is false; sorted by path.
/// Other names, other tags and the files of live processes (a concurrent run writing the same
/// name) are not listed. A missing or unreadable folder lists nothing. Touches no file.
[[nodiscard]] std::vector<LeftoverFile> find_leftovers(const std::string& output,
                                                       const std::function<bool(long)>& is_alive);

/// False only when kill(pid, 0) reports that no such process exists (ESRCH); a process of
/// another user counts as alive. Process ids are per machine: a run on another host writing to a
/// shared folder is not seen, and a reused id keeps a leftover (it is then only kept longer).
[[nodiscard]] bool process_exists(long pid);

/// Cleans up `leftovers` (from find_leftovers(output, ...)) in order: a temporary is removed; an
/// aside file is renamed back to `output` when `output` does not exist (the run was stopped between
/// moving the earlier file aside and committing the new one, commit_together), else removed.
/// Returns one line per file saying what was done or why it could not be; never throws.
[[nodiscard]] std::vector<std::string> clean_leftovers(const std::string& output,
                                                       const std::vector<LeftoverFile>& leftovers);

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
