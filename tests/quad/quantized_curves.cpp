#include "quantized_curves.hpp"

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/core/tasks.hpp"

namespace qsmesh::test {
namespace {

// Background curve meshes at `size`, the uniform sizes on them, and their quantization.
struct Quantized {
  std::vector<mesh::CurveMesh> background;
  std::vector<std::vector<double>> at;
  quantize::Quantization q;
};

Quantized quantize_uniform(const cad::CadModel& model, double size,
                           const quantize::QuantizeOptions& options, const TaskArena& tasks) {
  background::SizeOptions sizes;
  sizes.size = size;
  Quantized out;
  out.background = background::mesh_curves(model, sizes, tasks);
  for (const auto& m : out.background) out.at.emplace_back(m.points.size(), size);
  out.q = quantize::quantize_curves(model, quantize::ideal_edge_counts(out.background, out.at),
                                    options);
  return out;
}

}  // namespace

QuantizedCurves quantized_curves(const cad::CadModel& model, double size) {
  const TaskArena tasks(1);
  quantize::QuantizeOptions qo;
  qo.halved_minimums = true;
  const Quantized u = quantize_uniform(model, size, qo, tasks);
  QuantizedCurves c;
  c.background = u.background;
  c.full = quantize::place_vertices(model, u.background, u.at, u.q, false, tasks);
  c.halved = quantize::place_vertices(model, u.background, u.at, u.q, true, tasks);
  return c;
}

std::vector<mesh::CurveMesh> quantized_full_curves(const cad::CadModel& model, double size,
                                                   const quantize::QuantizeOptions& options,
                                                   std::vector<int>* edges) {
  const TaskArena tasks(1);
  const Quantized u = quantize_uniform(model, size, options, tasks);
  if (edges != nullptr) *edges = u.q.edges;
  return quantize::place_vertices(model, u.background, u.at, u.q, false, tasks);
}

}  // namespace qsmesh::test
