// Sec. 3.2: singularities of the CR cross field and the Euler relation (Sec. 1.3, Eq. 2).
//
// The rotation of the cross is measured on the cells of the medial subdivision of the glued mesh:
// each vertex has the cell bounded by the segments joining the midpoints of its incident edges,
// each triangle the small triangle joining its three edge midpoints. Inside a triangle the
// difference of two edge crosses is the paper's diff operator (Eq. after 8: frames rotated by the
// angle between the edges, the 4-symmetry removed by wrapping 4Δθ into (-π, π]). Summed around a
// vertex cell it is the rotation of the cross against the triangle frames; adding 4 × the angle
// defect turns it into the rotation against parallel transport, so smooth curved surfaces get index
// 0. Every cell index is an exact integer and their sum with the boundary indices is 4χ (discrete
// Gauss-Bonnet).
#include <algorithm>
#include <cmath>

#include "internal.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::crossfield::detail {

namespace {

// The index of every cell of the medial subdivision: vertex cells (0 at boundary vertices), then
// triangle cells, and the field's boundary term summed over the boundary vertices.
struct CellIndices {
  std::vector<int> vertex, triangle;
  int field_boundary = 0;
};

CellIndices cell_indices(const FaceCrossField& cf, const Geometry& g) {
  const LO nv = static_cast<LO>(cf.points.size()), nt = static_cast<LO>(cf.triangles.size());
  CellIndices out;
  std::vector<double> S(static_cast<std::size_t>(nv), 0.0);
  out.triangle.assign(static_cast<std::size_t>(nt), 0);
  for (LO t = 0; t < nt; ++t) {
    double sum = 0;
    const double angle[3] = {angle_in_triangle(cf, g, t, 0), angle_in_triangle(cf, g, t, 1),
                             angle_in_triangle(cf, g, t, 2)};
    for (int m = 0; m < 3; ++m) {
      // At vertex m, counterclockwise around the normal: from edge (m, m+1) to edge (m+2, m).
      const double d = wrap_angle(angle[(m + 2) % 3] - angle[m]);
      S[cf.triangles[t][m]] += d;
      sum += d;
    }
    // The midpoint triangle is walked clockwise by the vertex cells around it.
    out.triangle[t] = -static_cast<int>(std::lround(sum / (2 * kPi)));
  }
  out.vertex.assign(static_cast<std::size_t>(nv), 0);
  for (LO v = 0; v < nv; ++v) {
    if (g.boundary_vertex[v]) {
      out.field_boundary +=
          static_cast<int>(std::lround(2 + (S[v] - 4 * g.vertex_angle[v]) / (2 * kPi)));
    } else {
      out.vertex[v] =
          static_cast<int>(std::lround((S[v] + 4 * (2 * kPi - g.vertex_angle[v])) / (2 * kPi)));
    }
  }
  return out;
}

bool any_nonzero(const std::vector<int>& index) {
  return std::any_of(index.begin(), index.end(), [](int k) { return k != 0; });
}

}  // namespace

bool has_singular_cell(const FaceCrossField& cf, const Geometry& g) {
  const CellIndices cells = cell_indices(cf, g);
  return any_nonzero(cells.vertex) || any_nonzero(cells.triangle);
}

