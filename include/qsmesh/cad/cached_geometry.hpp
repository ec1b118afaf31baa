#pragma once
// A face evaluator that remembers its evaluations and normals by their exact (u, v).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "qsmesh/cad/geometry.hpp"

namespace qsmesh::cad {

/// Wraps a FaceGeometry and keeps eval(uv) and normal(uv) by the bits of (u, v): asked again for
/// the same parameters, it returns what the wrapped surface returned, bit for bit (both are
/// functions of (u, v) alone). Why: the cavity remeshing (paper 000 Sec. 6.2) lays out, smooths
/// and measures hundreds of candidates over the same vertices; the normals of the vertices they
/// keep, and the evaluation at a vertex's current (u, v) that each smoothing move starts from,
/// are asked for again and again. The tables are direct-mapped (2^table_bits slots each, a new
/// (u, v) takes the slot of an older one): no allocation per evaluation, and a forgotten entry
/// is only evaluated again. eval2, project, boundary_uv and contains go to the wrapped surface.
/// Not thread-safe (one per thread, like the OCCT evaluators).
class CachedFaceGeometry final : public FaceGeometry {
 public:
  explicit CachedFaceGeometry(const FaceGeometry& inner, int table_bits = 14);

  [[nodiscard]] SurfaceEval eval(const Vec2& uv) const override;
  [[nodiscard]] SurfaceEval2 eval2(const Vec2& uv) const override { return inner_.eval2(uv); }
  [[nodiscard]] Vec3 normal(const Vec2& uv) const override;
  [[nodiscard]] Vec2 project(const Vec3& p, const Vec2& uv_guess, Vec3* foot) const override {
    return inner_.project(p, uv_guess, foot);
  }
  [[nodiscard]] Vec2 boundary_uv(LO loop, LO use, double t) const override {
    return inner_.boundary_uv(loop, use, t);
  }
  [[nodiscard]] bool contains(const Vec2& uv) const override { return inner_.contains(uv); }

  /// Evaluations and normals answered from the tables, and asked of the wrapped surface.
  [[nodiscard]] std::int64_t hits() const { return hits_; }
  [[nodiscard]] std::int64_t misses() const { return misses_; }

 private:
  struct Key {
    std::uint64_t u = 0, v = 0;
    bool operator==(const Key&) const = default;
  };
  template <class T>
  struct Slot {
    Key key;
    bool used = false;
    T value{};
  };
  [[nodiscard]] std::size_t slot(const Key& k) const;

  const FaceGeometry& inner_;
  std::size_t mask_;
  mutable std::vector<Slot<SurfaceEval>> evals_;
  mutable std::vector<Slot<Vec3>> normals_;
  mutable std::int64_t hits_ = 0, misses_ = 0;
};

}  // namespace qsmesh::cad
