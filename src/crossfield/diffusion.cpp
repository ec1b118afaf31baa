// Sec. 3.1: Crouzeix-Raviart cross field, boundary-condition extension and Algorithm 1.
//
// One unknown pair (cos 4θ, sin 4θ) per edge, θ measured from the edge's own direction. Inside a
// triangle every edge direction lies in the triangle's plane, so the crosses of two edges of the
// triangle are compared after rotating by 4 times the angle between their directions: the CR
// stiffness couples edges i and j of a triangle by K_ij R(4(φ_j - φ_i)). Across an edge the two
// triangles share the edge direction, which is the discrete parallel transport of the surface; on a
// curved face the holonomy around a vertex is its angle defect, as it should be.
#include <algorithm>
#include <cmath>

#include "internal.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::crossfield::detail {
namespace {

// The cross field's systems are the real form of complex Hermitian ones (each edge's two
// unknowns are the real and imaginary parts of its representation vector, and the connection
// couples them by rotations): factorized as complex, they cost less (linalg::SolverOptions).
linalg::SolverOptions pair_solver(linalg::SolverOptions options) {
  options.complex_pairs = true;
  return options;
}

/// CR stiffness of the triangles selected by `use`, on the n unknowns edge2unk (2 per edge,
/// kNoIndex: Dirichlet). Returns the free-free matrix and adds -K_fd u_d to `coupling`.
linalg::SparseMatrix assemble_stiffness(const FaceCrossField& cf, const Geometry& g,
                                        const std::vector<std::uint8_t>& use,
                                        const std::vector<LO>& edge2unk, LO n,
                                        std::vector<double>& coupling) {
  // One element a triangle: its three edges' unknown pairs and their 6 x 6 block.
  constexpr int kDofs = 6;
  const auto used = static_cast<std::size_t>(std::count(use.begin(), use.end(), 1));
  std::vector<LO> dofs;
  std::vector<double> blocks;
  dofs.reserve(used * kDofs);
  blocks.reserve(used * kDofs * kDofs);
  for (std::size_t t = 0; t < cf.triangles.size(); ++t) {
    if (!use[t]) continue;
    // Edge k of the triangle joins vertices k and k+1: it is opposite vertex k+2. The CR basis
    // function of the edge opposite vertex m is 1 - 2 λ_m, so K = 4 × (P1 stiffness): off-diagonal
    // -2 cot(third angle), diagonal 2 (cot + cot) of the two angles at the edge's ends.
    double K[3][3];
    for (int i = 0; i < 3; ++i) {
      const int oi = (i + 2) % 3;  // vertex opposite edge i
      for (int j = 0; j < 3; ++j) {
        const int oj = (j + 2) % 3;
        if (i == j)
          K[i][j] = 2 * (g.cot[t][(oi + 1) % 3] + g.cot[t][(oi + 2) % 3]);
        else
          K[i][j] = -2 * g.cot[t][3 - oi - oj];
      }
    }
    for (int i = 0; i < 3; ++i) {
      const LO ui = edge2unk[cf.tri2edges[t][i]];
      dofs.push_back(ui);
      dofs.push_back(ui == kNoIndex ? kNoIndex : ui + 1);
    }
    const std::size_t block = blocks.size();
    blocks.resize(block + static_cast<std::size_t>(kDofs) * kDofs, 0.0);
    for (int i = 0; i < 3; ++i) {
      const LO ui = edge2unk[cf.tri2edges[t][i]];
      if (ui == kNoIndex) continue;
      for (int j = 0; j < 3; ++j) {
        const LO ej = cf.tri2edges[t][j];
        const double beta = 4 * (g.phi[t][j] - g.phi[t][i]);
        const double c = std::cos(beta) * K[i][j], s = std::sin(beta) * K[i][j];
        const double B[2][2] = {{c, -s}, {s, c}};
        if (edge2unk[ej] != kNoIndex) {
          for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b)
              blocks[block + static_cast<std::size_t>((2 * i + a) * kDofs + 2 * j + b)] = B[a][b];
        } else {
          const Vec2& d = cf.u[ej];
          coupling[ui] -= B[0][0] * d.u + B[0][1] * d.v;
          coupling[ui + 1] -= B[1][0] * d.u + B[1][1] * d.v;
        }
      }
    }
  }
  return linalg::SparseMatrix::from_elements(n, kDofs, dofs, blocks);
}

