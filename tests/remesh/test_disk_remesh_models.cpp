// Disk remeshing on the unstructured quad meshes of a shared CAD model (skipped without
// ../shared/cad): the serial flow of the pipeline up to the unstructured stage, then
// remesh_disk_defects on every all-quad face. Checks validity and the CAD boundary; prints the
// defect counts (the numbers of docs/benchmarks-style measurements).
#include <gtest/gtest.h>

#include <filesystem>
#include <iostream>
#include <map>
#include <tuple>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/background/face_mesh.hpp"
#include "qsmesh/cad/model.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/mesh/quality.hpp"
#include "qsmesh/quad/unstructured.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "qsmesh/remesh/disk_remesh.hpp"
#include "qsmesh/sizemap/size_map.hpp"

namespace qsmesh::remesh {
namespace {

LO invalid_quads(const mesh::FaceMesh& m) {
  LO n = 0;
  for (const auto& q : m.quads)
    n += mesh::quad_sicn({m.points[q[0]], m.points[q[1]], m.points[q[2]], m.points[q[3]]}) <= 0;
  return n;
}

std::map<std::tuple<int, LO, LO>, Vec3> cad_vertices(const mesh::FaceMesh& m) {
  std::map<std::tuple<int, LO, LO>, Vec3> out;
  for (LO v = 0; v < m.num_vertices(); ++v)
    if (m.vclass[v].dim != 2)
      out[{m.vclass[v].dim, m.vclass[v].entity, m.vclass[v].index}] = m.points[v];
  return out;
}

void run_model(const std::string& name, double size_factor) {
  const std::string path = std::string(QSMESH_SHARED_CAD_DIR) + "/" + name;
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " absent";
  const cad::CadModel model = cad::load_cad(path);
  background::BackgroundOptions bo;
  bo.sizes.size = model.diagonal() * size_factor;
  sizemap::SizeMapOptions so;
  so.size_max = bo.sizes.size;
  const TaskArena one(1);
  const auto curves = background::mesh_curves(model, bo.sizes, one);
  const auto initial = sizemap::initial_curve_sizes(model, curves, so, one);
  const auto targets = sizemap::face_quad_targets(model, so);
  sizemap::CurveSizes united = initial;
  for (LO f = 0; f < model.num_faces(); ++f) {
    const auto bg = background::mesh_face_background(model, f, curves, bo, nullptr);
    const auto cf = crossfield::compute_face_cross_field(bg, {}, nullptr);
    sizemap::fold_boundary_min(bg, sizemap::face_sizes(bg, &cf, curves, initial, targets[f], so).s,
                               united);
  }
  sizemap::grade_curves(model, curves, so.gradation, united);
  const auto q =
      quantize::quantize_curves(model, quantize::ideal_edge_counts(curves, united.at), {});
  const auto full = quantize::place_vertices(model, curves, united.at, q, false, one);
  quad::UnstructuredOptions qo;
  qo.size = bo.sizes.size;

  const DiskQuadTable table = DiskQuadTable::builtin();
  const DiskRemeshOptions options;
  LO faces = 0, before = 0, after = 0, replaced = 0, quads_before = 0, quads_after = 0;
  double sicn_min_before = 1, sicn_min_after = 1;
  for (LO f = 0; f < model.num_faces(); ++f) {
    quad::UnstructuredReport report;
    const mesh::FaceMesh m =
        quad::mesh_face_unstructured(model, f, full, quad::FaceFields{}, qo, &report);
    if (!report.ok || !m.triangles.empty() || m.quads.empty()) continue;
    const auto surface = model.face_geometry(f);
    DiskRemeshStats stats;
    const mesh::FaceMesh out = remesh_disk_defects(m, *surface, table, options, &stats);
    ++faces;
    before += stats.defects_before;
    after += stats.defects_after;
    replaced += stats.replaced;
    quads_before += static_cast<LO>(m.quads.size());
    quads_after += static_cast<LO>(out.quads.size());
    sicn_min_before = std::min(sicn_min_before, smooth::measure(m).sicn_min);
    sicn_min_after = std::min(sicn_min_after, smooth::measure(out).sicn_min);
    EXPECT_EQ(invalid_quads(out), 0) << "face " << f;
    EXPECT_EQ(cad_vertices(out), cad_vertices(m)) << "face " << f;
  }
  std::cout << name << " size factor " << size_factor << ": " << faces << " all-quad faces, quads "
            << quads_before << " -> " << quads_after << ", defects " << before << " -> " << after
            << " (" << replaced << " cavities replaced), SICN min " << sicn_min_before << " -> "
            << sicn_min_after << "\n";
  EXPECT_GT(faces, 0);
  EXPECT_LE(after, before);
}

TEST(DiskRemeshModels, T20Data) { run_model("t20_data.step", 0.05); }

}  // namespace
}  // namespace qsmesh::remesh
