// The MPI layer. MPI appears only in src/parallel and drivers; algorithms see none of it.
// Every MPI return code is checked and turned into qsmesh::Error.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace qsmesh::parallel {

/// Initialises MPI (thread level SERIALIZED: MPI itself is called from the main thread only, but
/// PETSc solves run on worker threads, one at a time through linalg::PetscLane) and finalises it on
/// destruction. Exactly one per process, created by the driver's main().
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  /// Ends all ranks with `code` (for errors met by one rank only).
  [[noreturn]] static void abort(int code);
};

/// A communicator (MPI_COMM_WORLD by default).
class Comm {
 public:
  /// The world communicator; MPI must be initialised.
  static Comm world();
  /// This process alone (MPI_COMM_SELF): serial runs of collective code.
  static Comm self();
  Comm(const Comm&);
  Comm& operator=(const Comm&);
  ~Comm();

  [[nodiscard]] int rank() const;
  [[nodiscard]] int size() const;
  /// Number of ranks of this communicator running on this rank's node (shared memory).
  [[nodiscard]] int local_size() const;
  void barrier() const;

  /// Element-wise sum over ranks, result on every rank.
  void allreduce_sum(std::vector<double>& values) const;
  void allreduce_sum(std::vector<std::int64_t>& values) const;
  /// Element-wise minimum over ranks, result on every rank.
  void allreduce_min(std::vector<double>& values) const;
  /// Maximum over ranks.
  [[nodiscard]] double allreduce_max(double value) const;
  /// Logical and over ranks.
  [[nodiscard]] bool allreduce_and(bool value) const;
  /// Gathers every rank's byte buffer on `root`, in rank order (empty vector on other ranks).
  [[nodiscard]] std::vector<std::vector<char>> gather_bytes(const std::vector<char>& mine,
                                                            int root = 0) const;
  /// Broadcasts a byte buffer from `root` (resized on the receivers).
  void broadcast_bytes(std::vector<char>& bytes, int root = 0) const;

 private:
  struct Impl;
  explicit Comm(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
};

}  // namespace qsmesh::parallel
