#include "qsmesh/parallel/comm.hpp"

#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <limits>
#include <mutex>
#include <thread>

#include "qsmesh/core/error.hpp"

namespace qsmesh::parallel {

namespace {
void check_mpi(int code, const char* what) {
  if (code == MPI_SUCCESS) return;
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(code, text, &len);
  throw Error(std::string("MPI error in ") + what + ": " +
              std::string(text, static_cast<std::size_t>(len)));
}

// A window of `slots` int64 on rank 0 of `comm` (none elsewhere), every slot set to `fill`,
// ready for passive-target access once this collective returns. Memory allocated by MPI, not
// MPI_Win_create on our own: on one node Open MPI then shares it and does the atomics itself.
// With a window over user memory it fell back to messages that rank 0 serves only when it calls
// MPI, so the other ranks waited for its faces to end (Block at its reference count, 2 ranks:
// improvement 9.3 s against 10.4 s on one).
MPI_Win allocate_rank0_window(MPI_Comm comm, bool owner, MPI_Aint slots, std::int64_t fill) {
  std::int64_t* base = nullptr;
  MPI_Win win = MPI_WIN_NULL;
  check_mpi(
      MPI_Win_allocate(owner ? slots * static_cast<MPI_Aint>(sizeof(std::int64_t)) : 0,
                       static_cast<int>(sizeof(std::int64_t)), MPI_INFO_NULL, comm, &base, &win),
      "MPI_Win_allocate");
  check_mpi(MPI_Win_set_errhandler(win, MPI_ERRORS_RETURN), "MPI_Win_set_errhandler");
  if (owner) {
    check_mpi(MPI_Win_lock(MPI_LOCK_EXCLUSIVE, 0, 0, win), "MPI_Win_lock");
    for (MPI_Aint i = 0; i < slots; ++i) base[i] = fill;
    check_mpi(MPI_Win_unlock(0, win), "MPI_Win_unlock");
  }
  check_mpi(MPI_Barrier(comm), "MPI_Barrier");
  return win;
}
}  // namespace

MpiSession::MpiSession(int* argc, char*** argv) {
  int provided = 0;
  check_mpi(MPI_Init_thread(argc, argv, MPI_THREAD_SERIALIZED, &provided), "MPI_Init_thread");
  // Errors come back as codes so that they are checked and reported, not aborted on silently.
  check_mpi(MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
}

MpiSession::~MpiSession() {
  int finalized = 0;
  MPI_Finalized(&finalized);
  if (finalized == 0) MPI_Finalize();
}

void MpiSession::abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::abort();
}

struct Comm::Impl {
  MPI_Comm comm = MPI_COMM_WORLD;
  // Serialises the MPI calls that worker threads make (SharedCounter, SharedBytes): MPI runs at
  // MPI_THREAD_SERIALIZED.
  std::mutex lane;
};

Comm::Comm(std::shared_ptr<Impl> impl) : impl_(std::move(impl)) {}
Comm::Comm(const Comm&) = default;
Comm& Comm::operator=(const Comm&) = default;
Comm::~Comm() = default;

Comm Comm::world() { return Comm(std::make_shared<Impl>()); }

Comm Comm::self() {
  auto impl = std::make_shared<Impl>();
  impl->comm = MPI_COMM_SELF;
  return Comm(std::move(impl));
}

int Comm::rank() const {
  int r = 0;
  check_mpi(MPI_Comm_rank(impl_->comm, &r), "MPI_Comm_rank");
  return r;
}

int Comm::size() const {
  int s = 0;
  check_mpi(MPI_Comm_size(impl_->comm, &s), "MPI_Comm_size");
  return s;
}

std::unique_ptr<linalg::SolverGroup> Comm::solver_group() const {
  return std::make_unique<linalg::SolverGroup>(&impl_->comm, rank(), size());
}

int Comm::local_size() const {
  MPI_Comm node = MPI_COMM_NULL;
  check_mpi(MPI_Comm_split_type(impl_->comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node),
            "MPI_Comm_split_type");
  int s = 1;
  const int code = MPI_Comm_size(node, &s);
  MPI_Comm_free(&node);
  check_mpi(code, "MPI_Comm_size");
  return s;
}

void Comm::barrier() const { check_mpi(MPI_Barrier(impl_->comm), "MPI_Barrier"); }

void Comm::allreduce_sum(std::vector<double>& values) const {
  QSMESH_CHECK(values.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max()),
               "reduction too large");
  check_mpi(MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE,
                          MPI_SUM, impl_->comm),
            "MPI_Allreduce");
}

