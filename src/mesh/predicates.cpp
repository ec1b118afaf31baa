// Exact-sign predicates with floating-point expansions (nonoverlapping sums of doubles whose sign
// is the sign of their largest component). The error-bound filter follows the classical analysis
// of the 2x2 and 3x3 determinants; only inputs within the bound take the exact path.
// This file must be compiled without floating-point contraction (see CMakeLists.txt).
#include "qsmesh/mesh/predicates.hpp"

#include <cmath>

namespace qsmesh::mesh {
namespace {

constexpr double kEps = 0x1p-53;  // half an ulp of 1: the unit roundoff of round-to-nearest
constexpr double kCcwBound = (3.0 + 16.0 * kEps) * kEps;
constexpr double kIccBound = (10.0 + 96.0 * kEps) * kEps;

inline void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double bv = x - a;
  const double av = x - bv;
  y = (a - av) + (b - bv);
}

inline void fast_two_sum(double a, double b, double& x, double& y) {  // requires |a| >= |b|
  x = a + b;
  y = b - (x - a);
}

inline void two_diff(double a, double b, double& x, double& y) {
  x = a - b;
  const double bv = a - x;
  const double av = x + bv;
  y = (a - av) + (bv - b);
}

inline void two_prod(double a, double b, double& x, double& y) {
  x = a * b;
  y = std::fma(a, b, -x);
}

// h = e * b, zero components dropped; h holds 2 * elen. Returns the length (>= 1).
int scale_expansion(int elen, const double* e, double b, double* h) {
  int n = 0;
  double q, hh;
  two_prod(e[0], b, q, hh);
  if (hh != 0) h[n++] = hh;
  for (int i = 1; i < elen; ++i) {
    double p1, p0, sum;
    two_prod(e[i], b, p1, p0);
    two_sum(q, p0, sum, hh);
    if (hh != 0) h[n++] = hh;
    fast_two_sum(p1, sum, q, hh);
    if (hh != 0) h[n++] = hh;
  }
  if (q != 0 || n == 0) h[n++] = q;
  return n;
}

// h = e + f (h must not alias e or f; holds elen + flen). Merges by magnitude, then one pass of
// exact two-sums; zero components dropped. Returns the length (>= 1).
int sum_expansion(int elen, const double* e, int flen, const double* f, double* h) {
  int i = 0, j = 0, k = 0;
  while (i < elen && j < flen) h[k++] = (std::fabs(e[i]) < std::fabs(f[j])) ? e[i++] : f[j++];
  while (i < elen) h[k++] = e[i++];
  while (j < flen) h[k++] = f[j++];
  if (k == 0) {
    h[0] = 0;
    return 1;
  }
  double q = h[0];
  int n = 0;
  for (int m = 1; m < k; ++m) {
    double qn, hh;
    two_sum(q, h[m], qn, hh);
    q = qn;
    if (hh != 0) h[n++] = hh;
  }
  if (q != 0 || n == 0) h[n++] = q;
  return n;
}

// h = e * f; h holds 2 * elen * flen, scratch needs 2 * elen + 2 * elen * flen.
int mul_expansion(int elen, const double* e, int flen, const double* f, double* h,
                  double* scratch) {
  double* part = scratch;
  double* acc = scratch + 2 * elen;
  int n = scale_expansion(elen, e, f[0], h);
  for (int j = 1; j < flen; ++j) {
    const int pn = scale_expansion(elen, e, f[j], part);
    for (int m = 0; m < n; ++m) acc[m] = h[m];
    n = sum_expansion(n, acc, pn, part, h);
  }
  return n;
}

inline void negate(int n, double* e) {
  for (int i = 0; i < n; ++i) e[i] = -e[i];
}

double orient2d_exact(const Vec2& a, const Vec2& b, const Vec2& c) {
  double acx[2], acy[2], bcx[2], bcy[2];
  two_diff(a.u, c.u, acx[1], acx[0]);
  two_diff(a.v, c.v, acy[1], acy[0]);
  two_diff(b.u, c.u, bcx[1], bcx[0]);
  two_diff(b.v, c.v, bcy[1], bcy[0]);
  double left[8], right[8], scratch[16], det[16];
  const int nl = mul_expansion(2, acx, 2, bcy, left, scratch);
  const int nr = mul_expansion(2, acy, 2, bcx, right, scratch);
  negate(nr, right);
  const int n = sum_expansion(nl, left, nr, right, det);
  return det[n - 1];
}

double incircle_exact(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  double adx[2], ady[2], bdx[2], bdy[2], cdx[2], cdy[2];
  two_diff(a.u, d.u, adx[1], adx[0]);
  two_diff(a.v, d.v, ady[1], ady[0]);
  two_diff(b.u, d.u, bdx[1], bdx[0]);
  two_diff(b.v, d.v, bdy[1], bdy[0]);
  two_diff(c.u, d.u, cdx[1], cdx[0]);
  two_diff(c.v, d.v, cdy[1], cdy[0]);

  double scratch[1024];
  // lift(x, y) = x^2 + y^2 (<= 16 components)
  auto lift = [&](const double* x, const double* y, double* out) {
    double xx[8], yy[8];
    const int nx = mul_expansion(2, x, 2, x, xx, scratch);
    const int ny = mul_expansion(2, y, 2, y, yy, scratch);
    return sum_expansion(nx, xx, ny, yy, out);
  };
  // cross(x1, y1, x2, y2) = x1 * y2 - x2 * y1 (<= 16 components)
  auto cross2 = [&](const double* x1, const double* y1, const double* x2, const double* y2,
                    double* out) {
    double p[8], q[8];
    const int np = mul_expansion(2, x1, 2, y2, p, scratch);
    const int nq = mul_expansion(2, x2, 2, y1, q, scratch);
    negate(nq, q);
    return sum_expansion(np, p, nq, q, out);
  };
  double la[16], lb[16], lc[16], ca[16], cb[16], cc[16];
  const int nla = lift(adx, ady, la);
  const int nlb = lift(bdx, bdy, lb);
  const int nlc = lift(cdx, cdy, lc);
  const int nca = cross2(bdx, bdy, cdx, cdy, ca);
  const int ncb = cross2(cdx, cdy, adx, ady, cb);
  const int ncc = cross2(adx, ady, bdx, bdy, cc);
  double ta[512], tb[512], tc[512], tab[1024], det[1536];
  const int nta = mul_expansion(nla, la, nca, ca, ta, scratch);
  const int ntb = mul_expansion(nlb, lb, ncb, cb, tb, scratch);
  const int ntc = mul_expansion(nlc, lc, ncc, cc, tc, scratch);
  const int nab = sum_expansion(nta, ta, ntb, tb, tab);
  const int n = sum_expansion(nab, tab, ntc, tc, det);
  return det[n - 1];
}

}  // namespace

