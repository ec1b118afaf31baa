// Area-distortion energy (paper 004 Eqs. 4.9-4.11) and the zeros of a holomorphic 1-form.
#include <cmath>
#include <numbers>

#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"

namespace qsmesh::holomorphic {
namespace {

std::complex<double> directed(const PolyAnnulus& s, std::span<const std::complex<double>> phi,
                              LO from, LO e) {
  return s.edges[static_cast<std::size_t>(e)][0] == from ? phi[static_cast<std::size_t>(e)]
                                                         : -phi[static_cast<std::size_t>(e)];
}

// Per triangle, the real and imaginary parts of each basis form on its first two ccw edges: the
// triangle's area under lambda is 1/2 [(a1.l)(b2.l) - (b1.l)(a2.l)], a quadratic form in lambda.
struct AreaTerms {
  std::size_t n = 0;
  std::vector<double> a1, b1, a2, b2;  // triangle-major, n per triangle
  std::vector<double> area;            // 3D areas
};

AreaTerms area_terms(const PolyAnnulus& s, const HolomorphicBasis& B) {
  AreaTerms T;
  T.n = static_cast<std::size_t>(B.n);
  const std::size_t nt = s.triangles.size();
  T.a1.resize(nt * T.n);
  T.b1.resize(nt * T.n);
  T.a2.resize(nt * T.n);
  T.b2.resize(nt * T.n);
  T.area.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& c = s.triangles[t];
    const Vec3& p0 = s.points[static_cast<std::size_t>(c[0])];
    T.area[t] = 0.5 * norm(cross(s.points[static_cast<std::size_t>(c[1])] - p0,
                                 s.points[static_cast<std::size_t>(c[2])] - p0));
    for (std::size_t k = 0; k < T.n; ++k) {
      const auto z1 = directed(s, B.phi[k], c[0], s.tri_edges[t][0]);
      const auto z2 = directed(s, B.phi[k], c[1], s.tri_edges[t][1]);
      T.a1[t * T.n + k] = z1.real();
      T.b1[t * T.n + k] = z1.imag();
      T.a2[t * T.n + k] = z2.real();
      T.b2[t * T.n + k] = z2.imag();
    }
  }
  return T;
}

struct Eval {
  double energy = 0;
  std::vector<double> grad;
  std::vector<double> hess;  // n x n, row-major
};

// Energy, gradient (Eq. 4.11) and Hessian at lambda. With A(l) = 1/2 l^T C l per triangle, the
// gradient of A is C l = 1/2 [a1 (b2.l) + b2 (a1.l) - b1 (a2.l) - a2 (b1.l)], and C itself the
// symmetric part of a1 b2^T - b1 a2^T.
Eval evaluate(const AreaTerms& T, std::span<const double> l, bool with_hessian) {
  const std::size_t n = T.n;
  Eval E;
  E.grad.assign(n, 0.0);
  if (with_hessian) E.hess.assign(n * n, 0.0);
  std::vector<double> g(n);
  for (std::size_t t = 0; t < T.area.size(); ++t) {
    const double* a1 = &T.a1[t * n];
    const double* b1 = &T.b1[t * n];
    const double* a2 = &T.a2[t * n];
    const double* b2 = &T.b2[t * n];
    double A1 = 0, B1 = 0, A2 = 0, B2 = 0;
    for (std::size_t k = 0; k < n; ++k) {
      A1 += a1[k] * l[k];
      B1 += b1[k] * l[k];
      A2 += a2[k] * l[k];
      B2 += b2[k] * l[k];
    }
    const double r = 0.5 * (A1 * B2 - B1 * A2) - T.area[t];
    E.energy += r * r;
    for (std::size_t k = 0; k < n; ++k)
      g[k] = 0.5 * (a1[k] * B2 + b2[k] * A1 - b1[k] * A2 - a2[k] * B1);
    for (std::size_t k = 0; k < n; ++k) E.grad[k] += 2 * r * g[k];
    if (with_hessian)
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) {
          const double C = 0.5 * (a1[i] * b2[j] + a1[j] * b2[i] - b1[i] * a2[j] - b1[j] * a2[i]);
          E.hess[i * n + j] += 2 * g[i] * g[j] + 2 * r * C;
        }
  }
  return E;
}

// Cholesky solve of H x = b; false when H is not positive definite.
bool cholesky_solve(std::vector<double> H, std::size_t n, std::span<const double> b,
                    std::vector<double>& x) {
  for (std::size_t j = 0; j < n; ++j) {
    double d = H[j * n + j];
    for (std::size_t k = 0; k < j; ++k) d -= H[j * n + k] * H[j * n + k];
    if (!(d > 0)) return false;
    d = std::sqrt(d);
    H[j * n + j] = d;
    for (std::size_t i = j + 1; i < n; ++i) {
      double v = H[i * n + j];
      for (std::size_t k = 0; k < j; ++k) v -= H[i * n + k] * H[j * n + k];
      H[i * n + j] = v / d;
    }
  }
  x.assign(b.begin(), b.end());
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < i; ++k) x[i] -= H[i * n + k] * x[k];
    x[i] /= H[i * n + i];
  }
  for (std::size_t i = n; i-- > 0;) {
    for (std::size_t k = i + 1; k < n; ++k) x[i] -= H[k * n + i] * x[k];
    x[i] /= H[i * n + i];
  }
  return true;
}

}  // namespace

std::vector<double> phi_areas(const PolyAnnulus& s, std::span<const std::complex<double>> phi) {
  std::vector<double> out(s.triangles.size());
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const auto& c = s.triangles[t];
    const auto z1 = directed(s, phi, c[0], s.tri_edges[t][0]);
    const auto z2 = directed(s, phi, c[1], s.tri_edges[t][1]);
    out[t] = 0.5 * (std::conj(z1) * z2).imag();
  }
  return out;
}