void find_singularities(FaceCrossField& cf, const Geometry& g, const CrossFieldOptions& options) {
  const LO nv = static_cast<LO>(cf.points.size()), nt = static_cast<LO>(cf.triangles.size());
  const CellIndices cells = cell_indices(cf, g);
  const std::vector<int>& vert_index = cells.vertex;
  const std::vector<int>& tri_index = cells.triangle;
  const int field_boundary = cells.field_boundary;

  // Group singular cells touching each other (vertex-vertex by an edge, vertex-triangle by
  // incidence, triangle-triangle by an edge); a group whose indices sum to ±1 is one singularity.
  // The triangles around each vertex, built only when some cell is singular (most faces of a CAD
  // model have no singularity at all).
  const bool any_singular = any_nonzero(vert_index) || any_nonzero(tri_index);
  std::vector<std::vector<LO>> v2t(any_singular ? static_cast<std::size_t>(nv) : 0);
  if (any_singular)
    for (LO t = 0; t < nt; ++t)
      for (LO v : cf.triangles[t]) v2t[v].push_back(t);
  const auto cell_index = [&](LO c) { return c < nv ? vert_index[c] : tri_index[c - nv]; };
  std::vector<std::uint8_t> seen(any_singular ? static_cast<std::size_t>(nv + nt) : 0, 0);
  cf.singularities.clear();
  for (LO c0 = 0; any_singular && c0 < nv + nt; ++c0) {
    if (seen[c0] || cell_index(c0) == 0) continue;
    std::vector<LO> group{c0};
    seen[c0] = 1;
    for (std::size_t q = 0; q < group.size(); ++q) {
      const LO c = group[q];
      std::vector<LO> nb;
      if (c < nv) {
        for (LO t : v2t[c]) {
          nb.push_back(nv + t);
          for (LO w : cf.triangles[t]) nb.push_back(w);
        }
      } else {
        const LO t = c - nv;
        for (LO w : cf.triangles[t]) nb.push_back(w);
        for (LO e : cf.tri2edges[t])
          for (LO s : g.edge2tris[e])
            if (s != kNoIndex) nb.push_back(nv + s);
      }
      for (LO d : nb)
        if (!seen[d] && cell_index(d) != 0) {
          seen[d] = 1;
          group.push_back(d);
        }
    }
    std::sort(group.begin(), group.end());
    int sum = 0;
    Vec3 centre{0, 0, 0};
    for (LO c : group) {
      sum += cell_index(c);
      if (c < nv)
        centre += cf.points[c];
      else {
        const auto& tri = cf.triangles[c - nv];
        centre += (cf.points[tri[0]] + cf.points[tri[1]] + cf.points[tri[2]]) / 3.0;
      }
    }
    centre = centre / double(group.size());
    if (sum == 0) {
      ++cf.stats.dropped_pairs;
      continue;
    }
    if (std::abs(sum) == 1) {
      Singularity s;
      s.position = centre;
      s.index = sum;
      if (group.size() == 1 && group[0] < nv) {
        s.where = Singularity::Where::Vertex;
        s.element = group[0];
      } else if (group.size() == 1) {
        s.where = Singularity::Where::Triangle;
        s.element = group[0] - nv;
      } else if (group.size() == 2 && group[1] < nv) {
        // Two vertices joined by an edge: the singularity sits on that edge.
        s.where = Singularity::Where::Edge;
        for (LO t : v2t[group[0]])
          for (LO e : cf.tri2edges[t])
            if ((cf.edges[e][0] == group[0] && cf.edges[e][1] == group[1]) ||
                (cf.edges[e][0] == group[1] && cf.edges[e][1] == group[0]))
              s.element = e;
      } else {
        // Spread over several cells: the triangle nearest the centre of the group carries it.
        s.where = Singularity::Where::Triangle;
        double best = 1e300;
        for (LO c : group)
          for (LO t : (c < nv ? v2t[c] : std::vector<LO>{c - nv})) {
            const auto& tri = cf.triangles[t];
            const double d =
                distance(centre, (cf.points[tri[0]] + cf.points[tri[1]] + cf.points[tri[2]]) / 3.0);
            if (d < best) best = d, s.element = t;
          }
      }
      cf.singularities.push_back(s);
      continue;
    }
    // |sum| >= 2: keep the total, one ±1 singularity per unit at each non-zero cell.
    for (LO c : group) {
      const int k = cell_index(c);
      if (std::abs(k) >= 2) ++cf.stats.high_index_cells;
      for (int r = 0; r < std::abs(k); ++r) {
        Singularity s;
        s.index = k > 0 ? 1 : -1;
        if (c < nv)
          s.position = cf.points[c], s.where = Singularity::Where::Vertex, s.element = c;
        else {
          const auto& tri = cf.triangles[c - nv];
          s.position = (cf.points[tri[0]] + cf.points[tri[1]] + cf.points[tri[2]]) / 3.0;
          s.where = Singularity::Where::Triangle;
          s.element = c - nv;
        }
        cf.singularities.push_back(s);
      }
    }
  }

  // Eq. 2 with the CAD corners; acute corners count as valence 1 plus an artificial +1 singularity.
  EulerCheck& eu = cf.euler;
  eu.chi = nv - static_cast<int>(cf.edges.size()) + nt;
  eu.corner_term = 0;
  for (LO v = 0; v < nv; ++v) {
    if (cf.vertex_dim[v] != 0 || !g.boundary_vertex[v]) continue;
    const double deg = g.vertex_angle[v] * 180 / kPi;
    if (deg < options.acute_corner_deg) {
      eu.corner_term += 1;
      cf.singularities.push_back({cf.points[v], 1, Singularity::Where::AcuteCorner, v});
    } else {
      eu.corner_term += 2 - static_cast<int>(std::lround(deg / 90));
    }
  }
  eu.expected = 4 * eu.chi - eu.corner_term;
  eu.found = 0;
  for (const auto& s : cf.singularities) eu.found += s.index;
  eu.consistent = eu.found == eu.expected;
  eu.field_boundary_term = field_boundary;
}

}  // namespace qsmesh::crossfield::detail