/// Lumped CR mass (|t1| + |t2|) / 3 of each edge.
std::vector<double> edge_mass(const FaceCrossField& cf, const Geometry& g) {
  std::vector<double> m(cf.edges.size(), 0.0);
  for (std::size_t t = 0; t < cf.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) m[cf.tri2edges[t][k]] += g.area[t] / 3;
  return m;
}

Vec2 project(const Vec2& x, const Vec2& fallback) {
  const double n = norm(x);
  return n > 1e-14 ? x / n : fallback;
}

// The two measures of level_change, accumulated pair by pair in the pairs' order.
struct ChangeSum {
  double max = 0, sum = 0, total = 0;
  void add(double du, double dv, double mass) {
    max = std::max(max, std::max(std::abs(du), std::abs(dv)));
    sum += mass * (du * du + dv * dv);
    total += mass;
  }
  [[nodiscard]] double value(LevelChange how) const {
    if (how == LevelChange::Max) return max;
    return total > 0 ? std::sqrt(sum / total) : 0.0;
  }
};

/// Boundary-condition extension: the crosses of the triangles touching the boundary are fixed to
/// the solution of the CR Laplace equation on that one-triangle layer with the boundary crosses as
/// data.
void extend_boundary_conditions(FaceCrossField& cf, const Geometry& g,
                                const CrossFieldOptions& options, linalg::SolverLane* lane,
                                const std::vector<double>& mass) {
  const std::size_t nt = cf.triangles.size(), ne = cf.edges.size();
  std::vector<std::uint8_t> layer(nt, 0);
  for (std::size_t t = 0; t < nt; ++t)
    for (LO v : cf.triangles[t])
      if (g.boundary_vertex[v]) layer[t] = 1;
  std::vector<LO> edge2unk(ne, kNoIndex);
  LO n = 0;
  for (std::size_t t = 0; t < nt; ++t) {
    if (!layer[t]) continue;
    for (LO e : cf.tri2edges[t])
      if (!cf.boundary_edge[e] && edge2unk[e] == kNoIndex) {
        edge2unk[e] = n;
        n += 2;
      }
  }
  if (n == 0) return;
  std::vector<double> rhs(static_cast<std::size_t>(n), 0.0);
  linalg::SparseMatrix A = assemble_stiffness(cf, g, layer, edge2unk, n, rhs);
  // A vanishing mass term keeps the system definite should a layer triangle be degenerate.
  const double eps = 1e-10 / (g.min_edge * g.min_edge);
  for (std::size_t e = 0; e < ne; ++e)
    if (const LO i = edge2unk[e]; i != kNoIndex)
      for (int a = 0; a < 2; ++a) A.values()[A.find(i + a, i + a)] += eps * mass[e];
  auto solver = linalg::make_solver(n, pair_solver(options.solver), lane);
  solver->analyze(A);
  solver->factorize(A);
  std::vector<double> x(static_cast<std::size_t>(n));
  solver->solve(rhs, x);
  ++cf.stats.extension_solves;
  for (std::size_t e = 0; e < ne; ++e) {
    const LO i = edge2unk[e];
    if (i == kNoIndex) continue;
    const Vec2 raw{x[i], x[i + 1]};
    cf.u_norm[e] = norm(raw);
    cf.u[e] = project(raw, Vec2{1, 0});
    cf.fixed_edge[e] = 1;
  }
}

}  // namespace

