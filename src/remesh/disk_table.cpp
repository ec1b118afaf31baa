#include "qsmesh/remesh/disk_table.hpp"

#include <algorithm>
#include <charconv>
#include <map>
#include <utility>

#include "qsmesh/core/error.hpp"

namespace qsmesh::remesh {

namespace detail {
extern const std::string_view kDiskTableText;  // generated from data/disk_quadrangulations.txt
}

DiskQuadTable DiskQuadTable::builtin() { return parse(detail::kDiskTableText); }

namespace {

// Integers of one line; false on anything that is not a non-negative integer.
bool read_ints(std::string_view line, std::vector<int>& out) {
  out.clear();
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i == line.size()) break;
    int value = 0;
    const auto [end, ec] = std::from_chars(line.data() + i, line.data() + line.size(), value);
    if (ec != std::errc() || value < 0) return false;
    out.push_back(value);
    i = static_cast<std::size_t>(end - line.data());
  }
  return true;
}

}  // namespace

DiskQuadTable DiskQuadTable::parse(std::string_view text) {
  DiskQuadTable t;
  std::vector<int> v;
  std::size_t line_no = 0;
  while (!text.empty()) {
    const std::size_t eol = text.find('\n');
    const std::string_view line = text.substr(0, eol);
    text = eol == std::string_view::npos ? std::string_view{} : text.substr(eol + 1);
    ++line_no;
    if (line.empty() || line[0] == '#') continue;
    QSMESH_CHECK(read_ints(line, v), "disk table line " << line_no << ": not a list of integers");
    if (v.empty()) continue;
    QSMESH_CHECK(v.size() >= 2, "disk table line " << line_no << ": no b n");
    const int b = v[0], n = v[1];
    QSMESH_CHECK(b >= 4 && b % 2 == 0 && b < 64 && n < 64,
                 "disk table line " << line_no << ": bad sizes b=" << b << " n=" << n);
    const int nq = b / 2 + n - 1, nv = b + n;
    QSMESH_CHECK(static_cast<int>(v.size()) == 2 + 4 * nq,
                 "disk table line " << line_no << ": expected " << nq << " quads");
    std::vector<std::uint8_t> val(nv, 0);
    // Directed edges: an interior edge appears in both directions, a boundary edge once, and the
    // boundary edges must be exactly i -> i+1 (the counter-clockwise cycle 0..b-1).
    std::map<std::pair<int, int>, int> directed;
    for (int q = 0; q < nq; ++q) {
      std::array<std::uint8_t, 4> quad{};
      for (int k = 0; k < 4; ++k) {
        const int id = v[2 + 4 * q + k];
        QSMESH_CHECK(id < nv, "disk table line " << line_no << ": vertex id " << id);
        quad[k] = static_cast<std::uint8_t>(id);
        ++val[id];
      }
      for (int k = 0; k < 4; ++k) ++directed[{quad[k], quad[(k + 1) % 4]}];
      t.quads_.push_back(quad);
    }
    int boundary_edges = 0;
    for (const auto& [e, c] : directed) {
      QSMESH_CHECK(c == 1, "disk table line " << line_no << ": edge used twice in one direction");
      if (directed.count({e.second, e.first}) == 0) {
        QSMESH_CHECK(e.first < b && e.second == (e.first + 1) % b,
                     "disk table line " << line_no << ": boundary is not the cycle 0..b-1");
        ++boundary_edges;
      }
    }
    QSMESH_CHECK(boundary_edges == b, "disk table line " << line_no << ": " << boundary_edges
                                                         << " boundary edges for b=" << b);
    t.boundary_.push_back(static_cast<std::uint8_t>(b));
    t.interior_.push_back(static_cast<std::uint8_t>(n));
    t.quad_offset_.push_back(static_cast<LO>(t.quads_.size()));
    t.valence_.insert(t.valence_.end(), val.begin(), val.end());
    t.vertex_offset_.push_back(static_cast<LO>(t.valence_.size()));
    t.max_boundary_ = std::max(t.max_boundary_, b);
  }
  t.by_boundary_.resize(t.boundary_.size());
  for (LO i = 0; i < t.size(); ++i) t.by_boundary_[i] = i;
  std::stable_sort(t.by_boundary_.begin(), t.by_boundary_.end(),
                   [&](LO a, LO c) { return t.boundary_[a] < t.boundary_[c]; });
  t.by_boundary_offset_.assign(t.max_boundary_ + 2, 0);
  for (LO i = 0; i < t.size(); ++i) ++t.by_boundary_offset_[t.boundary_[i] + 1];
  for (int b = 0; b <= t.max_boundary_; ++b)
    t.by_boundary_offset_[b + 1] += t.by_boundary_offset_[b];
  return t;
}

std::span<const LO> DiskQuadTable::with_boundary(int b) const {
  if (b < 0 || b > max_boundary_) return {};
  return {by_boundary_.data() + by_boundary_offset_[b],
          by_boundary_.data() + by_boundary_offset_[b + 1]};
}

LO DiskQuadTable::count(int b, int n) const {
  LO c = 0;
  for (LO i : with_boundary(b))
    if (interior_[i] == n) ++c;
  return c;
}

}  // namespace qsmesh::remesh
