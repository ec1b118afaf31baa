// Sec. 3.3: conformal scaling of the cross field.
//
// Sign: for T = e^H (cos θ, sin θ), S = e^H (-sin θ, cos θ) the bracket [T, S] vanishes when
// ∇H = (θ_y, -θ_x) = -∇⊥θ; Eq. 8 of the paper prints the opposite sign. Check: the polar grid
// T = r e_r, S = r e_φ commutes and has θ = φ, ∇θ = e_φ / r, so ∇H = e_r / r and h = r; with
// the printed sign h would be 1 / r, whose fields e_r / r, e_φ / r do not commute.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "internal.hpp"
#include "qsmesh/core/error.hpp"

namespace qsmesh::crossfield {
namespace detail {
namespace {

// Clamps H to its quantiles q and 1 - q, each vertex weighted by `weight` (a third of the area of
// its triangles; `total` their sum). Weighting by area keeps the bounds independent of how finely
// the background mesh is graded near the very corners whose values are clamped.
void clamp_to_quantiles(std::vector<double>& H, const std::vector<double>& weight, double total,
                        double q) {
  if (!(total > 0)) return;
  std::vector<LO> order(H.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](LO a, LO b) { return H[a] < H[b] || (H[a] == H[b] && a < b); });
  auto value_at = [&](double fraction) {
    double acc = 0;
    for (const LO v : order) {
      acc += weight[v];
      if (acc >= fraction * total) return H[v];
    }
    return H[order.back()];
  };
  const double lo = value_at(q), hi = value_at(1 - q);
  for (double& h : H) h = std::clamp(h, lo, hi);
}

}  // namespace

void compute_scaling(FaceCrossField& cf, const Geometry& g, const CrossFieldOptions& options,
                     linalg::SolverLane* lane) {
  const LO nv = static_cast<LO>(cf.points.size()), nt = static_cast<LO>(cf.triangles.size());
  cf.H.assign(static_cast<std::size_t>(nv), 0.0);
  cf.h.assign(static_cast<std::size_t>(nv), 1.0);
  if (nv < 2) return;
  // At a cusp (two curves leaving a corner tangentially) the field turns by a right angle over a
  // vanishing width: H goes to -infinity there with a coefficient no quantile clamp tames, and a
  // clamped value still shrinks the sizes of every curve the face shares (t20_data's chamfer
  // faces halved those of the hexagon flats beside them). Such a field says nothing about sizes;
  // the face keeps a uniform scaling, and s_min still sees its small features.
  for (LO v = 0; v < nv; ++v)
    if (cf.vertex_dim[v] == 0 && g.boundary_vertex[v] &&
        g.vertex_angle[v] * 180 / kPi < options.cusp_angle_deg)
      return;
  // H is fixed to 0 at vertex 0 (then shifted to zero mean): unknown of vertex v is v - 1.
  // One element a triangle of positive area: its vertices' unknowns and their 3 x 3 block.
  std::vector<LO> dofs;
  std::vector<double> blocks;
  dofs.reserve(static_cast<std::size_t>(nt) * 3);
  blocks.reserve(static_cast<std::size_t>(nt) * 9);
  std::vector<double> rhs(static_cast<std::size_t>(nv - 1), 0.0);
  for (LO t = 0; t < nt; ++t) {
    if (g.area[t] <= 0) continue;
    const auto& tri = cf.triangles[t];
    const Vec3& n = g.normal[t];
    Vec3 grad_l[3];
    for (int m = 0; m < 3; ++m)
      grad_l[m] =
          cross(n, cf.points[tri[(m + 2) % 3]] - cf.points[tri[(m + 1) % 3]]) / (2 * g.area[t]);
    // θ at the three edge midpoints in the triangle frame, made continuous with the diff operator.
    const double A0 = angle_in_triangle(cf, g, t, 0);
    Vec3 grad_theta{0, 0, 0};
    for (int k = 0; k < 3; ++k) {
      const double a = (A0 + wrap_angle(angle_in_triangle(cf, g, t, k) - A0)) / 4;
      grad_theta += grad_l[(k + 2) % 3] * (-2 * a);  // CR basis of edge k: 1 - 2 λ_(k+2)
    }
    const Vec3 target = cross(grad_theta, n);  // -∇⊥θ
    for (int i = 0; i < 3; ++i) {
      dofs.push_back(tri[i] == 0 ? kNoIndex : tri[i] - 1);
      if (tri[i] != 0) rhs[tri[i] - 1] += g.area[t] * dot(grad_l[i], target);
      for (int j = 0; j < 3; ++j) blocks.push_back(g.area[t] * dot(grad_l[i], grad_l[j]));
    }
  }
  const auto A = linalg::SparseMatrix::from_elements(nv - 1, 3, dofs, blocks);
  auto solver = linalg::make_solver(nv - 1, options.solver, lane);
  solver->analyze(A);
  solver->factorize(A);
  std::vector<double> x(static_cast<std::size_t>(nv - 1));
  solver->solve(rhs, x);
  double mean = 0, total = 0;
  std::vector<double> weight(static_cast<std::size_t>(nv), 0.0);  // a third of the area around
  for (LO v = 1; v < nv; ++v) cf.H[v] = x[v - 1];
  for (LO t = 0; t < nt; ++t)
    for (LO v : cf.triangles[t]) {
      mean += cf.H[v] * g.area[t] / 3, total += g.area[t] / 3;
      weight[v] += g.area[t] / 3;
    }
  if (total > 0) mean /= total;
  for (LO v = 0; v < nv; ++v) {
    cf.H[v] -= mean;
    QSMESH_CHECK(std::isfinite(cf.H[v]), "crossfield: face " << cf.face << ": non-finite scaling");
  }
  QSMESH_CHECK(
      options.scaling_quantile >= 0 && options.scaling_quantile < 0.5,
      "crossfield: scaling_quantile " << options.scaling_quantile << " is not in [0, 0.5)");
  if (options.scaling_quantile > 0)
    clamp_to_quantiles(cf.H, weight, total, options.scaling_quantile);
  for (LO v = 0; v < nv; ++v) cf.h[v] = std::exp(cf.H[v]);
}

}  // namespace detail

double scaling_constant(const FaceCrossField& cf, double n_quads) {
  QSMESH_CHECK(n_quads > 0, "crossfield: scaling_constant needs n_quads > 0");
  double integral = 0;
  for (const auto& tri : cf.triangles) {
    const Vec3 a = cf.points[tri[1]] - cf.points[tri[0]], b = cf.points[tri[2]] - cf.points[tri[0]];
    double mean = 0;
    for (LO v : tri) mean += std::exp(-2 * cf.H[v]) / 3;
    integral += 0.5 * norm(cross(a, b)) * mean;
  }
  QSMESH_CHECK(integral > 0, "crossfield: scaling_constant on an empty field");
  return -0.5 * std::log(n_quads / integral);
}

}  // namespace qsmesh::crossfield