void diffuse(FaceCrossField& cf, const Geometry& g, const CrossFieldOptions& options,
             linalg::SolverLane* lane) {
  QSMESH_CHECK(options.levels >= 1, "crossfield: levels must be >= 1");
  const std::size_t ne = cf.edges.size(), nt = cf.triangles.size();
  cf.u.assign(ne, Vec2{1, 0});
  cf.u_norm.assign(ne, 1.0);
  cf.fixed_edge.assign(ne, 0);
  bool has_boundary = false;
  for (std::size_t e = 0; e < ne; ++e)
    if (cf.boundary_edge[e]) cf.fixed_edge[e] = 1, has_boundary = true;

  const auto mass = edge_mass(cf, g);
  if (options.extend_boundary && has_boundary)
    extend_boundary_conditions(cf, g, options, lane, mass);

  if (!has_boundary) {
    // Closed surface: no boundary to diffuse, start from one fixed direction seen in each edge
    // frame.
    const Vec3 dir = normalized(Vec3{1.0, 0.31, 0.17});
    for (std::size_t e = 0; e < ne; ++e) {
      const LO t = g.edge2tris[e][0];
      const Vec3 d = normalized(cf.points[cf.edges[e][1]] - cf.points[cf.edges[e][0]]);
      const double b = std::atan2(dot(dir, cross(g.normal[t], d)), dot(dir, d));
      cf.u[e] = {std::cos(4 * b), std::sin(4 * b)};
    }
  }

  std::vector<LO> edge2unk(ne, kNoIndex);
  LO n = 0;
  for (std::size_t e = 0; e < ne; ++e)
    if (!cf.fixed_edge[e]) {
      edge2unk[e] = n;
      n += 2;
    }
  if (n == 0) return;  // every edge is fixed: nothing to diffuse

  std::vector<double> coupling(static_cast<std::size_t>(n), 0.0);
  // Every unknown edge lies in a triangle, so the diagonal is in K's pattern. A level's matrix
  // K + M / α differs from K on the diagonal only: A is K, and a level rewrites its diagonal.
  linalg::SparseMatrix A =
      assemble_stiffness(cf, g, std::vector<std::uint8_t>(nt, 1), edge2unk, n, coupling);
  std::vector<double> mfree(static_cast<std::size_t>(n));
  std::vector<std::int64_t> diag(static_cast<std::size_t>(n));
  std::vector<double> k_diag(static_cast<std::size_t>(n));
  for (std::size_t e = 0; e < ne; ++e)
    if (const LO i = edge2unk[e]; i != kNoIndex)
      for (int a = 0; a < 2; ++a) {
        mfree[i + a] = mass[e];
        diag[i + a] = A.find(i + a, i + a);
        k_diag[i + a] = A.values()[static_cast<std::size_t>(diag[i + a])];
      }

  // α from (0.1 d)^2 down to (3 h_min)^2, linearly (Algorithm 1).
  const double a0 = std::pow(0.1 * g.diagonal, 2);
  const double a1 = std::min(a0, std::pow(3 * g.min_edge, 2));
  auto solver = linalg::make_solver(n, pair_solver(options.solver), lane);
  cf.stats.solver = solver->name();
  solver->analyze(A);

  std::vector<double> U(static_cast<std::size_t>(n)), X(U.size()), rhs(U.size());
  for (std::size_t e = 0; e < ne; ++e)
    if (const LO i = edge2unk[e]; i != kNoIndex) {
      // Surfaces with a boundary start from zero: the first solve diffuses the boundary crosses.
      U[i] = has_boundary ? 0.0 : cf.u[e].u;
      U[i + 1] = has_boundary ? 0.0 : cf.u[e].v;
    }
  std::vector<double> pair_mass(U.size() / 2), m_alpha(U.size());
  std::vector<double> rms;  // the level's RMS changes, for the stall rule
  for (std::size_t k = 0; k < pair_mass.size(); ++k) pair_mass[k] = mfree[2 * k];
  // Whether the crosses U have a singularity inside the face: U's pairs written into cf.u, which
  // the end of the diffusion overwrites anyway.
  const auto singular_inside = [&](const std::vector<double>& crosses) {
    for (std::size_t e = 0; e < ne; ++e)
      if (const LO i = edge2unk[e]; i != kNoIndex) cf.u[e] = {crosses[i], crosses[i + 1]};
    return has_singular_cell(cf, g);
  };
  for (int level = 0; level < options.levels; ++level) {
    const double alpha =
        options.levels == 1 ? a1 : a0 + (a1 - a0) * double(level) / double(options.levels - 1);
    // M / α once a level: the same quotients the loops below would divide out every iteration.
    for (LO i = 0; i < n; ++i) m_alpha[i] = mfree[i] / alpha;
    for (LO i = 0; i < n; ++i) A.values()[diag[i]] = k_diag[i] + m_alpha[i];
    solver->factorize(A);
    ++cf.stats.factorizations;
    int it = 0;
    double change = 1e300;
    rms.clear();
    while (change >= options.tolerance && it < options.max_iterations_per_level) {
      for (LO i = 0; i < n; ++i) rhs[i] = m_alpha[i] * U[i] + coupling[i];
      solver->solve(rhs, X);
      ++cf.stats.solves;
      ++it;
      // The projection and level_change's two measures in one pass.
      ChangeSum moved;
      for (LO i = 0; i < n; i += 2) {
        const Vec2 p = project({X[i], X[i + 1]}, Vec2{U[i], U[i + 1]});
        moved.add(p.u - U[i], p.v - U[i + 1], pair_mass[static_cast<std::size_t>(i / 2)]);
        U[i] = p.u;
        U[i + 1] = p.v;
      }
      change = moved.value(options.level_change);
      if (options.stall_window > 0) {
        rms.push_back(moved.value(LevelChange::Rms));
        if (change >= options.tolerance &&
            level_stalled(rms, options.stall_window, options.stall_ratio)) {
          ++cf.stats.stalled_levels;
          break;
        }
      }
    }
    cf.stats.iterations_per_level.push_back(it);
    ++cf.stats.levels;
    if (change < options.tolerance && it <= options.settled_level_iterations &&
        level + 2 < options.levels) {
      // A regular field set by its boundary: the levels left would keep it.
      if (options.settled_regular_ends && !singular_inside(U)) break;
      level = options.levels - 2;  // the loop's increment makes it the last level
    }
  }
  for (std::size_t e = 0; e < ne; ++e)
    if (const LO i = edge2unk[e]; i != kNoIndex) {
      cf.u[e] = {U[i], U[i + 1]};
      cf.u_norm[e] = std::hypot(X[i], X[i + 1]);
      QSMESH_CHECK(std::isfinite(cf.u[e].u) && std::isfinite(cf.u[e].v),
                   "crossfield: face " << cf.face << ": non-finite cross at edge " << e);
    }
}

}  // namespace qsmesh::crossfield::detail