double orient2d_naive(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (a.u - c.u) * (b.v - c.v) - (a.v - c.v) * (b.u - c.u);
}

double incircle_naive(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double adx = a.u - d.u, ady = a.v - d.v;
  const double bdx = b.u - d.u, bdy = b.v - d.v;
  const double cdx = c.u - d.u, cdy = c.v - d.v;
  const double alift = adx * adx + ady * ady;
  const double blift = bdx * bdx + bdy * bdy;
  const double clift = cdx * cdx + cdy * cdy;
  return alift * (bdx * cdy - cdx * bdy) + blift * (cdx * ady - adx * cdy) +
         clift * (adx * bdy - bdx * ady);
}

double orient2d(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double detleft = (a.u - c.u) * (b.v - c.v);
  const double detright = (a.v - c.v) * (b.u - c.u);
  const double det = detleft - detright;
  double detsum;
  if (detleft > 0) {
    if (detright <= 0) return det;
    detsum = detleft + detright;
  } else if (detleft < 0) {
    if (detright >= 0) return det;
    detsum = -detleft - detright;
  } else {
    return det;
  }
  const double bound = kCcwBound * detsum;
  if (det >= bound || -det >= bound) return det;
  return orient2d_exact(a, b, c);
}

double incircle(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double adx = a.u - d.u, ady = a.v - d.v;
  const double bdx = b.u - d.u, bdy = b.v - d.v;
  const double cdx = c.u - d.u, cdy = c.v - d.v;
  const double bdxcdy = bdx * cdy, cdxbdy = cdx * bdy;
  const double alift = adx * adx + ady * ady;
  const double cdxady = cdx * ady, adxcdy = adx * cdy;
  const double blift = bdx * bdx + bdy * bdy;
  const double adxbdy = adx * bdy, bdxady = bdx * ady;
  const double clift = cdx * cdx + cdy * cdy;
  const double det =
      alift * (bdxcdy - cdxbdy) + blift * (cdxady - adxcdy) + clift * (adxbdy - bdxady);
  const double permanent = (std::fabs(bdxcdy) + std::fabs(cdxbdy)) * alift +
                           (std::fabs(cdxady) + std::fabs(adxcdy)) * blift +
                           (std::fabs(adxbdy) + std::fabs(bdxady)) * clift;
  const double bound = kIccBound * permanent;
  if (det > bound || -det > bound) return det;
  return incircle_exact(a, b, c, d);
}

}  // namespace qsmesh::mesh
