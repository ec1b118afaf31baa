// The MPI layer. MPI appears only in src/parallel and drivers; algorithms see none of it.
// Every MPI return code is checked and turned into qsmesh::Error.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "qsmesh/linalg/solver.hpp"

namespace qsmesh::parallel {

/// Initialises MPI (thread level SERIALIZED: MPI is called from the main thread, except PETSc
/// solves, which run on worker threads one at a time through linalg::SolverLane, and SharedCounter
/// and SharedBytes, whose calls are serialised by their communicator's lock in stages without
/// PETSc) and finalises it on
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
  /// These ranks as a linalg::SolverGroup (the communicator opaque to linalg), for a group lane
  /// whose large systems are split over them. Valid while this Comm (or a copy) lives.
  [[nodiscard]] std::unique_ptr<linalg::SolverGroup> solver_group() const;
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
  /// The same gather, handed over one rank at a time: on `root`, use(r, bytes) runs for r = 0, 1,
  /// ... with rank r's buffer (its own is `mine`, moved, not copied), each received only after the
  /// previous call returned, so that the root never holds more than one rank's buffer besides what
  /// `use` keeps. `use` may move from or clear the buffer. Other ranks send theirs and return.
  /// Collective.
  void gather_bytes_each(std::vector<char>&& mine, int root,
                         const std::function<void(int rank, std::vector<char>& bytes)>& use) const;
  /// Broadcasts a byte buffer from `root` (resized on the receivers).
  void broadcast_bytes(std::vector<char>& bytes, int root = 0) const;
  /// Every rank's byte buffer on every rank, in rank order (gathered on rank 0, then broadcast).
  [[nodiscard]] std::vector<std::vector<char>> allgather_bytes(const std::vector<char>& mine) const;
  /// Personalised exchange: to_each[r] (one buffer per rank, this rank's own included) goes to rank
  /// r; returns what every rank sent here, indexed by sender. Sizes are 64-bit and the payloads
  /// travel in pieces under the int range, each pair of ranks directly (no rank holds more than
  /// what it sends and receives).
  [[nodiscard]] std::vector<std::vector<char>> alltoall_bytes(
      const std::vector<std::vector<char>>& to_each) const;

 private:
  struct Impl;
  explicit Comm(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
  friend class SharedCounter;
  friend class SharedBytes;
  friend class RankHelpers;
};

/// A counter shared by every rank and thread of a communicator, for dealing out work dynamically:
/// next() returns 0, 1, 2, ... each value once over all callers together, in no fixed order across
/// callers. Several ranks: one 64-bit integer in an MPI window on rank 0, advanced by
/// MPI_Fetch_and_op under a passive-target lock (rank 0 need not take part: on one node Open MPI's
/// shared-memory window does the atomic itself; a transport without remote atomics may make a call
/// wait for rank 0's next MPI call); one rank: an atomic.
/// Construction and destruction are collective. next() is thread-safe: its MPI calls are
/// serialised by the communicator's lock (shared by the Comm's copies, and with SharedBytes::read),
/// as MPI_THREAD_SERIALIZED requires, so it must not run while another thread of the rank is inside
/// MPI by another path (no PETSc solve in the same stage).
class SharedCounter {
 public:
  explicit SharedCounter(const Comm& comm);
  ~SharedCounter();
  SharedCounter(const SharedCounter&) = delete;
  SharedCounter& operator=(const SharedCounter&) = delete;
  [[nodiscard]] std::int64_t next();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Every rank's byte buffer, readable by every rank and thread without its owner taking part: for
/// work dealt out as it goes (SharedCounter), where a rank learns which item it takes only when it
/// takes it, and fetches that item alone instead of receiving every rank's items beforehand.
/// Several ranks: the bytes are copied into an MPI window allocated by MPI (on one node Open MPI
/// serves reads from shared memory; see SharedCounter), read with MPI_Get under a shared
/// passive-target lock; one rank: read in place.
/// Construction and destruction are collective. read() is thread-safe; its MPI calls take the
/// communicator's lock, the one SharedCounter::next() takes.
class SharedBytes {
 public:
  SharedBytes(const Comm& comm, const std::vector<char>& mine);
  ~SharedBytes();
  SharedBytes(const SharedBytes&) = delete;
  SharedBytes& operator=(const SharedBytes&) = delete;
  /// Bytes [offset, offset + length) of rank `owner`'s buffer. Precondition: the range lies in
  /// that buffer (checked against its size; throws qsmesh::Error otherwise).
  [[nodiscard]] std::vector<char> read(int owner, std::int64_t offset, std::int64_t length) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Ranks lending themselves to other ranks' work once their own is done (issue 28: one face's
/// move search dealt over the ranks that have finished theirs). A rank whose own work has ended
/// calls serve_until_all_done: it declares itself free and answers requests until every rank has
/// called it. A rank with lendable work claims free ranks (claim), sends each claimed one a
/// message (send: every claimed rank gets exactly one, possibly empty) and receives its answer
/// (receive: every message is answered, an empty one with an empty answer), after which that
/// rank is free again.
/// Several ranks: each rank's state (busy, free, claimed) in an MPI window on rank 0, with a count
/// of the ranks done. A claim swaps "claimed" into a rank's slot with MPI_Fetch_and_op and
/// MPI_REPLACE and has that rank when the old value was "free"; swapping "claimed" over "busy" or
/// "claimed" changes nothing that matters (a busy rank writes "free" itself when it ends, and only
/// a free rank is ever sent a message). MPI_Compare_and_swap is avoided: it crashed in Open MPI
/// 4's shared-memory windows. The messages travel on a duplicate of the communicator. One rank:
/// nothing to claim, serve_until_all_done returns at once.
/// Construction and destruction are collective. Not thread-safe: one thread of the rank uses it
/// (the pipeline lends only with one thread per rank).
class RankHelpers {
 public:
  explicit RankHelpers(const Comm& comm);
  ~RankHelpers();
  RankHelpers(const RankHelpers&) = delete;
  RankHelpers& operator=(const RankHelpers&) = delete;
  [[nodiscard]] int rank() const;
  [[nodiscard]] int size() const;
  /// Claims up to `wanted` ranks that are free now (never this one); their ranks, possibly none.
  [[nodiscard]] std::vector<int> claim(int wanted);
  /// Sends a claimed rank its share (empty: released with nothing to do). Non-blocking: the bytes
  /// must stay alive until wait_sent().
  void send(int helper, const std::vector<char>& bytes);
  /// Waits for every send() since the last call.
  void wait_sent();
  /// The answer of a claimed rank that was sent a share.
  [[nodiscard]] std::vector<char> receive(int helper);
  /// This rank has no work of its own left: declares itself free, answers each share with
  /// serve(share) (an empty share with an empty answer, without calling serve) and returns when
  /// every rank has called this. Every rank calls it once, after its own work.
  void serve_until_all_done(
      const std::function<std::vector<char>(const std::vector<char>&)>& serve);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace qsmesh::parallel
