// The one exchange of per-face records between ranks (src/parallel only): records keyed by face
// go to the rank that owns the face. What a record holds is declared once by its type's fields()
// (qsmesh/parallel/record.hpp); nothing here names a field.
#pragma once

#include <utility>
#include <vector>

#include "qsmesh/core/types.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/record.hpp"

namespace qsmesh::parallel {

/// Records of type R on their way to the ranks owning their faces.
template <class R>
class ToOwners {
 public:
  explicit ToOwners(int nranks) : outgoing_(static_cast<std::size_t>(nranks)) {}
  /// Packs (face, record) for rank `owner`.
  void add(int owner, LO face, const R& record) {
    std::vector<char>& out = outgoing_.at(static_cast<std::size_t>(owner));
    write_record(out, face);
    write_record(out, record);
  }
  /// Collective (Comm::alltoall_bytes; nothing on one rank, where no record needs to move):
  /// sends what was added, then calls receive(face, R&&) for every record sent to this rank, in
  /// the order of the senders' ranks and, per sender, of add().
  template <class F>
  void deliver(const Comm& comm, F&& receive) {
    if (comm.size() == 1) return;
    const std::vector<std::vector<char>> incoming = comm.alltoall_bytes(outgoing_);
    outgoing_ = {};
    for (const std::vector<char>& bytes : incoming) {
      std::size_t pos = 0;
      while (pos < bytes.size()) {
        LO face = kNoIndex;
        read_record(bytes, pos, face);
        R record;
        read_record(bytes, pos, record);
        receive(face, std::move(record));
      }
    }
  }

 private:
  std::vector<std::vector<char>> outgoing_;
};

}  // namespace qsmesh::parallel
