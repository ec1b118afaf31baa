#include "quantized_curves.hpp"

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/core/tasks.hpp"
#include "qsmesh/quantize/quantize.hpp"

namespace qsmesh::test {

QuantizedCurves quantized_curves(const cad::CadModel& model, double size) {
  const TaskArena tasks(1);
  background::SizeOptions sizes;
  sizes.size = size;
  const auto bg = background::mesh_curves(model, sizes, tasks);
  std::vector<std::vector<double>> at;
  for (const auto& m : bg) at.emplace_back(m.points.size(), size);
  quantize::QuantizeOptions qo;
  qo.halved_minimums = true;
  const auto q = quantize::quantize_curves(model, quantize::ideal_edge_counts(bg, at), qo);
  QuantizedCurves c;
  c.background = bg;
  c.full = quantize::place_vertices(model, bg, at, q, false, tasks);
  c.halved = quantize::place_vertices(model, bg, at, q, true, tasks);
  return c;
}

}  // namespace qsmesh::test
