// A face's system split over the ranks (SolverOptions::distributed_threshold, a group lane): the
// solve really runs on every rank, its solution is the correctly rounded one whatever the rank
// count, and the mesh path gives the same fields as Eigen and the same mesh at 1, 2 and 4 ranks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "qsmesh/linalg/solver.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "shapes.hpp"

namespace qsmesh::parallel {
namespace {

using linalg::SparseMatrix;

// One rank lane per process, as the drivers make it: made after MPI, gone before it ends.
class LaneEnvironment : public ::testing::Environment {
 public:
  void SetUp() override { lane_ = std::make_unique<linalg::SolverLane>(); }
  void TearDown() override { lane_.reset(); }
  static inline std::unique_ptr<linalg::SolverLane> lane_;
};
[[maybe_unused]] ::testing::Environment* const kLaneEnvironment =
    ::testing::AddGlobalTestEnvironment(new LaneEnvironment);

linalg::SolverLane& rank_lane() { return *LaneEnvironment::lane_; }

// An SPD system like the heat systems: a 2D Laplacian on an m x m grid with a mass term, two
// unknowns per node coupled by a rotation-like block.
SparseMatrix heat_like(LO m) {
  std::vector<SparseMatrix::Triplet> t;
  const auto id = [m](LO i, LO j) { return 2 * (i * m + j); };
  for (LO i = 0; i < m; ++i)
    for (LO j = 0; j < m; ++j) {
      const LO r = id(i, j);
      for (int a = 0; a < 2; ++a) t.push_back({r + a, r + a, 4.7 + 0.001 * ((i * 7 + j) % 5)});
      t.push_back({r, r + 1, 0.3});
      t.push_back({r + 1, r, 0.3});
      const std::pair<LO, LO> next[2] = {{i + 1, j}, {i, j + 1}};
      for (const auto& [ni, nj] : next) {
        if (ni >= m || nj >= m) continue;
        const LO s = id(ni, nj);
        for (int a = 0; a < 2; ++a) {
          t.push_back({r + a, s + a, -1.0});
          t.push_back({s + a, r + a, -1.0});
        }
      }
    }
  return SparseMatrix(2 * m * m, t);
}

TEST(DistributedSolve, SplitsTheRowsAndGivesTheSameBitsAtEveryRankCount) {
  const Comm comm = Comm::world();
  const SparseMatrix A = heat_like(30);  // 1800 unknowns
  const auto n = static_cast<std::size_t>(A.size());
  std::vector<double> b(n);
  for (std::size_t i = 0; i < n; ++i) b[i] = std::sin(0.37 * static_cast<double>(i)) + 0.1;
  linalg::SolverOptions options;
  options.distributed_threshold = 1000;

  const auto solve = [&](const Comm& c, linalg::DistributedReport& report, std::string& name) {
    const auto group = c.solver_group();
    linalg::SolverLane lane(rank_lane(), *group);
    auto solver = linalg::make_solver(A.size(), options, &lane);
    solver->analyze(A);
    SparseMatrix B = A;
    for (double& v : B.values()) v *= 1.5;  // a first level, then the real one
    solver->factorize(B);
    std::vector<double> x(n);
    solver->solve(b, x);
    solver->factorize(A);
    solver->solve(b, x);
    report = lane.report();
    name = solver->name();
    return x;
  };
  linalg::DistributedReport report;
  std::string name;
  const std::vector<double> x = solve(comm, report, name);
  EXPECT_EQ(name, "petsc/mumps-cholesky-mpi" + std::to_string(comm.size()));
  // Every rank assembled its own block of rows.
  EXPECT_EQ(report.ranks, comm.size());
  EXPECT_EQ(report.unknowns, A.size());
  ASSERT_EQ(report.rows_per_rank.size(), static_cast<std::size_t>(comm.size()));
  for (const LO rows : report.rows_per_rank) EXPECT_GE(rows, A.size() / comm.size() - 1);
  EXPECT_EQ(std::accumulate(report.rows_per_rank.begin(), report.rows_per_rank.end(), LO{0}),
            A.size());
  EXPECT_EQ(report.solves, 2);

  // The residual is at the rounding level, and Eigen agrees.
  std::vector<double> r(n);
  A.multiply(x, r);
  double worst = 0;
  for (std::size_t i = 0; i < n; ++i) worst = std::max(worst, std::abs(r[i] - b[i]));
  EXPECT_LT(worst, 1e-11);  // the solution is rounded to 2^-40 of its largest entry
  linalg::SolverOptions eigen;
  eigen.backend = linalg::Backend::Eigen;
  auto e = linalg::make_solver(A.size(), eigen, nullptr);
  e->analyze(A);
  e->factorize(A);
  std::vector<double> xe(n);
  e->solve(b, xe);
  for (std::size_t i = 0; i < n; ++i) ASSERT_NEAR(x[i], xe[i], 1e-12) << i;

  // One rank alone gets the same bits.
  if (comm.rank() != 0) return;
  linalg::DistributedReport alone;
  const std::vector<double> x1 = solve(Comm::self(), alone, name);
  EXPECT_EQ(alone.ranks, 1);
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(x[i], x1[i]) << i;
}

TEST(DistributedSolve, FaceAboveTheThresholdIsSplitOverTheRanksAlikeOnEveryRankCount) {
  const Comm comm = Comm::world();
  const std::string path =
      std::string(QSMESH_TEST_TMP_DIR) + "/distributed_np" + std::to_string(comm.size()) + ".brep";
  if (comm.rank() == 0) test::write_teardrop(3.0, path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);

  PipelineOptions options;
  options.background.sizes.size = 0.2;  // the field system: about a thousand unknowns per level
  options.sizemap.size_max = 0.6;
  options.crossfield.solver.petsc_threshold = 300;
  options.crossfield.solver.petsc_threshold_complex = 300;
  options.crossfield.solver.distributed_threshold = 300;
  options.cross_fields = true;
  options.until = Stage::Unstructured;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log, &rank_lane());
  if (comm.rank() != 0) return;