void Comm::allreduce_sum(std::vector<std::int64_t>& values) const {
  QSMESH_CHECK(values.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max()),
               "reduction too large");
  check_mpi(MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_INT64_T,
                          MPI_SUM, impl_->comm),
            "MPI_Allreduce");
}

void Comm::allreduce_min(std::vector<double>& values) const {
  QSMESH_CHECK(values.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max()),
               "reduction too large");
  check_mpi(MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE,
                          MPI_MIN, impl_->comm),
            "MPI_Allreduce");
}

double Comm::allreduce_max(double value) const {
  double out = value;
  check_mpi(MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_MAX, impl_->comm), "MPI_Allreduce");
  return out;
}

bool Comm::allreduce_and(bool value) const {
  int in = value ? 1 : 0, out = 0;
  check_mpi(MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_LAND, impl_->comm), "MPI_Allreduce");
  return out != 0;
}

std::vector<std::vector<char>> Comm::gather_bytes(const std::vector<char>& mine, int root) const {
  std::vector<std::vector<char>> out(rank() == root ? static_cast<std::size_t>(size()) : 0);
  gather_bytes_each(std::vector<char>(mine), root,
                    [&](int r, std::vector<char>& bytes) { out[r] = std::move(bytes); });
  return out;
}

void Comm::gather_bytes_each(
    std::vector<char>&& mine, int root,
    const std::function<void(int rank, std::vector<char>& bytes)>& use) const {
  // Sizes first (64-bit), then the payload rank by rank with point-to-point messages, so that no
  // single MPI count exceeds the int range even when the assembled mesh is large.
  const int n = size();
  const int me = rank();
  std::int64_t my_size = static_cast<std::int64_t>(mine.size());
  std::vector<std::int64_t> sizes(static_cast<std::size_t>(n), 0);
  check_mpi(MPI_Gather(&my_size, 1, MPI_INT64_T, sizes.data(), 1, MPI_INT64_T, root, impl_->comm),
            "MPI_Gather");
  constexpr std::int64_t kChunk = std::int64_t{1} << 30;
  if (me == root) {
    std::vector<char> bytes;
    for (int r = 0; r < n; ++r) {
      if (r == root) {
        std::vector<char> own = std::move(mine);
        use(r, own);
        continue;
      }
      bytes.resize(static_cast<std::size_t>(sizes[r]));
      for (std::int64_t off = 0; off < sizes[r]; off += kChunk) {
        const int count = static_cast<int>(std::min(kChunk, sizes[r] - off));
        check_mpi(
            MPI_Recv(bytes.data() + off, count, MPI_CHAR, r, 9, impl_->comm, MPI_STATUS_IGNORE),
            "MPI_Recv");
      }
      use(r, bytes);
    }
  } else {
    for (std::int64_t off = 0; off < my_size; off += kChunk) {
      const int count = static_cast<int>(std::min(kChunk, my_size - off));
      check_mpi(MPI_Send(mine.data() + off, count, MPI_CHAR, root, 9, impl_->comm), "MPI_Send");
    }
  }
}

void Comm::broadcast_bytes(std::vector<char>& bytes, int root) const {
  std::int64_t n = static_cast<std::int64_t>(bytes.size());
  check_mpi(MPI_Bcast(&n, 1, MPI_INT64_T, root, impl_->comm), "MPI_Bcast");
  bytes.resize(static_cast<std::size_t>(n));
  constexpr std::int64_t kChunk = std::int64_t{1} << 30;
  for (std::int64_t off = 0; off < n; off += kChunk) {
    const int count = static_cast<int>(std::min(kChunk, n - off));
    check_mpi(MPI_Bcast(bytes.data() + off, count, MPI_CHAR, root, impl_->comm), "MPI_Bcast");
  }
}

