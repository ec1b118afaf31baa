// Robust predicates: exact signs on nearly degenerate inputs, checked against exact integer
// evaluation (__int128) on inputs that are integers after scaling by a power of two.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>

#include "qsmesh/mesh/predicates.hpp"

namespace {

using qsmesh::Vec2;
using qsmesh::mesh::incircle;
using qsmesh::mesh::incircle_naive;
using qsmesh::mesh::orient2d;
using qsmesh::mesh::orient2d_naive;
__extension__ typedef __int128 I128;  // NOLINT(modernize-use-using)

int sign(double x) { return (x > 0) - (x < 0); }
int sign(I128 x) { return (x > 0) - (x < 0); }

// Exact orient2d of integer points.
I128 orient_exact(I128 ax, I128 ay, I128 bx, I128 by, I128 cx, I128 cy) {
  return (ax - cx) * (by - cy) - (ay - cy) * (bx - cx);
}

TEST(Predicates, OrientSimple) {
  EXPECT_GT(orient2d({0, 0}, {1, 0}, {0, 1}), 0);
  EXPECT_LT(orient2d({0, 0}, {0, 1}, {1, 0}), 0);
  EXPECT_EQ(orient2d({0, 0}, {1, 1}, {2, 2}), 0);
  EXPECT_EQ(orient2d({0.1, 0.1}, {0.1, 0.1}, {0.3, 0.7}), 0);
}

// Classic near-collinear grid: a = (0.5 + i ulp, 0.5 + j ulp), b = (12, 12), c = (24, 24).
// Scaled by 2^53 every coordinate is an integer below 2^58, so __int128 evaluates exactly.
TEST(Predicates, OrientNearCollinearMatchesExact) {
  const double ulp = std::ldexp(1.0, -53);
  int naive_wrong = 0, robust_wrong = 0, zeros = 0;
  for (int i = 0; i < 256; ++i) {
    for (int j = 0; j < 256; ++j) {
      const Vec2 a{0.5 + i * ulp, 0.5 + j * ulp}, b{12, 12}, c{24, 24};
      auto sc = [](double x) { return static_cast<I128>(std::ldexp(x, 53)); };
      const int exact = sign(orient_exact(sc(a.u), sc(a.v), sc(b.u), sc(b.v), sc(c.u), sc(c.v)));
      robust_wrong += sign(orient2d(a, b, c)) != exact;
      naive_wrong += sign(orient2d_naive(a, b, c)) != exact;
      zeros += exact == 0;
    }
  }
  EXPECT_EQ(robust_wrong, 0);
  EXPECT_GT(naive_wrong, 0) << "test should exercise inputs the naive formula gets wrong";
  EXPECT_GT(zeros, 0);
  std::printf("orient2d near-collinear: naive wrong on %d / 65536, robust wrong on %d\n",
              naive_wrong, robust_wrong);
}

TEST(Predicates, OrientRandomIntegersMatchExact) {
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::int64_t> coord(-(1LL << 40), 1LL << 40);
  int wrong = 0;
  for (int k = 0; k < 100000; ++k) {
    std::int64_t ax = coord(rng), ay = coord(rng), bx = coord(rng), by = coord(rng);
    // c nearly on line ab
    const std::int64_t t = coord(rng) >> 20;
    std::int64_t cx = ax + (bx - ax) / 1024 * (t % 7), cy = ay + (by - ay) / 1024 * (t % 7);
    cx += (k % 3) - 1;
    const Vec2 a{static_cast<double>(ax), static_cast<double>(ay)},
        b{static_cast<double>(bx), static_cast<double>(by)},
        c{static_cast<double>(cx), static_cast<double>(cy)};
    wrong += sign(orient2d(a, b, c)) != sign(orient_exact(ax, ay, bx, by, cx, cy));
  }
  EXPECT_EQ(wrong, 0);
}

I128 incircle_exact(const std::int64_t* p) {  // a, b, c, d as x, y pairs
  const I128 adx = p[0] - p[6], ady = p[1] - p[7];
  const I128 bdx = p[2] - p[6], bdy = p[3] - p[7];
  const I128 cdx = p[4] - p[6], cdy = p[5] - p[7];
  return (adx * adx + ady * ady) * (bdx * cdy - cdx * bdy) +
         (bdx * bdx + bdy * bdy) * (cdx * ady - adx * cdy) +
         (cdx * cdx + cdy * cdy) * (adx * bdy - bdx * ady);
}

TEST(Predicates, IncircleSimple) {
  EXPECT_GT(incircle({0, 0}, {1, 0}, {0, 1}, {0.3, 0.3}), 0);
  EXPECT_LT(incircle({0, 0}, {1, 0}, {0, 1}, {3, 3}), 0);
  EXPECT_EQ(incircle({0, 0}, {1, 0}, {1, 1}, {0, 1}), 0);
}

// Points of the integer circle x^2 + y^2 = 5^8 (many lattice points), translated far from the
// origin and perturbed by at most one unit: |coords| < 2^25, so __int128 is exact, while the
// naive double formula has terms ~2^100 and loses the sign.
TEST(Predicates, IncircleNearCocircularMatchesExact) {
  std::vector<std::pair<std::int64_t, std::int64_t>> circle;
  const std::int64_t r2 = 390625;  // 5^8
  for (std::int64_t x = -625; x <= 625; ++x) {
    const auto y =
        static_cast<std::int64_t>(std::llround(std::sqrt(static_cast<double>(r2 - x * x))));
    if (x * x + y * y == r2) {
      circle.emplace_back(x, y);
      if (y != 0) circle.emplace_back(x, -y);
    }
  }
  ASSERT_GE(circle.size(), 8U);
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::size_t> pick(0, circle.size() - 1);
  std::uniform_int_distribution<int> jitter(-1, 1);
  const std::int64_t off = (1LL << 24) + 12345;
  int naive_wrong = 0, robust_wrong = 0, zeros = 0;
  for (int k = 0; k < 20000; ++k) {
    std::int64_t p[8];
    for (int q = 0; q < 4; ++q) {
      const auto& c = circle[pick(rng)];
      p[2 * q] = c.first * 37 + off + (q == 3 ? jitter(rng) : 0);
      p[2 * q + 1] = c.second * 37 + off - 777 + (q == 3 ? jitter(rng) : 0);
    }
    const Vec2 a{double(p[0]), double(p[1])}, b{double(p[2]), double(p[3])},
        c{double(p[4]), double(p[5])}, d{double(p[6]), double(p[7])};
    const int exact = sign(incircle_exact(p));
    robust_wrong += sign(incircle(a, b, c, d)) != exact;
    naive_wrong += sign(incircle_naive(a, b, c, d)) != exact;
    zeros += exact == 0;
  }
  EXPECT_EQ(robust_wrong, 0);
  EXPECT_GT(zeros, 0);
  std::printf(
      "incircle near-cocircular: naive wrong on %d / 20000, robust wrong on %d (%d exact zeros)\n",
      naive_wrong, robust_wrong, zeros);
}

// Non-integer inputs with tiny perturbations: exact reference by scaling dyadic coordinates.
TEST(Predicates, IncirclePerturbedDyadicMatchesExact) {
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<int> small(-4, 4);
  int wrong = 0, naive_wrong = 0;
  const double s = std::ldexp(1.0, -20);
  for (int k = 0; k < 20000; ++k) {
    // Unit-square corners (cocircular) scaled to [0, 2^5], fourth perturbed by multiples of 2^-20.
    const std::int64_t base[8] = {0, 0, 32, 0, 32, 32, 0, 32};
    std::int64_t p[8];
    Vec2 v[4];
    for (int q = 0; q < 4; ++q) {
      const std::int64_t ix = base[2 * q] * (1LL << 20) + small(rng) * (q == 3 ? 1 : 0);
      const std::int64_t iy = base[2 * q + 1] * (1LL << 20) + small(rng) * (q == 3 ? 1 : 0);
      p[2 * q] = ix;
      p[2 * q + 1] = iy;
      v[q] = {static_cast<double>(ix) * s + 1000.0, static_cast<double>(iy) * s + 1000.0};
      p[2 * q] += 1000LL << 20;
      p[2 * q + 1] += 1000LL << 20;
    }
    const int exact = sign(incircle_exact(p));
    wrong += sign(incircle(v[0], v[1], v[2], v[3])) != exact;
    naive_wrong += sign(incircle_naive(v[0], v[1], v[2], v[3])) != exact;
  }
  EXPECT_EQ(wrong, 0);
  std::printf("incircle perturbed square: naive wrong on %d / 20000\n", naive_wrong);
}

}  // namespace