  // The face's systems were split over every rank.
  ASSERT_EQ(dist.cross_fields.size(), 1u);
  const CrossFieldOutput& field = dist.cross_fields[0];
  ASSERT_TRUE(field.ok) << field.error;
  EXPECT_EQ(field.solver, "petsc/mumps-cholesky-mpi" + std::to_string(comm.size()));
  EXPECT_EQ(field.solver_ranks, comm.size());
  ASSERT_EQ(field.rows_per_rank.size(), static_cast<std::size_t>(comm.size()));
  for (const LO rows : field.rows_per_rank) EXPECT_GT(rows, 300 / comm.size());

  // The same mesh as one rank and one thread, also through the split path (a group of one).
  const PipelineResult one =
      run_pipeline(Comm::self(), model, options, TaskArena(1), log, &rank_lane());
  EXPECT_EQ(one.cross_fields[0].solver, "petsc/mumps-cholesky-mpi1");
  ASSERT_EQ(dist.mesh.points.size(), one.mesh.points.size());
  for (std::size_t i = 0; i < one.mesh.points.size(); ++i)
    ASSERT_EQ(dist.mesh.points[i], one.mesh.points[i]) << i;
  EXPECT_EQ(dist.mesh.quads, one.mesh.quads);
  EXPECT_GT(dist.mesh.quads.size(), 50u);
  const auto conformity = mesh::check_conformity(dist.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();

  // The fields equal Eigen's to 1e-8.
  const PipelineResult eigen =
      run_pipeline(Comm::self(), model, options, TaskArena(1), log, nullptr);
  const CrossFieldOutput& e = eigen.cross_fields[0];
  ASSERT_TRUE(e.ok) << e.error;
  EXPECT_EQ(e.solver.rfind("eigen", 0), 0u) << e.solver;
  ASSERT_EQ(field.directions.size(), e.directions.size());
  double worst = 0;
  for (std::size_t t = 0; t < e.directions.size(); ++t)
    for (int k = 0; k < 2; ++k)
      worst = std::max(worst, norm(field.directions[t][k] - e.directions[t][k]));
  EXPECT_LT(worst, 1e-8);
  ASSERT_EQ(field.H.size(), e.H.size());
  for (std::size_t t = 0; t < e.H.size(); ++t) ASSERT_NEAR(field.H[t], e.H[t], 1e-8) << t;
  EXPECT_EQ(field.singularities.size(), e.singularities.size());
}

}  // namespace
}  // namespace qsmesh::parallel