std::vector<std::vector<char>> Comm::allgather_bytes(const std::vector<char>& mine) const {
  const auto gathered = gather_bytes(mine, 0);
  // One buffer: each rank's size (64-bit) then its bytes.
  std::vector<char> all;
  if (rank() == 0)
    for (const auto& b : gathered) {
      const auto n = static_cast<std::int64_t>(b.size());
      const auto* p = reinterpret_cast<const char*>(&n);
      all.insert(all.end(), p, p + sizeof n);
      all.insert(all.end(), b.begin(), b.end());
    }
  broadcast_bytes(all, 0);
  std::vector<std::vector<char>> out(static_cast<std::size_t>(size()));
  std::size_t pos = 0;
  for (auto& b : out) {
    std::int64_t n = 0;
    QSMESH_CHECK(pos + sizeof n <= all.size(), "allgather_bytes: truncated buffer");
    std::memcpy(&n, all.data() + pos, sizeof n);
    pos += sizeof n;
    QSMESH_CHECK(n >= 0 && pos + static_cast<std::size_t>(n) <= all.size(),
                 "allgather_bytes: truncated buffer");
    b.assign(all.begin() + static_cast<std::ptrdiff_t>(pos),
             all.begin() + static_cast<std::ptrdiff_t>(pos + static_cast<std::size_t>(n)));
    pos += static_cast<std::size_t>(n);
  }
  QSMESH_CHECK(pos == all.size(), "allgather_bytes: " << all.size() - pos << " bytes left over");
  return out;
}

std::vector<std::vector<char>> Comm::alltoall_bytes(
    const std::vector<std::vector<char>>& to_each) const {
  const int n = size();
  const int me = rank();
  QSMESH_CHECK(to_each.size() == static_cast<std::size_t>(n),
               "alltoall_bytes: " << to_each.size() << " buffers for " << n << " ranks");
  std::vector<std::int64_t> send_sizes(static_cast<std::size_t>(n)), recv_sizes(send_sizes.size());
  for (int r = 0; r < n; ++r) send_sizes[r] = static_cast<std::int64_t>(to_each[r].size());
  check_mpi(MPI_Alltoall(send_sizes.data(), 1, MPI_INT64_T, recv_sizes.data(), 1, MPI_INT64_T,
                         impl_->comm),
            "MPI_Alltoall");
  constexpr std::int64_t kChunk = std::int64_t{1} << 30;
  std::vector<std::vector<char>> out(static_cast<std::size_t>(n));
  std::vector<MPI_Request> requests;
  // Pieces between two ranks share a tag: MPI keeps their order.
  const auto pieces = [&](std::int64_t bytes, const auto& post) {
    for (std::int64_t off = 0; off < bytes; off += kChunk) {
      MPI_Request q = MPI_REQUEST_NULL;
      post(off, static_cast<int>(std::min(kChunk, bytes - off)), &q);
      requests.push_back(q);
    }
  };
  for (int r = 0; r < n; ++r) {
    if (r == me) continue;
    out[r].resize(static_cast<std::size_t>(recv_sizes[r]));
    pieces(recv_sizes[r], [&](std::int64_t off, int count, MPI_Request* q) {
      check_mpi(MPI_Irecv(out[r].data() + off, count, MPI_CHAR, r, 8, impl_->comm, q), "MPI_Irecv");
    });
  }
  for (int r = 0; r < n; ++r) {
    if (r == me) continue;
    pieces(send_sizes[r], [&](std::int64_t off, int count, MPI_Request* q) {
      check_mpi(MPI_Isend(to_each[r].data() + off, count, MPI_CHAR, r, 8, impl_->comm, q),
                "MPI_Isend");
    });
  }
  out[me] = to_each[me];
  check_mpi(MPI_Waitall(static_cast<int>(requests.size()), requests.data(), MPI_STATUSES_IGNORE),
            "MPI_Waitall");
  return out;
}

