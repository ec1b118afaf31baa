// Times the holomorphic basis on a plate with 9 holes (10 boundary loops), the size of paper 004's
// aneurysm (26,165 vertices, basis 165.6 s): bench_holomorphic SIZE DIR. Prints one line per stage.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "holo_shapes.hpp"
#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/holomorphic/holomorphic.hpp"

int main(int argc, char** argv) {
  using namespace qsmesh;
  if (argc != 3) {
    std::fprintf(stderr, "usage: bench_holomorphic SIZE DIR\n");
    return 2;
  }
  const double size = std::atof(argv[1]);
  std::vector<std::array<double, 3>> holes;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      holes.push_back({2.0 + 3.0 * i, 1.5 + 1.5 * j, 0.4 + 0.1 * ((i + j) % 3)});
  const cad::CadModel model = cad::load_cad(
      test::write_plate_with_holes(10, 6, holes, std::string(argv[2]) + "/bench_plate9.brep"));
  background::BackgroundOptions options;
  options.sizes.size = size;
  const TaskArena tasks(1);
  const auto curves = background::mesh_curves(model, options.sizes, tasks);
  background::FaceReport report;
  Stopwatch clock;
  const mesh::FaceMesh bg = background::mesh_face_background(model, 0, curves, options, &report);
  const double t_background = clock.seconds();
  clock.reset();
  const holomorphic::PolyAnnulus s = holomorphic::poly_annulus(bg);
  const double t_topology = clock.seconds();
  if (!s.ok) {
    std::fprintf(stderr, "not a poly-annulus: %s\n", s.reason.c_str());
    return 1;
  }
  clock.reset();
  const holomorphic::HolomorphicBasis B = holomorphic::holomorphic_basis(s, {}, nullptr);
  const double t_basis = clock.seconds();
  const holomorphic::EnergyResult E = holomorphic::minimize_area_distortion(s, B, {});
  const holomorphic::ZeroReport Z = holomorphic::find_zeros(s, holomorphic::combine(B, E.lambda));
  std::printf("vertices %d triangles %zu boundary_loops %zu\n", s.num_vertices(),
              s.triangles.size(), s.loops.size());
  std::printf("background_s %.3f topology_s %.3f basis_s %.3f (factorizations %d, solves %d)\n",
              t_background, t_topology, t_basis, B.factorizations, B.solves);
  std::printf("optimisation_s %.3f iterations %d converged %d energy %.6g -> %.6g\n", E.seconds,
              E.iterations, E.converged ? 1 : 0, E.energy.front(), E.energy.back());
  std::printf("interior_zeros %zu boundary_zeros %zu flipped %d index_sum %.6f\n",
              Z.interior.size(), Z.boundary.size(), Z.flipped, Z.index_sum);
  std::printf("paper_basis_s 165.61 speedup %.1f\n", 165.61 / t_basis);
  return 0;
}
