// Private to the highorder module: the (u, v) images of a vertex in a face, the 1D Lagrange basis
// and the Jacobian check of Lagrange quads, shared by the high-order mesh (high_order.cpp) and the
// blocks as single patches (block_patches.cpp).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/highorder/high_order.hpp"
#include "qsmesh/mesh/high_order_nodes.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::highorder::detail {

// The (u, v) images of vertex v in face f: its own (u, v) inside the face; on a curve or at a
// corner, the pcurve images of every use of the curve(s) in the face's loops (a seam has two).
inline std::vector<Vec2> uv_images(const cad::CadModel& model, const cad::FaceGeometry& face, LO f,
                                   const mesh::VertexClass& c) {
  if (c.dim == 2) return {Vec2{c.param[0], c.param[1]}};
  std::vector<Vec2> out;
  const auto& loops = model.faces()[static_cast<std::size_t>(f)].loops;
  for (std::size_t l = 0; l < loops.size(); ++l)
    for (std::size_t u = 0; u < loops[l].uses.size(); ++u) {
      const LO curve = loops[l].uses[u].curve;
      const cad::Curve& cc = model.curves()[static_cast<std::size_t>(curve)];
      if (c.dim == 1 && curve == c.entity) {
        out.push_back(face.boundary_uv(static_cast<LO>(l), static_cast<LO>(u), c.param[0]));
      } else if (c.dim == 0) {
        if (cc.corners[0] == c.entity)
          out.push_back(face.boundary_uv(static_cast<LO>(l), static_cast<LO>(u), cc.t0));
        if (cc.corners[1] == c.entity)
          out.push_back(face.boundary_uv(static_cast<LO>(l), static_cast<LO>(u), cc.t1));
      }
    }
  return out;
}

// The bilinear interpolation at (r, t) of the values at a quad's corners 0 (0, 0), 1 (1, 0),
// 2 (1, 1) and 3 (0, 1).
template <class T>
T bilinear(const std::array<T, 4>& c, double r, double t) {
  return (1 - r) * (1 - t) * c[0] + r * (1 - t) * c[1] + r * t * c[2] + (1 - r) * t * c[3];
}

// Point (i, j), 0 < i, j < n, of the transfinite (Coons) interpolation of the boundary rows of an
// (n + 1) x (n + 1) grid `at(i, j)`.
template <class At>
auto coons(const At& at, int n, int i, int j) {
  const double r = static_cast<double>(i) / n, t = static_cast<double>(j) / n;
  return (1 - t) * at(i, 0) + t * at(i, n) + (1 - r) * at(0, j) + r * at(n, j) -
         ((1 - r) * (1 - t) * at(0, 0) + r * (1 - t) * at(n, 0) + r * t * at(n, n) +
          (1 - r) * t * at(0, n));
}

// The sides of an n x n node grid in a quad's node order: side k starts at (walk[k][0],
// walk[k][1]) and its node s is s steps of (walk[k][2], walk[k][3]) on.
inline std::array<std::array<int, 4>, 4> side_walk(int n) {
  return {{{0, 0, 1, 0}, {n, 0, 0, 1}, {n, n, -1, 0}, {0, n, 0, -1}}};
}

inline Vec2 nearest(const std::vector<Vec2>& images, const Vec2& ref) {
  Vec2 best = images.front();
  double d = std::numeric_limits<double>::max();
  for (const Vec2& x : images) {
    const double e = (x.u - ref.u) * (x.u - ref.u) + (x.v - ref.v) * (x.v - ref.v);
    if (e < d) {
      d = e;
      best = x;
    }
  }
  return best;
}

// The 1D Lagrange basis of degree n on the equispaced nodes a / n of [0, 1], and its derivative,
// at s.
inline void lagrange_1d(int n, double s, double* l, double* dl) {
  for (int a = 0; a <= n; ++a) {
    const double xa = static_cast<double>(a) / n;
    double value = 1, derivative = 0;
    for (int b = 0; b <= n; ++b) {
      if (b == a) continue;
      const double xb = static_cast<double>(b) / n;
      derivative = derivative * (s - xb) / (xa - xb) + value / (xa - xb);
      value *= (s - xb) / (xa - xb);
    }
    l[a] = value;
    if (dl != nullptr) dl[a] = derivative;
  }
}

constexpr int kMaxNodes = (kMaxOrder + 1) * (kMaxOrder + 1);
constexpr int kMaxSamples = 2 * kMaxOrder + 1;