struct SharedCounter::Impl {
  std::shared_ptr<Comm::Impl> owner;  // its communicator and lane
  MPI_Comm comm = MPI_COMM_NULL;
  bool distributed = false;
  MPI_Win win = MPI_WIN_NULL;
  std::atomic<std::int64_t> local{0};  // one rank
};

SharedCounter::SharedCounter(const Comm& comm) : impl_(std::make_unique<Impl>()) {
  impl_->owner = comm.impl_;
  impl_->comm = comm.impl_->comm;
  impl_->distributed = comm.size() > 1;
  if (!impl_->distributed) return;
  impl_->win = allocate_rank0_window(impl_->comm, comm.rank() == 0, 1, 0);
}

SharedCounter::~SharedCounter() {
  // Collective; an error here cannot be thrown from a destructor and would end the run anyway.
  if (impl_->win != MPI_WIN_NULL) MPI_Win_free(&impl_->win);
}

std::int64_t SharedCounter::next() {
  if (!impl_->distributed) return impl_->local.fetch_add(1);
  const std::lock_guard<std::mutex> guard(impl_->owner->lane);
  const std::int64_t one = 1;
  std::int64_t old = 0;
  check_mpi(MPI_Win_lock(MPI_LOCK_SHARED, 0, 0, impl_->win), "MPI_Win_lock");
  check_mpi(MPI_Fetch_and_op(&one, &old, MPI_INT64_T, 0, 0, MPI_SUM, impl_->win),
            "MPI_Fetch_and_op");
  check_mpi(MPI_Win_unlock(0, impl_->win), "MPI_Win_unlock");
  return old;
}

struct SharedBytes::Impl {
  std::shared_ptr<Comm::Impl> owner;  // its communicator and lane
  bool distributed = false;
  MPI_Win win = MPI_WIN_NULL;
  char* base = nullptr;             // this rank's bytes (in the window on several ranks)
  std::vector<char> local;          // one rank: the bytes themselves
  std::vector<std::int64_t> sizes;  // every rank's byte count
};

SharedBytes::SharedBytes(const Comm& comm, const std::vector<char>& mine)
    : impl_(std::make_unique<Impl>()) {
  impl_->owner = comm.impl_;
  const MPI_Comm c = comm.impl_->comm;
  const int n = comm.size();
  impl_->distributed = n > 1;
  const auto my_size = static_cast<std::int64_t>(mine.size());
  if (!impl_->distributed) {
    impl_->local = mine;
    impl_->base = impl_->local.data();
    impl_->sizes = {my_size};
    return;
  }
  impl_->sizes.resize(static_cast<std::size_t>(n));
  check_mpi(MPI_Allgather(&my_size, 1, MPI_INT64_T, impl_->sizes.data(), 1, MPI_INT64_T, c),
            "MPI_Allgather");
  // Allocated by MPI, as SharedCounter's: reads then need nothing from the owner.
  check_mpi(MPI_Win_allocate(static_cast<MPI_Aint>(my_size), 1, MPI_INFO_NULL, c, &impl_->base,
                             &impl_->win),
            "MPI_Win_allocate");
  check_mpi(MPI_Win_set_errhandler(impl_->win, MPI_ERRORS_RETURN), "MPI_Win_set_errhandler");
  const int me = comm.rank();
  check_mpi(MPI_Win_lock(MPI_LOCK_EXCLUSIVE, me, 0, impl_->win), "MPI_Win_lock");
  if (my_size > 0) std::memcpy(impl_->base, mine.data(), mine.size());
  check_mpi(MPI_Win_unlock(me, impl_->win), "MPI_Win_unlock");
  // Nobody reads before every owner has written.
  check_mpi(MPI_Barrier(c), "MPI_Barrier");
}