namespace qsmesh::crossfield {

bool level_stalled(std::span<const double> rms, int window, double ratio) {
  if (window <= 0 || rms.size() <= static_cast<std::size_t>(window)) return false;
  return rms.back() > ratio * rms[rms.size() - 1 - static_cast<std::size_t>(window)];
}

double level_change(std::span<const double> before, std::span<const double> after,
                    std::span<const double> mass, LevelChange how) {
  QSMESH_CHECK(before.size() == after.size() && before.size() == 2 * mass.size(),
               "crossfield: level_change needs two pairs of values per mass");
  detail::ChangeSum moved;
  for (std::size_t k = 0; k < mass.size(); ++k)
    moved.add(after[2 * k] - before[2 * k], after[2 * k + 1] - before[2 * k + 1], mass[k]);
  return moved.value(how);
}

}  // namespace qsmesh::crossfield

namespace qsmesh::crossfield::detail {

bool set_exact_uniform_field(FaceCrossField& cf, const Geometry& g) {
  const std::size_t ne = cf.edges.size(), nt = cf.triangles.size();
  if (nt == 0 || !(g.diagonal > 0)) return false;
  // The face normal: the area-weighted mean of the triangle normals (triangles are oriented along
  // the face normal). Planar: every vertex within 1e-10 of the diagonal from the mean plane, so
  // the field's holonomy is zero to rounding.
  Vec3 n{0, 0, 0};
  for (std::size_t t = 0; t < nt; ++t) n += g.normal[t] * g.area[t];
  if (!(norm(n) > 0)) return false;
  n = normalized(n);
  const Vec3 origin = cf.points[cf.triangles[0][0]];
  const double flat = 1e-10 * g.diagonal;
  for (const auto& p : cf.points)
    if (std::abs(dot(p - origin, n)) > flat) return false;
  for (std::size_t t = 0; t < nt; ++t)
    if (g.area[t] > 0 && dot(g.normal[t], n) <= 0) return false;
  // A global frame of the plane and the angle of each edge in it.
  const Vec3 x = g.xaxis[0] - n * dot(g.xaxis[0], n);
  if (!(norm(x) > 0)) return false;
  const Vec3 ex = normalized(x), ey = cross(n, ex);
  const auto edge_angle = [&](std::size_t e) {
    const Vec3 d = cf.points[cf.edges[e][1]] - cf.points[cf.edges[e][0]];
    return std::atan2(dot(d, ey), dot(d, ex));
  };
  // Boundary crosses are aligned with their edges (θ = 0): 4 × the edge angle must agree mod 2π.
  // 1e-6 rad on 4ψ is 2.5e-7 rad on the edge: straight CAD lines sampled exactly pass, any real
  // turn of the boundary does not.
  bool has_boundary = false;
  double ref = 0;
  for (std::size_t e = 0; e < ne; ++e) {
    if (!cf.boundary_edge[e]) continue;
    const double a = 4 * edge_angle(e);
    if (!has_boundary) {
      ref = a, has_boundary = true;
    } else if (std::abs(wrap_angle(a - ref)) > 1e-6) {
      return false;
    }
  }
  if (!has_boundary) return false;
  cf.u.resize(ne);
  cf.u_norm.assign(ne, 1.0);
  cf.fixed_edge.assign(ne, 0);
  for (std::size_t e = 0; e < ne; ++e) {
    if (cf.boundary_edge[e]) {
      cf.u[e] = {1, 0};  // exactly as the Dirichlet data of diffuse()
      cf.fixed_edge[e] = 1;
    } else {
      const double b = ref - 4 * edge_angle(e);
      cf.u[e] = {std::cos(b), std::sin(b)};
    }
  }
  cf.stats.solver = "exact uniform";
  return true;
}

bool set_revolution_field(FaceCrossField& cf, const Geometry& g, const cad::RevolutionAxis& axis) {
  const std::size_t ne = cf.edges.size();
  if (ne == 0 || !(g.diagonal > 0) || !(norm(axis.direction) > 0)) return false;
  const Vec3 a = normalized(axis.direction);
  // The parallel through x runs along a x (x - o); its length is x's distance from the axis.
  const double near_axis = 1e-6 * g.diagonal;
  std::vector<Vec2> u(ne);
  bool has_boundary = false;
  for (std::size_t e = 0; e < ne; ++e) {
    const Vec3 p0 = cf.points[cf.edges[e][0]], p1 = cf.points[cf.edges[e][1]];
    const Vec3 c = cross(a, (p0 + p1) * 0.5 - axis.point);
    if (!(norm(c) > near_axis)) return false;
    // The edge's tangent plane: the mean of its triangles' (the hinge between them).
    const auto& tris = g.edge2tris[e];
    Vec3 n = g.normal[tris[0]];
    if (tris[1] != kNoIndex) n = n + g.normal[tris[1]];
    if (!(norm(n) > 0)) return false;
    n = normalized(n);
    const Vec3 f = c - n * dot(c, n);
    if (!(norm(f) > 0.5 * norm(c))) return false;  // the parallel leaves the surface's plane
    const Vec3 d = normalized(p1 - p0);
    // θ of the parallel's cross from the edge, positive around the normal (FaceCrossField::u).
    const double theta = std::atan2(dot(cross(d, f), n), dot(d, f));
    if (cf.boundary_edge[e]) {
      if (std::abs(wrap_angle(4 * theta)) > 1e-4) return false;
      u[e] = {1, 0};  // exactly as the Dirichlet data of diffuse()
      has_boundary = true;
    } else {
      u[e] = {std::cos(4 * theta), std::sin(4 * theta)};
    }
  }
  if (!has_boundary) return false;
  cf.u = std::move(u);
  cf.u_norm.assign(ne, 1.0);
  cf.fixed_edge.assign(ne, 0);
  for (std::size_t e = 0; e < ne; ++e) cf.fixed_edge[e] = cf.boundary_edge[e];
  cf.stats.solver = "exact revolution";
  return true;
}

void compute_directions(FaceCrossField& cf, const Geometry& g) {
  cf.directions.resize(cf.triangles.size());
  for (std::size_t t = 0; t < cf.triangles.size(); ++t) {
    // CR basis functions are 1/3 each at the barycentre.
    Vec2 s{0, 0};
    for (int k = 0; k < 3; ++k) {
      const double a = angle_in_triangle(cf, g, static_cast<LO>(t), k);
      s += Vec2{std::cos(a), std::sin(a)};
    }
    const double theta = std::atan2(s.v, s.u) / 4;
    const Vec3 y = cross(g.normal[t], g.xaxis[t]);
    const Vec3 d0 = g.xaxis[t] * std::cos(theta) + y * std::sin(theta);
    cf.directions[t] = {d0, cross(g.normal[t], d0)};
  }
}

}  // namespace qsmesh::crossfield::detail
