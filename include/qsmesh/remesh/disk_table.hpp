// The table of disk quadrangulations (paper 000 Sec. 6.3.1): every quad mesh of a disk with at most
// 12 boundary and 4 interior vertices, interior valences 3..5 and boundary valences 1..3, one per
// isomorphism class. Written by the tool qsmesh_gen_disk_quads (src/remesh/tools, nauty canonical
// labelling) into data/disk_quadrangulations.txt and embedded in the library at build time.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "qsmesh/core/types.hpp"

namespace qsmesh::remesh {

/// Disk quadrangulations over flat arrays. In entry i, local vertices 0..b-1 are the boundary in
/// counter-clockwise order and b..b+n-1 the interior ones; quads are counter-clockwise, and there
/// are b/2 + n - 1 of them (Euler). Rotations and reflections of an entry are not stored.
class DiskQuadTable {
 public:
  /// The table embedded at build time (parsed on each call: keep the object, it is ~800 entries).
  [[nodiscard]] static DiskQuadTable builtin();
  /// Parses the text format of data/disk_quadrangulations.txt ('#' comment lines, then one entry
  /// per line: b n and the quads' local vertex ids). Throws qsmesh::Error on a malformed entry
  /// (wrong quad count, id out of range, boundary edges not forming the cycle 0..b-1).
  [[nodiscard]] static DiskQuadTable parse(std::string_view text);

  [[nodiscard]] LO size() const { return static_cast<LO>(boundary_.size()); }
  [[nodiscard]] int boundary_size(LO i) const { return boundary_[i]; }
  [[nodiscard]] int interior_size(LO i) const { return interior_[i]; }
  [[nodiscard]] std::span<const std::array<std::uint8_t, 4>> quads(LO i) const {
    return {quads_.data() + quad_offset_[i], quads_.data() + quad_offset_[i + 1]};
  }
  /// Quad valence of each local vertex of entry i (boundary first, then interior).
  [[nodiscard]] std::span<const std::uint8_t> valences(LO i) const {
    return {valence_.data() + vertex_offset_[i], valence_.data() + vertex_offset_[i + 1]};
  }
  /// Entries with b boundary vertices, in table order (empty when b is odd or out of range).
  [[nodiscard]] std::span<const LO> with_boundary(int b) const;
  /// Number of entries with b boundary and n interior vertices.
  [[nodiscard]] LO count(int b, int n) const;
  /// Largest boundary size in the table.
  [[nodiscard]] int max_boundary() const { return max_boundary_; }

 private:
  std::vector<std::uint8_t> boundary_, interior_;
  std::vector<LO> quad_offset_{0}, vertex_offset_{0};
  std::vector<std::array<std::uint8_t, 4>> quads_;
  std::vector<std::uint8_t> valence_;
  std::vector<LO> by_boundary_;         ///< entry ids sorted by b (stable)
  std::vector<LO> by_boundary_offset_;  ///< CSR offsets over b = 0..max_boundary_
  int max_boundary_ = 0;
};

}  // namespace qsmesh::remesh