SharedBytes::~SharedBytes() {
  // Collective; an error here cannot be thrown from a destructor and would end the run anyway.
  if (impl_->win != MPI_WIN_NULL) MPI_Win_free(&impl_->win);
}

std::vector<char> SharedBytes::read(int owner, std::int64_t offset, std::int64_t length) const {
  QSMESH_CHECK(owner >= 0 && owner < static_cast<int>(impl_->sizes.size()),
               "SharedBytes: no rank " << owner);
  QSMESH_CHECK(offset >= 0 && length >= 0 && offset + length <= impl_->sizes[owner],
               "SharedBytes: bytes [" << offset << ", " << offset + length << ") of rank " << owner
                                      << ", which has " << impl_->sizes[owner]);
  std::vector<char> out(static_cast<std::size_t>(length));
  if (length == 0) return out;
  if (!impl_->distributed) {
    std::memcpy(out.data(), impl_->base + offset, out.size());
    return out;
  }
  constexpr std::int64_t kChunk = std::int64_t{1} << 30;
  const std::lock_guard<std::mutex> guard(impl_->owner->lane);
  check_mpi(MPI_Win_lock(MPI_LOCK_SHARED, owner, 0, impl_->win), "MPI_Win_lock");
  for (std::int64_t off = 0; off < length; off += kChunk) {
    const int count = static_cast<int>(std::min(kChunk, length - off));
    const int code = MPI_Get(out.data() + off, count, MPI_CHAR, owner,
                             static_cast<MPI_Aint>(offset + off), count, MPI_CHAR, impl_->win);
    if (code != MPI_SUCCESS) {
      MPI_Win_unlock(owner, impl_->win);
      check_mpi(code, "MPI_Get");
    }
  }
  check_mpi(MPI_Win_unlock(owner, impl_->win), "MPI_Win_unlock");
  return out;
}

// RankHelpers: slot r of rank 0's window holds rank r's state, slot size() the ranks done.
namespace {
constexpr std::int64_t kBusy = 0, kFree = 1, kClaimed = 2;
constexpr int kTagShare = 1, kTagAnswer = 2;
}  // namespace

struct RankHelpers::Impl {
  MPI_Comm comm = MPI_COMM_NULL;  // a duplicate: the shares' tags meet no other message
  int rank = 0, size = 1;
  MPI_Win win = MPI_WIN_NULL;
  std::vector<MPI_Request> sends;

  std::int64_t fetch(std::int64_t value, int slot, MPI_Op op) {
    std::int64_t old = 0;
    check_mpi(MPI_Win_lock(MPI_LOCK_SHARED, 0, 0, win), "MPI_Win_lock");
    check_mpi(MPI_Fetch_and_op(&value, &old, MPI_INT64_T, 0, slot, op, win), "MPI_Fetch_and_op");
    check_mpi(MPI_Win_unlock(0, win), "MPI_Win_unlock");
    return old;
  }
};

RankHelpers::RankHelpers(const Comm& comm) : impl_(std::make_unique<Impl>()) {
  impl_->rank = comm.rank();
  impl_->size = comm.size();
  if (impl_->size == 1) return;
  check_mpi(MPI_Comm_dup(comm.impl_->comm, &impl_->comm), "MPI_Comm_dup");
  check_mpi(MPI_Comm_set_errhandler(impl_->comm, MPI_ERRORS_RETURN), "MPI_Comm_set_errhandler");
  // One state a rank, every rank busy, and the count of ranks done (kBusy too: none yet).
  impl_->win = allocate_rank0_window(impl_->comm, impl_->rank == 0,
                                     static_cast<MPI_Aint>(impl_->size + 1), kBusy);
}

RankHelpers::~RankHelpers() {
  // Collective; every rank left serve_until_all_done, so no share is in flight.
  if (impl_->win != MPI_WIN_NULL) MPI_Win_free(&impl_->win);
  if (impl_->comm != MPI_COMM_NULL) MPI_Comm_free(&impl_->comm);
}