double area_energy(const PolyAnnulus& surface, const HolomorphicBasis& basis,
                   std::span<const double> lambda) {
  return evaluate(area_terms(surface, basis), lambda, false).energy;
}

EnergyResult minimize_area_distortion(const PolyAnnulus& s, const HolomorphicBasis& B,
                                      const EnergyOptions& options) {
  QSMESH_CHECK(B.n > 0, "no basis form to combine");
  const Stopwatch clock;
  const AreaTerms T = area_terms(s, B);
  const std::size_t n = T.n;
  EnergyResult R;
  // Start: all coefficients equal, scaled so that the phi-area equals the 3D area (area is
  // homogeneous of degree 2 in lambda).
  R.lambda.assign(n, 1.0);
  double total = 0, phi_total = 0;
  for (const double a : T.area) total += a;
  {
    const auto z = combine(B, R.lambda);
    for (const double a : phi_areas(s, z)) phi_total += a;
  }
  QSMESH_CHECK(phi_total > 0, "the basis forms' sum has non-positive area " << phi_total);
  for (double& v : R.lambda) v *= std::sqrt(total / phi_total);
  Eval E = evaluate(T, R.lambda, true);
  R.energy.push_back(E.energy);
  std::vector<double> step, trial(n);
  const double scale = total * total;
  for (int it = 0; it < options.max_iterations; ++it) {
    double gnorm = 0, lnorm = 0;
    for (std::size_t k = 0; k < n; ++k) {
      gnorm += E.grad[k] * E.grad[k];
      lnorm += R.lambda[k] * R.lambda[k];
    }
    gnorm = std::sqrt(gnorm);
    if (gnorm * std::sqrt(lnorm) <= options.gradient_tolerance * (E.energy + scale)) {
      R.converged = true;
      break;
    }
    std::vector<double> minus_g(n);
    for (std::size_t k = 0; k < n; ++k) minus_g[k] = -E.grad[k];
    if (!cholesky_solve(E.hess, n, minus_g, step)) step = minus_g;
    // Backtracking: only a strict decrease is accepted.
    double t = 1.0;
    Eval next;
    bool accepted = false;
    for (int halvings = 0; halvings < 60; ++halvings, t *= 0.5) {
      for (std::size_t k = 0; k < n; ++k) trial[k] = R.lambda[k] + t * step[k];
      next = evaluate(T, trial, true);
      if (next.energy < E.energy) {
        accepted = true;
        break;
      }
    }
    if (!accepted) {
      R.converged = true;  // no descent left at machine precision
      break;
    }
    const double decrease = E.energy - next.energy;
    R.lambda = trial;
    E = std::move(next);
    R.energy.push_back(E.energy);
    R.iterations = it + 1;
    if (decrease <= options.relative_decrease * (E.energy + scale)) {
      R.converged = true;
      break;
    }
  }
  R.seconds = clock.seconds();
  return R;
}

ZeroReport find_zeros(const PolyAnnulus& s, std::span<const std::complex<double>> phi) {
  ZeroReport Z;
  std::vector<double> turn(s.points.size(), 0.0);
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const auto& c = s.triangles[t];
    for (int k = 0; k < 3; ++k) {
      // At corner k the ccw triangle goes from edge (k, k+1) to edge (k, k+2).
      const LO v = c[k];
      const auto to_next = directed(s, phi, v, s.tri_edges[t][k]);
      const auto to_prev = -directed(s, phi, c[(k + 2) % 3], s.tri_edges[t][(k + 2) % 3]);
      // phi is real on boundary edges (f is constant along each loop), so a triangle with two
      // boundary edges at a corner maps to a flat triangle with an angle of exactly pi there; the
      // sign of a zero imaginary part must not turn it into -pi.
      double angle = std::arg(to_prev / to_next);
      if (angle < -std::numbers::pi + 1e-9) angle = std::numbers::pi;
      turn[static_cast<std::size_t>(v)] += angle;
    }
  }
  std::vector<LO> flipped;
  {
    const auto areas = phi_areas(s, phi);
    for (std::size_t t = 0; t < areas.size(); ++t) {
      // Flat images (corner triangles, see above) are not flipped.
      const auto& c = s.triangles[t];
      const double scale = std::abs(directed(s, phi, c[0], s.tri_edges[t][0])) *
                           std::abs(directed(s, phi, c[1], s.tri_edges[t][1]));
      if (areas[t] < -1e-9 * scale) flipped.push_back(static_cast<LO>(t));
    }
  }
  std::vector<char> on_boundary(s.points.size(), 0);
  for (const auto& loop : s.loops)
    for (const LO v : loop) on_boundary[static_cast<std::size_t>(v)] = 1;
  const double pi = std::numbers::pi;
  for (LO v = 0; v < s.num_vertices(); ++v) {
    const double a = turn[static_cast<std::size_t>(v)];
    if (on_boundary[static_cast<std::size_t>(v)] != 0) {
      Z.index_sum += (a - pi) / (2 * pi);
      if (a > 1.5 * pi) Z.boundary.push_back(v);
    } else {
      const int winding = static_cast<int>(std::lround(a / (2 * pi)));
      Z.index_sum += winding - 1;
      if (winding != 1) Z.interior.push_back({v, kNoIndex, winding - 1});
    }
  }
  Z.flipped = static_cast<LO>(flipped.size());
  for (const LO t : flipped) Z.interior.push_back({kNoIndex, t, 1});
  Z.index_sum += Z.flipped;
  return Z;
}

}  // namespace qsmesh::holomorphic
