// compute_face_cross_field: the stages of step 1 for one face, in order.
#include <chrono>

#include "internal.hpp"

namespace qsmesh::crossfield {

FaceCrossField compute_face_cross_field(const mesh::FaceMesh& background,
                                        const CrossFieldOptions& options, linalg::PetscLane* lane) {
  const auto start = std::chrono::steady_clock::now();
  FaceCrossField cf;
  cf.face = background.face;
  glue_triangulation(background, cf);
  const detail::Geometry g = detail::compute_geometry(cf);
  detail::diffuse(cf, g, options, lane);
  detail::compute_directions(cf, g);
  detail::find_singularities(cf, g, options);
  detail::compute_scaling(cf, g, options, lane);
  cf.stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return cf;
}

}  // namespace qsmesh::crossfield
