// compute_face_cross_field: the stages of step 1 for one face, in order.
#include <chrono>

#include "internal.hpp"

namespace qsmesh::crossfield {

FaceCrossField compute_face_cross_field(const mesh::FaceMesh& background,
                                        const CrossFieldOptions& options, linalg::SolverLane* lane,
                                        const std::optional<cad::RevolutionAxis>& axis) {
  const auto start = std::chrono::steady_clock::now();
  FaceCrossField cf;
  cf.face = background.face;
  glue_triangulation(background, cf);
  const detail::Geometry g = detail::compute_geometry(cf);
  const bool uniform = options.exact_uniform && detail::set_exact_uniform_field(cf, g);
  bool revolution = !uniform && options.exact_revolution && axis.has_value() &&
                    detail::set_revolution_field(cf, g, *axis);
  CrossFieldOptions solve_options = options;
  if (axis.has_value() && options.stall_window == 0)
    solve_options.stall_window = options.revolution_stall_window;
  if (!uniform && !revolution) detail::diffuse(cf, g, solve_options, lane);
  detail::compute_directions(cf, g);
  detail::find_singularities(cf, g, options);
  if (revolution && (!cf.singularities.empty() || !cf.euler.consistent)) {
    // The parallels' cross turns around a pole inside the face, or does not fit its corners: the
    // shortcut does not hold, the face is solved as any other.
    revolution = false;
    cf.stats.solver.clear();
    detail::diffuse(cf, g, solve_options, lane);
    detail::compute_directions(cf, g);
    detail::find_singularities(cf, g, options);
  }
  if (uniform || (revolution && axis->cylinder)) {
    // A constant cross on a plane, or the parallels' cross on a cylinder (developable: unrolled,
    // it is constant), does not rotate: the right-hand side of Eq. 9 is zero.
    cf.H.assign(cf.points.size(), 0.0);
    cf.h.assign(cf.points.size(), 1.0);
  } else {
    detail::compute_scaling(cf, g, options, lane);
  }
  cf.stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return cf;
}

void shrink_cross_field(FaceCrossField& cf, CrossFieldUse use) {
  // Swaps with empty vectors: clear() would keep the capacity.
  std::vector<std::int8_t>().swap(cf.vertex_dim);
  std::vector<std::array<LO, 3>>().swap(cf.tri2edges);
  std::vector<std::uint8_t>().swap(cf.boundary_edge);
  std::vector<std::uint8_t>().swap(cf.fixed_edge);
  std::vector<Vec2>().swap(cf.u);
  std::vector<double>().swap(cf.u_norm);
  if (use == CrossFieldUse::Guide) {
    std::vector<Vec3>().swap(cf.points);
    std::vector<std::array<LO, 2>>().swap(cf.edges);
    std::vector<double>().swap(cf.H);
    std::vector<double>().swap(cf.h);
  }
}

}  // namespace qsmesh::crossfield
