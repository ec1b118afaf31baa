// A small integer linear program and the solver behind it (paper 002 Sec. III.B-C: the quantization
// of the T-mesh). No solver type appears here; the implementation links Debian's COIN-OR CBC
// (docs/architecture.md says why CBC and not GLPK).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace qsmesh::layout {

/// min objective . x  subject to  lower <= x <= upper, x integer, and every row's
/// lo <= sum(coef * x[var]) <= hi (use +-infinity for a one-sided row).
struct IntegerProgram {
  std::vector<double> objective;  ///< one per variable
  std::vector<double> lower, upper;
  struct Row {
    std::vector<std::pair<int, double>> terms;  ///< (variable, coefficient), each variable once
    double lo = 0, hi = 0;
  };
  std::vector<Row> rows;
  [[nodiscard]] int num_variables() const { return static_cast<int>(objective.size()); }
};

struct IlpOptions {
  /// Wall-clock bound on the branch and bound (0: none). A run stopped by it returns its best
  /// feasible solution, which then depends on timing: the default leaves it to the fallback.
  double time_limit_s = 120;
  /// CBC's preprocessing of the integer program. Off for the T-meshes whose traces cross smooth
  /// curves (CoarseOptions::traces_across_smooth_curves): on A319 Debian's CBC 2.10 stopped the
  /// process there with a failed assertion in Clp (ClpNonLinearCost.cpp:1064, "lowerValue <=
  /// upperValue") on the first solve, a program that the input lengths satisfy.
  bool preprocess = true;
};

struct IlpResult {
  bool feasible = false;  ///< x holds a feasible integer solution
  bool optimal = false;   ///< and it is proven optimal
  std::vector<long> x;
  double objective = 0;
  double seconds = 0;
  std::string status;  ///< a word for the log: "optimal", "feasible", "infeasible", "failed"
};

/// Solves `program` on one thread with fixed options, so the same program gives the same solution.
/// Preconditions: lower, upper and objective have num_variables() entries; every row term names
/// a variable in [0, num_variables()). Never throws for an infeasible program (feasible = false).
[[nodiscard]] IlpResult solve_integer_program(const IntegerProgram& program,
                                              const IlpOptions& options = {});

}  // namespace qsmesh::layout
