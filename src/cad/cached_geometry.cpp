#include "qsmesh/cad/cached_geometry.hpp"

#include <algorithm>
#include <bit>

namespace qsmesh::cad {

CachedFaceGeometry::CachedFaceGeometry(const FaceGeometry& inner, int table_bits)
    : inner_(inner),
      mask_((std::size_t{1} << std::clamp(table_bits, 1, 24)) - 1),
      evals_(mask_ + 1),
      normals_(mask_ + 1) {}

std::size_t CachedFaceGeometry::slot(const Key& k) const {
  // Nearby parameters differ in their low mantissa bits: mix both words before masking.
  std::uint64_t h = k.u * 0x9E3779B97F4A7C15ULL ^ (k.v + 0x632BE59BD9B4E019ULL + (k.u << 6));
  h ^= h >> 29;
  h *= 0xBF58476D1CE4E5B9ULL;
  h ^= h >> 32;
  return static_cast<std::size_t>(h) & mask_;
}

SurfaceEval CachedFaceGeometry::eval(const Vec2& uv) const {
  const Key k{std::bit_cast<std::uint64_t>(uv.u), std::bit_cast<std::uint64_t>(uv.v)};
  auto& s = evals_[slot(k)];
  if (s.used && s.key == k) {
    ++hits_;
    return s.value;
  }
  ++misses_;
  s.value = inner_.eval(uv);
  s.key = k;
  s.used = true;
  return s.value;
}

Vec3 CachedFaceGeometry::normal(const Vec2& uv) const {
  const Key k{std::bit_cast<std::uint64_t>(uv.u), std::bit_cast<std::uint64_t>(uv.v)};
  auto& s = normals_[slot(k)];
  if (s.used && s.key == k) {
    ++hits_;
    return s.value;
  }
  ++misses_;
  s.value = inner_.normal(uv);
  s.key = k;
  s.used = true;
  return s.value;
}

}  // namespace qsmesh::cad
