// Critical trajectories of a holomorphic 1-form (paper 004 Sec. 4, "Quad-mesh generation").
#include <algorithm>
#include <cmath>

#include "qsmesh/core/error.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"

namespace qsmesh::holomorphic {
namespace {

using C = std::complex<double>;

double cross2(C a, C b) { return a.real() * b.imag() - a.imag() * b.real(); }

// The flat chart of triangle t: corner 0 at 0, the others by phi along its edges.
std::array<C, 3> chart(const PolyAnnulus& s, std::span<const C> phi, std::size_t t) {
  const auto& c = s.triangles[t];
  auto dir = [&](LO from, LO e) {
    return s.edges[static_cast<std::size_t>(e)][0] == from ? phi[static_cast<std::size_t>(e)]
                                                           : -phi[static_cast<std::size_t>(e)];
  };
  std::array<C, 3> z{};
  z[1] = dir(c[0], s.tri_edges[t][0]);
  z[2] = z[1] + dir(c[1], s.tri_edges[t][1]);
  return z;
}

int corner_of(const std::array<LO, 3>& c, LO v) {
  return static_cast<int>(std::find(c.begin(), c.end(), v) - c.begin());
}

}  // namespace

std::vector<Trajectory> critical_trajectories(const PolyAnnulus& s, std::span<const C> phi,
                                              const ZeroReport& zeros,
                                              const TraceOptions& options) {
  const std::size_t nt = s.triangles.size();
  std::vector<std::vector<LO>> vertex_tris(s.points.size());
  for (std::size_t t = 0; t < nt; ++t)
    for (const LO v : s.triangles[t])
      vertex_tris[static_cast<std::size_t>(v)].push_back(static_cast<LO>(t));
  // The neighbourhood of each zero: the triangles touching its vertex or its flipped triangle.
  std::vector<std::vector<LO>> hood(zeros.interior.size());
  std::vector<LO> zero_of(nt, kNoIndex);
  for (std::size_t z = 0; z < zeros.interior.size(); ++z) {
    const Zero& zero = zeros.interior[z];
    std::vector<LO> seeds;
    if (zero.vertex != kNoIndex)
      seeds.push_back(zero.vertex);
    else
      for (const LO v : s.triangles[static_cast<std::size_t>(zero.triangle)]) seeds.push_back(v);
    for (const LO v : seeds)
      for (const LO t : vertex_tris[static_cast<std::size_t>(v)])
        if (std::find(hood[z].begin(), hood[z].end(), t) == hood[z].end()) hood[z].push_back(t);
    std::sort(hood[z].begin(), hood[z].end());
    for (const LO t : hood[z])
      if (zero_of[static_cast<std::size_t>(t)] == kNoIndex)
        zero_of[static_cast<std::size_t>(t)] = static_cast<LO>(z);
  }

  std::vector<Trajectory> out;
  for (std::size_t z = 0; z < zeros.interior.size(); ++z) {
    const Zero& zero = zeros.interior[z];
    if (zero.order < 1) continue;
    const auto& H = hood[z];
    // Integrate phi over the neighbourhood (a disk), from the first triangle.
    std::vector<std::array<C, 3>> Z(H.size());
    std::vector<char> done(H.size(), 0);
    auto local = [&](LO t) {
      const auto it = std::lower_bound(H.begin(), H.end(), t);
      return it != H.end() && *it == t ? static_cast<std::size_t>(it - H.begin()) : H.size();
    };
    const std::size_t first = zero.triangle != kNoIndex ? local(zero.triangle) : 0;
    Z[first] = chart(s, phi, static_cast<std::size_t>(H[first]));
    done[first] = 1;
    std::vector<std::size_t> queue{first};
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::size_t i = queue[head];
      const auto t = static_cast<std::size_t>(H[i]);
      for (int k = 0; k < 3; ++k) {
        const auto& et = s.edge_tris[static_cast<std::size_t>(s.tri_edges[t][k])];
        const LO u = et[0] == static_cast<LO>(t) ? et[1] : et[0];
        if (u == kNoIndex) continue;
        const std::size_t j = local(u);
        if (j == H.size() || done[j] != 0) continue;
        const auto cu = chart(s, phi, static_cast<std::size_t>(u));
        const int ka = corner_of(s.triangles[static_cast<std::size_t>(u)], s.triangles[t][k]);
        const C shift = Z[i][k] - cu[static_cast<std::size_t>(ka)];
        for (int m = 0; m < 3; ++m) Z[j][m] = cu[m] + shift;
        done[j] = 1;
        queue.push_back(j);
      }
    }
    C centre;
    if (zero.vertex != kNoIndex) {
      centre = Z[0][static_cast<std::size_t>(
          corner_of(s.triangles[static_cast<std::size_t>(H[0])], zero.vertex))];
    } else {
      centre = (Z[first][0] + Z[first][1] + Z[first][2]) / 3.0;
    }
    // Crossings of the axes by the immersed boundary of the neighbourhood.
    for (std::size_t i = 0; i < H.size(); ++i) {
      const auto t = static_cast<std::size_t>(H[i]);
      for (int k = 0; k < 3; ++k) {
        const LO e = s.tri_edges[t][k];
        const auto& et = s.edge_tris[static_cast<std::size_t>(e)];
        const LO outside = et[0] == static_cast<LO>(t) ? et[1] : et[0];
        if (outside != kNoIndex && local(outside) != H.size()) continue;
        const C za = Z[i][k] - centre, zb = Z[i][(k + 1) % 3] - centre;
        for (const bool horizontal : {true, false}) {
          const double ya = horizontal ? za.imag() : za.real();
          const double yb = horizontal ? zb.imag() : zb.real();
          if ((ya >= 0) == (yb >= 0)) continue;
          const double w = ya / (ya - yb);
          const C zc = za + w * (zb - za);
          Trajectory tr;
          tr.zero = z;
          tr.horizontal = horizontal;
          const C d =
              horizontal ? C{zc.real() > 0 ? 1.0 : -1.0, 0} : C{0, zc.imag() > 0 ? 1.0 : -1.0};
          const LO a = s.triangles[t][k], b = s.triangles[t][(k + 1) % 3];
          tr.points.push_back(s.points[static_cast<std::size_t>(a)] * (1 - w) +
                              s.points[static_cast<std::size_t>(b)] * w);
          if (outside == kNoIndex) {
            tr.end = Trajectory::End::Boundary;
            tr.end_loop = s.edge_loop[static_cast<std::size_t>(e)];
            out.push_back(std::move(tr));
            continue;
          }
          // Trace: triangle u entered through the edge (a, b) at fraction w from a.
          LO u = outside;
          std::array<double, 3> bary{};
          int entry = 0;
          {
            const auto& cu = s.triangles[static_cast<std::size_t>(u)];
            const int ia = corner_of(cu, a), ib = corner_of(cu, b);
            bary[static_cast<std::size_t>(ia)] = 1 - w;
            bary[static_cast<std::size_t>(ib)] = w;
            entry = (ib == (ia + 1) % 3) ? ia : ib;  // edge index joining them
          }
          for (int step = 0; step < options.max_steps; ++step) {
            if (zero_of[static_cast<std::size_t>(u)] != kNoIndex &&
                (zero_of[static_cast<std::size_t>(u)] != static_cast<LO>(z) || step > 0)) {
              tr.end = Trajectory::End::Zero;
              tr.end_zero = static_cast<std::size_t>(zero_of[static_cast<std::size_t>(u)]);
              break;
            }
            const auto zu = chart(s, phi, static_cast<std::size_t>(u));
            const C p = bary[0] * zu[0] + bary[1] * zu[1] + bary[2] * zu[2];
            int exit = -1;
            double best_s = 1e300, exit_r = 0;
            for (int j = 0; j < 3; ++j) {
              if (j == entry) continue;
              const C E = zu[(j + 1) % 3] - zu[j];
              const double den = cross2(d, E);
              if (den == 0) continue;
              const double sj = cross2(zu[j] - p, E) / den;
              const double rj = cross2(zu[j] - p, d) / den;
              if (sj > 0 && rj >= -1e-9 && rj <= 1 + 1e-9 && sj < best_s) {
                best_s = sj;
                exit = j;
                exit_r = std::clamp(rj, 0.0, 1.0);
              }
            }
            if (exit < 0) break;  // degenerate chart: End::Limit
            const auto& cu = s.triangles[static_cast<std::size_t>(u)];
            const LO ea = cu[exit], eb = cu[(exit + 1) % 3];
            tr.points.push_back(s.points[static_cast<std::size_t>(ea)] * (1 - exit_r) +
                                s.points[static_cast<std::size_t>(eb)] * exit_r);
            const LO e2 = s.tri_edges[static_cast<std::size_t>(u)][exit];
            const auto& et2 = s.edge_tris[static_cast<std::size_t>(e2)];
            const LO next = et2[0] == u ? et2[1] : et2[0];
            if (next == kNoIndex) {
              tr.end = Trajectory::End::Boundary;
              tr.end_loop = s.edge_loop[static_cast<std::size_t>(e2)];
              break;
            }
            const auto& cn = s.triangles[static_cast<std::size_t>(next)];
            const int ia = corner_of(cn, ea), ib = corner_of(cn, eb);
            bary = {0, 0, 0};
            bary[static_cast<std::size_t>(ia)] = 1 - exit_r;
            bary[static_cast<std::size_t>(ib)] = exit_r;
            entry = (ib == (ia + 1) % 3) ? ia : ib;
            u = next;
          }
          out.push_back(std::move(tr));
        }
      }
    }
  }
  return out;
}

}  // namespace qsmesh::holomorphic
