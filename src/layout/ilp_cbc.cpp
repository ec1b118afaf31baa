#include <coin/Cbc_C_Interface.h>

#include <cmath>
#include <limits>
#include <memory>

#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/layout/ilp.hpp"

namespace qsmesh::layout {

IlpResult solve_integer_program(const IntegerProgram& p, const IlpOptions& options) {
  const int n = p.num_variables();
  QSMESH_CHECK(p.lower.size() == static_cast<std::size_t>(n) &&
                   p.upper.size() == static_cast<std::size_t>(n),
               "ilp: bounds do not match the variables");
  Stopwatch clock;
  IlpResult out;
  // Column-major matrix, as Cbc_loadProblem takes it.
  std::vector<int> start(static_cast<std::size_t>(n) + 1, 0);
  for (const auto& r : p.rows)
    for (const auto& [v, c] : r.terms) {
      QSMESH_CHECK(v >= 0 && v < n, "ilp: row names variable " << v);
      ++start[static_cast<std::size_t>(v) + 1];
    }
  for (int v = 0; v < n; ++v)
    start[static_cast<std::size_t>(v) + 1] += start[static_cast<std::size_t>(v)];
  std::vector<int> index(static_cast<std::size_t>(start.back()));
  std::vector<double> value(index.size());
  std::vector<int> fill(start.begin(), start.end() - 1);
  std::vector<double> row_lo, row_hi;
  for (std::size_t r = 0; r < p.rows.size(); ++r) {
    for (const auto& [v, c] : p.rows[r].terms) {
      const auto k = static_cast<std::size_t>(fill[static_cast<std::size_t>(v)]++);
      index[k] = static_cast<int>(r);
      value[k] = c;
    }
    row_lo.push_back(p.rows[r].lo);
    row_hi.push_back(p.rows[r].hi);
  }
  std::unique_ptr<Cbc_Model, void (*)(Cbc_Model*)> model(Cbc_newModel(), Cbc_deleteModel);
  Cbc_loadProblem(model.get(), n, static_cast<int>(p.rows.size()), start.data(), index.data(),
                  value.data(), p.lower.data(), p.upper.data(), p.objective.data(), row_lo.data(),
                  row_hi.data());
  for (int v = 0; v < n; ++v) Cbc_setInteger(model.get(), v);
  Cbc_setLogLevel(model.get(), 0);
  // One thread and no randomised restarts: the same program gives the same branch and bound.
  Cbc_setParameter(model.get(), "threads", "0");
  Cbc_setParameter(model.get(), "randomSeed", "1");
  Cbc_setParameter(model.get(), "randomCbcSeed", "1");
  if (options.time_limit_s > 0) Cbc_setMaximumSeconds(model.get(), options.time_limit_s);
  if (!options.preprocess) Cbc_setParameter(model.get(), "preprocess", "off");
  const int rc = Cbc_solve(model.get());
  out.optimal = Cbc_isProvenOptimal(model.get()) != 0;
  const double* x = Cbc_getColSolution(model.get());
  bool integral = x != nullptr && rc >= 0 && Cbc_isProvenInfeasible(model.get()) == 0;
  if (integral) {
    out.x.resize(static_cast<std::size_t>(n));
    for (int v = 0; v < n; ++v) {
      const double r = std::round(x[v]);
      if (std::abs(r - x[v]) > 1e-6) integral = false;
      out.x[static_cast<std::size_t>(v)] = static_cast<long>(r);
    }
  }
  // A returned point is only used when it satisfies every row and bound exactly.
  if (integral) {
    for (int v = 0; v < n && integral; ++v) {
      const auto xv = static_cast<double>(out.x[static_cast<std::size_t>(v)]);
      integral = xv >= p.lower[static_cast<std::size_t>(v)] - 1e-9 &&
                 xv <= p.upper[static_cast<std::size_t>(v)] + 1e-9;
    }
    for (const auto& r : p.rows) {
      double s = 0;
      for (const auto& [v, c] : r.terms)
        s += c * static_cast<double>(out.x[static_cast<std::size_t>(v)]);
      if (s < r.lo - 1e-6 || s > r.hi + 1e-6) integral = false;
    }
  }
  out.feasible = integral;
  if (!integral) out.x.clear();
  if (integral)
    for (int v = 0; v < n; ++v)
      out.objective += p.objective[static_cast<std::size_t>(v)] *
                       static_cast<double>(out.x[static_cast<std::size_t>(v)]);
  out.status = out.optimal                                ? "optimal"
               : integral                                 ? "feasible"
               : Cbc_isProvenInfeasible(model.get()) != 0 ? "infeasible"
                                                          : "failed";
  out.seconds = clock.seconds();
  return out;
}

}  // namespace qsmesh::layout