int RankHelpers::rank() const { return impl_->rank; }
int RankHelpers::size() const { return impl_->size; }

std::vector<int> RankHelpers::claim(int wanted) {
  std::vector<int> got;
  if (impl_->size == 1) return got;
  // From the next rank on, so that owners do not all ask rank 0 first.
  for (int k = 1; k < impl_->size && static_cast<int>(got.size()) < wanted; ++k) {
    const int r = (impl_->rank + k) % impl_->size;
    if (impl_->fetch(kClaimed, r, MPI_REPLACE) == kFree) got.push_back(r);
  }
  return got;
}

void RankHelpers::send(int helper, const std::vector<char>& bytes) {
  QSMESH_CHECK(bytes.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max()),
               "helper share of " << bytes.size() << " bytes");
  MPI_Request request = MPI_REQUEST_NULL;
  check_mpi(MPI_Isend(bytes.data(), static_cast<int>(bytes.size()), MPI_BYTE, helper, kTagShare,
                      impl_->comm, &request),
            "MPI_Isend");
  impl_->sends.push_back(request);
}

void RankHelpers::wait_sent() {
  if (impl_->sends.empty()) return;
  check_mpi(
      MPI_Waitall(static_cast<int>(impl_->sends.size()), impl_->sends.data(), MPI_STATUSES_IGNORE),
      "MPI_Waitall");
  impl_->sends.clear();
}

namespace {
std::vector<char> receive_bytes(MPI_Comm comm, int from, int tag) {
  MPI_Status status;
  check_mpi(MPI_Probe(from, tag, comm, &status), "MPI_Probe");
  int count = 0;
  check_mpi(MPI_Get_count(&status, MPI_BYTE, &count), "MPI_Get_count");
  std::vector<char> bytes(static_cast<std::size_t>(count));
  check_mpi(
      MPI_Recv(bytes.data(), count, MPI_BYTE, status.MPI_SOURCE, tag, comm, MPI_STATUS_IGNORE),
      "MPI_Recv");
  return bytes;
}
}  // namespace

std::vector<char> RankHelpers::receive(int helper) {
  return receive_bytes(impl_->comm, helper, kTagAnswer);
}

void RankHelpers::serve_until_all_done(
    const std::function<std::vector<char>(const std::vector<char>&)>& serve) {
  if (impl_->size == 1) return;
  wait_sent();
  impl_->fetch(kFree, impl_->rank, MPI_REPLACE);
  impl_->fetch(1, impl_->size, MPI_SUM);
  // Polled, with a pause growing to 1 ms while nothing comes: a free rank should not take a core
  // from the ranks still working when ranks share cores.
  int idle = 0;
  for (;;) {
    int flag = 0;
    MPI_Status status;
    check_mpi(MPI_Iprobe(MPI_ANY_SOURCE, kTagShare, impl_->comm, &flag, &status), "MPI_Iprobe");
    if (flag != 0) {
      idle = 0;
      const int from = status.MPI_SOURCE;
      const std::vector<char> share = receive_bytes(impl_->comm, from, kTagShare);
      std::vector<char> answer;
      if (!share.empty()) answer = serve(share);
      // Free again before answering, so that the owner's next claim can find this rank.
      impl_->fetch(kFree, impl_->rank, MPI_REPLACE);
      QSMESH_CHECK(answer.size() <= static_cast<std::size_t>(std::numeric_limits<int>::max()),
                   "helper answer of " << answer.size() << " bytes");
      check_mpi(MPI_Send(answer.data(), static_cast<int>(answer.size()), MPI_BYTE, from, kTagAnswer,
                         impl_->comm),
                "MPI_Send");
      continue;
    }
    // Every rank done: no share can come any more (an owner counts itself done only after the
    // answers to all it sent).
    if (impl_->fetch(0, impl_->size, MPI_NO_OP) == impl_->size) break;
    std::this_thread::sleep_for(std::chrono::microseconds(std::min(1000, 20 << std::min(idle, 6))));
    ++idle;
  }
}

}  // namespace qsmesh::parallel