// The Jacobian check of Lagrange quads of one order, its tables made once: the basis and its
// derivative at the samples m / (2 n), and where each stored node sits on the grid.
class QuadChecker {
 public:
  explicit QuadChecker(int order) : n_(order), positions_(mesh::quad_grid_positions(order)) {
    QSMESH_CHECK(order >= 1 && order <= kMaxOrder,
                 "Lagrange quad: order " << order << " out of [1, " << kMaxOrder << "]");
    for (int m = 0; m < samples(); ++m)
      lagrange_1d(n_, static_cast<double>(m) / (2 * n_), l_[static_cast<std::size_t>(m)].data(),
                  dl_[static_cast<std::size_t>(m)].data());
  }
  [[nodiscard]] int order() const { return n_; }
  [[nodiscard]] int samples() const { return 2 * n_ + 1; }
  [[nodiscard]] const std::vector<std::array<int, 2>>& positions() const { return positions_; }
  // Grid index (i + (n + 1) j) of stored node k.
  [[nodiscard]] std::size_t grid(std::size_t k) const {
    return static_cast<std::size_t>(positions_[k][0] + (n_ + 1) * positions_[k][1]);
  }
  // `g`: the nodes on the grid (i + (n + 1) j).
  [[nodiscard]] bool valid(const std::array<Vec3, kMaxNodes>& g, const Vec3& normal) const {
    return valid_along(g, [&](int, int) { return normal; });
  }
  // The same with a reference normal per sample: normal_at(m1, m2) at reference position
  // (m1, m2) / (2 n) (m1 along corner 0 -> 1).
  template <class NormalAt>
  [[nodiscard]] bool valid_along(const std::array<Vec3, kMaxNodes>& g,
                                 const NormalAt& normal_at) const {
    return for_each_sample(g, [&](int m1, int m2, const Vec3& ds, const Vec3& dt) {
      return dot(cross(ds, dt), normal_at(m1, m2)) > 0;
    });
  }
  // The scaled Jacobian of the quad along `normal` at each sample: the Jacobian over the product
  // of the lengths of its two columns, in [-1, 1] (0 where a column vanishes). Returns the
  // smallest, and adds the negative ones to `*folded` (how deep the element folds, summed over
  // the samples: a smooth measure to untangle by, where the smallest alone moves with one node).
  [[nodiscard]] double min_scaled_jacobian(const std::array<Vec3, kMaxNodes>& g, const Vec3& normal,
                                           double* folded) const {
    const double len = norm(normal);
    const Vec3 unit = len > 0 ? normal * (1 / len) : normal;
    double worst = 1;
    (void)for_each_sample(g, [&](int, int, const Vec3& ds, const Vec3& dt) {
      const double scale = std::sqrt(dot(ds, ds) * dot(dt, dt));
      const double j = scale > 0 ? dot(cross(ds, dt), unit) / scale : 0.0;
      worst = std::min(worst, j);
      if (folded != nullptr && j < 0) *folded += j;
      return true;
    });
    return worst;
  }

 private:
  // Calls visit(m1, m2, ds, dt) with the two derivatives of the Lagrange map at each sample
  // (m1, m2) / (2 n) until it returns false; returns whether it never did.
  template <class Visit>
  bool for_each_sample(const std::array<Vec3, kMaxNodes>& g, const Visit& visit) const {
    const int np = n_ + 1;
    std::array<Vec3, kMaxOrder + 1> along{}, across{};
    for (int m2 = 0; m2 < samples(); ++m2) {
      const auto& l2 = l_[static_cast<std::size_t>(m2)];
      const auto& d2 = dl_[static_cast<std::size_t>(m2)];
      for (int a = 0; a < np; ++a) {
        Vec3 x{}, y{};
        for (int b = 0; b < np; ++b) {
          const Vec3& p = g[static_cast<std::size_t>(a + np * b)];
          x += p * l2[static_cast<std::size_t>(b)];
          y += p * d2[static_cast<std::size_t>(b)];
        }
        along[static_cast<std::size_t>(a)] = x;
        across[static_cast<std::size_t>(a)] = y;
      }
      for (int m1 = 0; m1 < samples(); ++m1) {
        const auto& l1 = l_[static_cast<std::size_t>(m1)];
        const auto& d1 = dl_[static_cast<std::size_t>(m1)];
        Vec3 ds{}, dt{};
        for (int a = 0; a < np; ++a) {
          ds += along[static_cast<std::size_t>(a)] * d1[static_cast<std::size_t>(a)];
          dt += across[static_cast<std::size_t>(a)] * l1[static_cast<std::size_t>(a)];
        }
        if (!visit(m1, m2, ds, dt)) return false;
      }
    }
    return true;
  }

  int n_;
  std::vector<std::array<int, 2>> positions_;
  std::array<std::array<double, kMaxOrder + 1>, kMaxSamples> l_{}, dl_{};
};

}  // namespace qsmesh::highorder::detail
