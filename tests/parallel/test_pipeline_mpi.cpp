// Run by ctest at 1, 2 and 4 ranks: the distributed pipeline must give, on rank 0, exactly the
// mesh that a serial run gives.
#include <gtest/gtest.h>
#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <functional>
#include <numeric>
#include <sstream>

#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/crossfield/cross_field.hpp"
#include "qsmesh/mesh/assemble.hpp"
#include "qsmesh/mesh/validate.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/parallel/pipeline.hpp"
#include "qsmesh/parallel/record.hpp"
#include "qsmesh/quantize/quantize.hpp"
#include "qsmesh/sizemap/size_map.hpp"
#include "shapes.hpp"

namespace qsmesh::parallel {
namespace {

std::string tmp(const std::string& name) { return std::string(QSMESH_TEST_TMP_DIR) + "/" + name; }

/// The path of a filleted box that rank 0 writes, once every rank may read it.
std::string written_box(const Comm& comm, const std::string& name) {
  const std::string path = tmp(name + "_np" + std::to_string(comm.size()) + ".step");
  if (comm.rank() == 0) test::write_filleted_box(path);
  comm.barrier();
  return path;
}

/// Rank 0 writes the model, everybody reads it (every rank reads the CAD file itself).
cad::CadModel shared_model(const Comm& comm, const std::string& name) {
  return cad::load_cad(written_box(comm, name));
}

TEST(MeasureSplit, FaceAreasSplitOverRanksAndThreadsAreTheSerialOnes) {
  const Comm comm = Comm::world();
  const std::string path = written_box(comm, "measured_box");
  const cad::CadModel serial = cad::load_cad(path);
  const TaskArena two(2);
  SplitRound round;
  std::atomic<int> measured{0};
  cad::LoadOptions options;
  options.measure_faces = [&](LO n, const std::function<double(LO)>& area) {
    return measure_split(
        comm, two, n,
        [&](LO f) {
          ++measured;
          return area(f);
        },
        &round);
  };
  const cad::CadModel split = cad::load_cad(path, options);
  const LO nf = serial.num_faces();
  ASSERT_EQ(split.num_faces(), nf);
  for (LO f = 0; f < nf; ++f) {
    EXPECT_GT(serial.faces()[f].area, 0.0) << "face " << f;
    // Computed once, on one rank, and copied bit for bit.
    EXPECT_EQ(split.faces()[f].area, serial.faces()[f].area) << "face " << f;
  }
  // Each face measured once over all ranks, dealt evenly: this rank did its share.
  std::vector<std::int64_t> count{measured.load()};
  comm.allreduce_sum(count);
  EXPECT_EQ(count[0], nf);
  EXPECT_LE(measured.load(), (nf + comm.size() - 1) / comm.size());
  ASSERT_EQ(static_cast<LO>(round.item_seconds.size()), nf);
  EXPECT_EQ(round.weights, std::vector<double>(static_cast<std::size_t>(nf), 1.0));
  EXPECT_EQ(round.bytes, static_cast<std::int64_t>(nf) *
                             static_cast<std::int64_t>(sizeof(LO) + 2 * sizeof(double)));
  for (LO f = 0; f < nf; ++f) EXPECT_GE(round.item_seconds[f], 0.0);
}

TEST(Comm, ReductionsAndGather) {
  const Comm comm = Comm::world();
  std::vector<std::int64_t> v{1, static_cast<std::int64_t>(comm.rank())};
  comm.allreduce_sum(v);
  EXPECT_EQ(v[0], comm.size());
  EXPECT_EQ(v[1], static_cast<std::int64_t>(comm.size()) * (comm.size() - 1) / 2);
  EXPECT_EQ(comm.allreduce_max(comm.rank()), comm.size() - 1);
  std::vector<double> m{static_cast<double>(comm.rank()), 5.0 - comm.rank()};
  comm.allreduce_min(m);
  EXPECT_EQ(m, (std::vector<double>{0.0, 5.0 - (comm.size() - 1)}));
  EXPECT_FALSE(comm.allreduce_and(comm.rank() != 0));
  const std::vector<char> mine(static_cast<std::size_t>(comm.rank()) + 1,
                               static_cast<char>('a' + comm.rank()));
  const auto all = comm.gather_bytes(mine, 0);
  if (comm.rank() == 0) {
    ASSERT_EQ(static_cast<int>(all.size()), comm.size());
    for (int r = 0; r < comm.size(); ++r)
      EXPECT_EQ(all[r], std::vector<char>(r + 1, static_cast<char>('a' + r)));
  } else {
    EXPECT_TRUE(all.empty());
  }
  std::vector<char> b;
  if (comm.rank() == 0) b = {'x', 'y', 'z'};
  comm.broadcast_bytes(b, 0);
  EXPECT_EQ(b, (std::vector<char>{'x', 'y', 'z'}));
}

// The counter that deals out the improvement stage: every value below the total goes to exactly
// one caller, over all ranks and two threads each.
TEST(Comm, SharedCounterHandsOutEachValueOnce) {
  const Comm comm = Comm::world();
  constexpr std::int64_t kTotal = 200;
  std::vector<std::int64_t> hits(kTotal, 0);
  {
    SharedCounter counter(comm);
    const TaskArena two(2);
    two.parallel_for(2, [&](std::int64_t) {
      for (std::int64_t k = counter.next(); k < kTotal; k = counter.next()) ++hits[k];
    });
  }
  comm.allreduce_sum(hits);
  for (std::int64_t k = 0; k < kTotal; ++k) EXPECT_EQ(hits[k], 1) << k;
}

// Rank r's byte i is (r * 31 + i) mod 251: a wrong owner or offset reads other values.
char byte_of(int rank, std::int64_t i) { return static_cast<char>((rank * 31 + i) % 251); }

TEST(Comm, SharedBytesReadsAnyRanksBytesWhileCounterRuns) {
  const Comm comm = Comm::world();
  const int n = comm.size();
  // Ranks hold different amounts, one of them none at all.
  const std::int64_t mine_size = comm.rank() == 1 ? 0 : 1000 + 37 * comm.rank();
  std::vector<char> mine(static_cast<std::size_t>(mine_size));
  for (std::int64_t i = 0; i < mine_size; ++i) mine[i] = byte_of(comm.rank(), i);
  constexpr std::int64_t kReads = 120;
  std::vector<std::int64_t> bad(1, 0), done(1, 0);
  {
    SharedBytes shared(comm, mine);
    SharedCounter counter(comm);
    const TaskArena two(2);
    std::atomic<std::int64_t> wrong{0}, count{0};
    // Two threads per rank mix counter calls and reads, as the improvement stage does.
    two.parallel_for(2, [&](std::int64_t) {
      for (std::int64_t k = counter.next(); k < kReads; k = counter.next()) {
        const int owner = static_cast<int>(k % n);
        const std::int64_t size = owner == 1 ? 0 : 1000 + 37 * owner;
        const std::int64_t offset = size == 0 ? 0 : (k * 97) % size;
        const std::int64_t length = std::min<std::int64_t>(size - offset, 1 + k % 300);
        const std::vector<char> got = shared.read(owner, offset, length);
        if (static_cast<std::int64_t>(got.size()) != length) ++wrong;
        for (std::int64_t i = 0; i < static_cast<std::int64_t>(got.size()); ++i)
          if (got[i] != byte_of(owner, offset + i)) ++wrong;
        ++count;
      }
    });
    bad[0] = wrong;
    done[0] = count;
    // A range past the owner's bytes is refused, not read.
    EXPECT_THROW((void)shared.read(0, 0, 1001), qsmesh::Error);
    EXPECT_THROW((void)shared.read(n, 0, 1), qsmesh::Error);
  }
  comm.allreduce_sum(bad);
  comm.allreduce_sum(done);
  EXPECT_EQ(bad[0], 0);
  EXPECT_EQ(done[0], kReads);
}

TEST(Comm, AlltoallBytesDeliversEachBufferToItsRank) {
  const Comm comm = Comm::world();
  const int n = comm.size(), me = comm.rank();
  // Rank s sends rank r (s + 1) * (r + 2) bytes of value s * 10 + r (nothing from 0 to 1).
  std::vector<std::vector<char>> to_each(static_cast<std::size_t>(n));
  for (int r = 0; r < n; ++r)
    if (!(me == 0 && r == 1))
      to_each[r].assign(static_cast<std::size_t>((me + 1) * (r + 2)),
                        static_cast<char>(me * 10 + r));
  const auto got = comm.alltoall_bytes(to_each);
  ASSERT_EQ(static_cast<int>(got.size()), n);
  for (int s = 0; s < n; ++s) {
    const std::size_t expected =
        s == 0 && me == 1 ? 0 : static_cast<std::size_t>((s + 1) * (me + 2));
    EXPECT_EQ(got[s].size(), expected) << "from " << s;
    for (char c : got[s]) EXPECT_EQ(c, static_cast<char>(s * 10 + me)) << "from " << s;
  }
  EXPECT_THROW((void)comm.alltoall_bytes(std::vector<std::vector<char>>(n + 1)), qsmesh::Error);
}

TEST(Comm, GatherBytesEachHandsOverOneRankAtATime) {
  const Comm comm = Comm::world();
  const int n = comm.size(), me = comm.rank();
  // Rank r sends 3 * r + 1 bytes of value r; the root sees them in rank order, its own moved in.
  std::vector<char> mine(static_cast<std::size_t>(3 * me + 1), static_cast<char>(me));
  const char* own_data = mine.data();
  std::vector<int> seen;
  comm.gather_bytes_each(std::move(mine), 0, [&](int r, std::vector<char>& bytes) {
    seen.push_back(r);
    EXPECT_EQ(bytes.size(), static_cast<std::size_t>(3 * r + 1)) << "from " << r;
    for (char c : bytes) EXPECT_EQ(c, static_cast<char>(r)) << "from " << r;
    if (r == 0) {
      EXPECT_EQ(bytes.data(), own_data);  // moved, not copied
    }
    bytes.clear();  // the callee may take or drop the buffer
  });
  if (me == 0) {
    std::vector<int> expected(static_cast<std::size_t>(n));
    std::iota(expected.begin(), expected.end(), 0);
    EXPECT_EQ(seen, expected);
  } else {
    EXPECT_TRUE(seen.empty());
  }
}

TEST(Pipeline, DistributedEqualsSerial) {
  const Comm comm = Comm::world();
  const cad::CadModel model = shared_model(comm, "pipe_fillet");
  PipelineOptions options;
  options.background.sizes.size = 0.6;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const TaskArena tasks(2);
  const PipelineResult result = run_pipeline(comm, model, options, tasks, log);

  // Every face is assigned to exactly one existing rank.
  ASSERT_EQ(static_cast<LO>(result.face_rank.size()), model.num_faces());
  for (int r : result.face_rank) EXPECT_TRUE(r >= 0 && r < comm.size());
  EXPECT_GT(result.times.get("background"), 0.0);
  // Every rank has every rank's own time in the per-face stages; here the background stage alone,
  // whose recorded time is the slowest rank's.
  ASSERT_EQ(static_cast<int>(result.rank_busy_seconds.size()), comm.size());
  std::vector<int> faces_of(static_cast<std::size_t>(comm.size()), 0);
  for (int r : result.face_rank) ++faces_of[static_cast<std::size_t>(r)];
  for (int r = 0; r < comm.size(); ++r) {
    if (faces_of[static_cast<std::size_t>(r)] > 0) {
      EXPECT_GT(result.rank_busy_seconds[r], 0.0) << r;
    }
  }
  EXPECT_EQ(*std::max_element(result.rank_busy_seconds.begin(), result.rank_busy_seconds.end()),
            result.times.get("background"));

  // The curves stage in two rounds split by curve over the ranks (sampling, then feature sizes):
  // every rank knows every curve's weight and time, and the bytes the all-gather moves are those
  // of every curve's record, at any rank count.
  const LO ncurves = model.num_curves();
  ASSERT_EQ(result.curve_rounds.size(), 2U);
  const background::CurveMeshing meshing(model, options.background.sizes);
  std::vector<std::int64_t> record_sizes(2, 0);
  for (LO c = 0; c < ncurves; ++c) {
    const background::CurveSamples samples = meshing.sample(c);
    const auto head = static_cast<std::int64_t>(sizeof(LO) + sizeof(double));
    record_sizes[0] += head + record_bytes(samples);
    record_sizes[1] += head + record_bytes(samples.h);
  }
  for (std::size_t k = 0; k < 2; ++k) {
    const SplitRound& round = result.curve_rounds[k];
    ASSERT_EQ(static_cast<LO>(round.weights.size()), ncurves);
    ASSERT_EQ(static_cast<LO>(round.item_seconds.size()), ncurves);
    EXPECT_EQ(round.bytes, record_sizes[k]) << "round " << k + 1;
    EXPECT_GT(round.seconds, 0.0);
    double work = 0;
    for (LO c = 0; c < ncurves; ++c) {
      EXPECT_GE(round.item_seconds[c], 0.0);
      work += round.item_seconds[c];
    }
    EXPECT_GT(work, 0.0) << "round " << k + 1;
  }
  EXPECT_EQ(result.curve_rounds[0].weights[0], meshing.sampling_cost(0));
  // The rounds' times are in the stage's.
  EXPECT_LE(result.curve_rounds[0].seconds + result.curve_rounds[1].seconds,
            result.times.get("curves"));

  if (comm.rank() != 0) return;
  // The serial reference: the same stage functions, no MPI, one thread.
  const TaskArena one(1);
  const auto curves = background::mesh_curves(model, options.background.sizes, one);
  std::vector<mesh::FaceMesh> faces(static_cast<std::size_t>(model.num_faces()));
  for (LO f = 0; f < model.num_faces(); ++f)
    faces[f] = background::mesh_face_background(model, f, curves, options.background, nullptr);
  const mesh::SurfaceMesh serial = mesh::assemble(model, curves, faces);

  const mesh::SurfaceMesh& dist = result.mesh;
  ASSERT_EQ(dist.points.size(), serial.points.size());
  for (std::size_t i = 0; i < serial.points.size(); ++i)
    ASSERT_EQ(dist.points[i], serial.points[i]) << i;
  EXPECT_EQ(dist.triangles, serial.triangles);
  EXPECT_EQ(dist.triangle_face, serial.triangle_face);
  EXPECT_EQ(dist.bars, serial.bars);
  ASSERT_EQ(static_cast<LO>(result.reports.size()), model.num_faces());
  for (const auto& r : result.reports) EXPECT_TRUE(r.ok) << r.error;
  const auto conformity = mesh::check_conformity(dist, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
}

TEST(Pipeline, CrossFieldsDoNotDependOnRanks) {
  const Comm comm = Comm::world();
  const cad::CadModel model = shared_model(comm, "pipe_cf");
  PipelineOptions options;
  options.background.sizes.size = 0.8;
  options.cross_fields = true;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult result = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  ASSERT_EQ(static_cast<LO>(result.cross_fields.size()), model.num_faces());
  const auto curves = background::mesh_curves(model, options.background.sizes, TaskArena(1));
  int consistent = 0;
  for (LO f = 0; f < model.num_faces(); ++f) {
    const auto face =
        background::mesh_face_background(model, f, curves, options.background, nullptr);
    const CrossFieldOutput serial = summarize(crossfield::compute_face_cross_field(
        face, options.crossfield, nullptr, cad::revolution_axis(model, f)));
    const CrossFieldOutput& dist = result.cross_fields[f];
    ASSERT_TRUE(dist.ok) << dist.error;
    ASSERT_EQ(dist.directions.size(), serial.directions.size());
    for (std::size_t t = 0; t < serial.directions.size(); ++t) {
      ASSERT_EQ(dist.directions[t][0], serial.directions[t][0]);
      ASSERT_EQ(dist.directions[t][1], serial.directions[t][1]);
    }
    EXPECT_EQ(dist.H, serial.H);
    ASSERT_EQ(dist.singularities.size(), serial.singularities.size());
    for (std::size_t k = 0; k < serial.singularities.size(); ++k) {
      EXPECT_EQ(dist.singularities[k].position, serial.singularities[k].position);
      EXPECT_EQ(dist.singularities[k].index, serial.singularities[k].index);
    }
    consistent += dist.euler.consistent ? 1 : 0;
  }
  // A box with filleted edges: flat faces, cylinders and sphere corners, all simple enough for the
  // Euler relation to hold everywhere.
  EXPECT_EQ(consistent, model.num_faces());
}

/// Runs the size map and quantization on `model` and checks, on every rank, that the curve data
/// equal those of the same stage functions run serially (no MPI), and that ranks agree. `out`, when
/// given, receives the distributed result for further checks.
// size_min_ratio > 0: the size map of the CLI's default (clamped) rules, no curvature sizes and
// the floor size_min_ratio x size; 0: SizeMapOptions' defaults (--sizing paper).
void check_size_map(const Comm& comm, const cad::CadModel& model, double size,
                    PipelineResult* out = nullptr, double size_min_ratio = 0) {
  PipelineOptions options;
  options.background.sizes.size = size;
  options.size_map = true;
  options.sizemap.size_max = size;
  if (size_min_ratio > 0) {
    options.sizemap.edges_per_turn = 0;
    options.sizemap.size_min = size_min_ratio * size;
  }
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  PipelineResult local;
  PipelineResult& result = out != nullptr ? *out : local;
  result = run_pipeline(comm, model, options, TaskArena(2), log);

  // Serial reference: every face on this process, the same flow.
  const TaskArena one(1);
  const auto curves = background::mesh_curves(model, options.background.sizes, one);
  const auto initial = sizemap::initial_curve_sizes(model, curves, options.sizemap, one);
  const auto targets = sizemap::face_quad_targets(model, options.sizemap);
  sizemap::CurveSizes united = initial;
  for (LO f = 0; f < model.num_faces(); ++f) {
    const auto bg = background::mesh_face_background(model, f, curves, options.background, nullptr);
    const auto cf = crossfield::compute_face_cross_field(bg, options.crossfield, nullptr,
                                                         cad::revolution_axis(model, f));
    const auto fs = sizemap::face_sizes(bg, &cf, curves, initial, targets[f], options.sizemap);
    sizemap::fold_boundary_min(bg, fs.s, united);
  }
  sizemap::grade_curves(model, curves, options.sizemap.gradation, united);
  EXPECT_EQ(result.curve_sizes.pack(), united.pack());
  auto q = quantize::quantize_curves(model, quantize::ideal_edge_counts(curves, united.at),
                                     options.quantize);
  q.edges = qstruct::balance_curve_counts(model, curves, q, qstruct::builtin_patterns(), {},
                                          options.balance);
  EXPECT_EQ(result.quantization.edges, q.edges);
  const auto placed = quantize::place_vertices(model, curves, united.at, q, false, one);
  ASSERT_EQ(result.quantized_curves.size(), placed.size());
  for (std::size_t c = 0; c < placed.size(); ++c) {
    EXPECT_EQ(result.quantized_curves[c].t, placed[c].t) << "curve " << c;
    ASSERT_EQ(result.quantized_curves[c].points.size(), placed[c].points.size());
    for (std::size_t i = 0; i < placed[c].points.size(); ++i)
      ASSERT_EQ(result.quantized_curves[c].points[i], placed[c].points[i]);
  }
  // Every rank holds the same counts: the sum of squares differs otherwise.
  std::int64_t mine = 0;
  for (int e : result.quantization.edges) mine += static_cast<std::int64_t>(e) * e;
  std::vector<std::int64_t> all{mine};
  comm.allreduce_sum(all);
  EXPECT_EQ(all[0], mine * comm.size());
}

// On rank 0: `dist` (the run on every rank) equals the run of the same options on one rank and
// one thread, point for point, and is a conforming all-quad mesh of at least `min_quads` quads
// whose every face has SICN min above `min_sicn`. Returns the one-rank run.
PipelineResult expect_quads_as_on_one_rank(const PipelineResult& dist, const cad::CadModel& model,
                                           const PipelineOptions& options, Logger& log,
                                           std::size_t min_quads, double min_sicn) {
  PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  EXPECT_EQ(dist.mesh.points.size(), serial.mesh.points.size());
  if (dist.mesh.points.size() != serial.mesh.points.size()) return serial;
  for (std::size_t i = 0; i < serial.mesh.points.size(); ++i) {
    EXPECT_EQ(dist.mesh.points[i], serial.mesh.points[i]) << i;
    if (dist.mesh.points[i] != serial.mesh.points[i]) break;
  }
  EXPECT_EQ(dist.mesh.quads, serial.mesh.quads);
  EXPECT_TRUE(dist.mesh.triangles.empty());
  EXPECT_GT(dist.mesh.quads.size(), min_quads);
  const auto conformity = mesh::check_conformity(dist.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  for (const auto& q : dist.quad_reports) EXPECT_TRUE(q.ok) << q.error;
  for (std::size_t f = 0; f < dist.face_stats.size(); ++f)
    EXPECT_GT(dist.face_stats[f].sicn_min, min_sicn) << "face " << f;
  return serial;
}

void check_quads_do_not_depend_on_ranks(Stage until, const std::string& name) {
  const Comm comm = Comm::world();
  const cad::CadModel model = shared_model(comm, name);
  PipelineOptions options;
  options.background.sizes.size = 0.7;
  options.sizemap.size_max = 0.7;
  options.until = until;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial = expect_quads_as_on_one_rank(dist, model, options, log, 500, 0.0);
  if (until == Stage::QuasiStructured) {
    ASSERT_EQ(dist.quasi_reports.size(), serial.quasi_reports.size());
    int by_pattern = 0;
    for (std::size_t f = 0; f < dist.quasi_reports.size(); ++f) {
      EXPECT_EQ(dist.quasi_reports[f].by_pattern, serial.quasi_reports[f].by_pattern);
      by_pattern += dist.quasi_reports[f].by_pattern ? 1 : 0;
    }
    EXPECT_GT(by_pattern, 0);  // the box's planar sides are simple faces
  }
}

// A half disk sized far coarser than itself, without curvature sizes: arc and diameter get 2 edges
// each, 1 each on the halved meshes, a loop enclosing nothing. The repair refines both on every
// rank alike (one rank owns the face, all take part in the sum of the flags).
TEST(Pipeline, CrossingBoundaryIsRepairedAlikeOnEveryRank) {
  const Comm comm = Comm::world();
  const std::string path = tmp("pipe_half_disk_np" + std::to_string(comm.size()) + ".brep");
  if (comm.rank() == 0) test::write_half_disk(5.0, path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  PipelineOptions options;
  options.background.sizes.size = 1.0;
  options.sizemap.size_max = 40.0;
  options.sizemap.edges_per_turn = 0;
  options.until = Stage::QuasiStructured;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  EXPECT_FALSE(dist.curves_refined_for_crossings.empty());  // every rank knows
  options.boundary_repair_rounds = 0;
  const PipelineResult unrepaired = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  ASSERT_EQ(dist.quad_reports.size(), 1u);
  EXPECT_TRUE(dist.quad_reports[0].ok) << dist.quad_reports[0].error;
  EXPECT_GT(dist.face_stats[0].sicn_min, 0);
  ASSERT_EQ(unrepaired.quad_reports.size(), 1u);
  EXPECT_FALSE(unrepaired.quad_reports[0].ok);  // the face was missing without the repair
  options.boundary_repair_rounds = 4;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  EXPECT_EQ(dist.quantization.edges, serial.quantization.edges);
  EXPECT_EQ(dist.mesh.quads, serial.mesh.quads);
  ASSERT_EQ(dist.mesh.points.size(), serial.mesh.points.size());
  for (std::size_t i = 0; i < serial.mesh.points.size(); ++i)
    ASSERT_EQ(dist.mesh.points[i], serial.mesh.points[i]);
}

TEST(Pipeline, QuadMeshDoesNotDependOnRanks) {
  check_quads_do_not_depend_on_ranks(Stage::Unstructured, "pipe_quads");
}

// With the background at the geometry's resolution (the program's default): on an L-shaped
// plate 30 wide the caps (diagonal / 8, about 5) bind against the size 1, and the background is
// coarser than the quads.
TEST(Pipeline, QuadMeshWithFieldsAtTheGeometrysResolutionDoesNotDependOnRanks) {
  const Comm comm = Comm::world();
  const std::string path = tmp("pipe_l_plate_np" + std::to_string(comm.size()) + ".brep");
  if (comm.rank() == 0)
    test::write_polygon_face({{0, 0}, {30, 0}, {30, 10}, {10, 10}, {10, 30}, {0, 30}}, path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  PipelineOptions options;
  options.background.sizes.size = 1.0;
  options.background.sizes.field_divisions = 8;
  options.sizemap.size_max = 1.0;
  options.until = Stage::QuasiStructured;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  (void)expect_quads_as_on_one_rank(dist, model, options, log, 300, 0.3);
  // The cap binds: the background at the target's resolution has more vertices.
  options.background.sizes.field_divisions = 0;
  options.until = Stage::Background;
  const PipelineResult target = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  options.background.sizes.field_divisions = 8;
  const PipelineResult coarse = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  EXPECT_GT(target.mesh.points.size(), 2 * coarse.mesh.points.size());
}

TEST(Pipeline, QuasiStructuredMeshDoesNotDependOnRanks) {
  check_quads_do_not_depend_on_ranks(Stage::QuasiStructured, "pipe_quasi");
}

// Pattern meshes refused by (here impossibly strict) quality thresholds are compared with what the
// unstructured path makes of the face, and kept where they are no worse. Returns the faces kept so.
int check_refused_patterns_compared(const Comm& comm, const cad::CadModel& model) {
  PipelineOptions options;
  options.background.sizes.size = 0.7;
  options.sizemap.size_max = 0.7;
  options.until = Stage::QuasiStructured;
  options.patterns.min_sicn = 0.999;
  options.patterns.min_sicn_avg = 0.999;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult compared = run_pipeline(comm, model, options, TaskArena(2), log);
  options.pattern_compare_tolerance = -1;
  const PipelineResult never = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return 0;
  options.pattern_compare_tolerance = 0.01;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  const auto nf = static_cast<std::size_t>(model.num_faces());
  EXPECT_EQ(compared.quasi_reports.size(), nf);
  EXPECT_EQ(never.face_stats.size(), nf);
  int taken = 0;
  const std::size_t checked =
      std::min({nf, compared.quasi_reports.size(), never.face_stats.size()});
  for (std::size_t f = 0; f < checked; ++f) {
    const QuasiReport& q = compared.quasi_reports[f];
    EXPECT_EQ(q.by_comparison, serial.quasi_reports[f].by_comparison) << "face " << f;
    EXPECT_FALSE(never.quasi_reports[f].by_comparison) << "face " << f;
    // Faces that pass even these thresholds (exact squares) are meshed by pattern either way.
    if (never.quasi_reports[f].by_pattern) {
      EXPECT_TRUE(q.by_pattern && !q.by_comparison) << "face " << f;
    }
    if (!q.by_comparison) continue;
    ++taken;
    EXPECT_TRUE(q.by_pattern);
    EXPECT_EQ(q.refusal, "quality");
    // The pattern mesh kept is no worse than the face's mesh without it.
    const mesh::FaceQuadStats& mine = compared.face_stats[f];
    const mesh::FaceQuadStats& other = never.face_stats[f];
    EXPECT_GT(mine.sicn_min, 0);
    EXPECT_GE(mine.sicn_min, other.sicn_min - 0.01) << "face " << f;
    EXPECT_GE(mine.sicn_avg, other.sicn_avg - 0.01) << "face " << f;
    EXPECT_LE(mine.irregular_interior, other.irregular_interior) << "face " << f;
  }
  const auto conformity = mesh::check_conformity(compared.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
  EXPECT_EQ(compared.mesh.quads, serial.mesh.quads);
  return taken;
}

TEST(Pipeline, RefusedPatternKeptWhereTheUnstructuredMeshIsNoBetter) {
  const Comm comm = Comm::world();
  // The box's planar sides and fillets get their grids back.
  const int box = check_refused_patterns_compared(comm, shared_model(comm, "pipe_compare"));
  if (comm.rank() == 0) {
    EXPECT_GT(box, 0);
  }
  // A right triangle with a 26.6 degree corner: the triangle pattern (SICN avg 0.74) loses to the
  // unstructured mesh (about 0.9 with four irregular vertices), and the comparison says so.
  const std::string path = tmp("pipe_compare_triangle_np" + std::to_string(comm.size()) + ".brep");
  if (comm.rank() == 0) test::write_polygon_face({{0, 0}, {10, 0}, {2, 4}}, path);
  comm.barrier();
  EXPECT_EQ(check_refused_patterns_compared(comm, cad::load_cad(path)), 0);
}

// PipelineOptions::pattern_min_quad_bound: the size map's bound on a fill's quads never goes below
// it. With a ratio so small that every bound is the floor, a floor of 1 refuses every fill on its
// count and a floor above any fill lets the pattern path mesh what it meshes without a bound.
TEST(Pipeline, PatternQuadBoundHasAFloor) {
  const Comm comm = Comm::world();
  const cad::CadModel model = shared_model(comm, "pipe_floor");
  PipelineOptions options;
  options.background.sizes.size = 0.7;
  options.sizemap.size_max = 0.7;
  options.until = Stage::QuasiStructured;
  options.pattern_compare_tolerance = -1;  // the bound alone decides (no fill taken afterwards)
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const auto by_pattern = [&](const PipelineResult& r, const char* refusal) {
    int n = 0, refused = 0;
    for (const QuasiReport& q : r.quasi_reports) {
      n += q.by_pattern ? 1 : 0;
      refused += q.refusal == refusal ? 1 : 0;
    }
    return std::make_pair(n, refused);
  };
  options.pattern_max_quad_ratio = 0;
  const PipelineResult unbounded = run_pipeline(comm, model, options, TaskArena(2), log);
  options.pattern_max_quad_ratio = 1e-9;
  options.pattern_min_quad_bound = 1;
  const PipelineResult tight = run_pipeline(comm, model, options, TaskArena(2), log);
  options.pattern_min_quad_bound = 1000000;
  const PipelineResult floor = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  const auto [all, none] = by_pattern(unbounded, "too_many_quads");
  EXPECT_GT(all, 0);
  EXPECT_EQ(none, 0);
  const auto [tight_n, tight_refused] = by_pattern(tight, "too_many_quads");
  EXPECT_EQ(tight_n, 0);
  EXPECT_GE(tight_refused, all);  // and the faces refused on quality without a bound
  EXPECT_EQ(by_pattern(floor, "too_many_quads"), std::make_pair(all, 0));
  EXPECT_EQ(floor.mesh.quads, unbounded.mesh.quads);
}

// A fill refused on the size map's quad bound gets a second look when the unstructured path had
// to make at least as many quads of the face: a strip two edges wide (its short curves cannot get
// fewer) sized for a few quads. Bound 1 refuses every fill on its count; the grid, no larger
// than the unstructured mesh and no worse, is kept after the comparison, the same on every rank.
TEST(Pipeline, FillRefusedOnCountIsComparedWhenTheUnstructuredMeshIsAsLarge) {
  const Comm comm = Comm::world();
  const std::string path = tmp("pipe_strip_np" + std::to_string(comm.size()) + ".brep");
  if (comm.rank() == 0) test::write_polygon_face({{0, 0}, {30, 0}, {30, 0.6}, {0, 0.6}}, path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  PipelineOptions options;
  options.background.sizes.size = 3;
  options.sizemap.size_max = 3;
  options.until = Stage::QuasiStructured;
  options.pattern_max_quad_ratio = 1e-9;
  options.pattern_min_quad_bound = 1;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult compared = run_pipeline(comm, model, options, TaskArena(2), log);
  options.pattern_compare_tolerance = -1;
  const PipelineResult never = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  options.pattern_compare_tolerance = 0.01;
  const PipelineResult serial = run_pipeline(Comm::self(), model, options, TaskArena(1), log);
  ASSERT_EQ(compared.quasi_reports.size(), 1U);
  ASSERT_EQ(never.quasi_reports.size(), 1U);
  EXPECT_EQ(never.quasi_reports[0].refusal, "too_many_quads");
  EXPECT_FALSE(never.quasi_reports[0].by_pattern);
  const QuasiReport& q = compared.quasi_reports[0];
  EXPECT_EQ(q.refusal, "too_many_quads");
  EXPECT_TRUE(q.by_pattern);
  EXPECT_TRUE(q.by_comparison);
  EXPECT_EQ(q.pattern, "grid");
  const mesh::FaceQuadStats& mine = compared.face_stats[0];
  const mesh::FaceQuadStats& other = never.face_stats[0];
  EXPECT_EQ(mine.irregular_interior, 0);
  EXPECT_LE(mine.quads, other.quads);
  EXPECT_GE(mine.sicn_min, other.sicn_min - 0.01);
  EXPECT_GE(mine.sicn_avg, other.sicn_avg - 0.01);
  EXPECT_EQ(compared.mesh.quads, serial.mesh.quads);
  const auto conformity = mesh::check_conformity(compared.mesh, model);
  EXPECT_TRUE(conformity.ok()) << conformity.summary();
}

// By default a fill is kept on its quality alone, whatever its quad count (paper 000 Sec. 6.1.2):
// a square sized for about 100 quads whose four sides are prescribed 40 edges is a 40 x 40 grid,
// 16 times what the size map asks for, kept directly; with a bound of 3 it is refused on its count.
TEST(Pipeline, PatternFillsAreNotBoundedByTheSizeMapByDefault) {
  const Comm comm = Comm::world();
  const std::string path = tmp("pipe_fine_square_np" + std::to_string(comm.size()) + ".brep");
  if (comm.rank() == 0) test::write_polygon_face({{0, 0}, {10, 0}, {10, 10}, {0, 10}}, path);
  comm.barrier();
  const cad::CadModel model = cad::load_cad(path);
  ASSERT_EQ(model.num_curves(), 4);
  PipelineOptions options;
  options.background.sizes.size = 1;
  options.sizemap.size_max = 1;
  options.until = Stage::QuasiStructured;
  for (LO c = 0; c < 4; ++c) options.quantize.prescribed.emplace_back(c, 40);
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult plain = run_pipeline(comm, model, options, TaskArena(2), log);
  options.pattern_max_quad_ratio = 3;
  options.pattern_compare_tolerance = -1;
  const PipelineResult bounded = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  ASSERT_EQ(plain.quasi_reports.size(), 1U);
  const QuasiReport& q = plain.quasi_reports[0];
  EXPECT_TRUE(q.by_pattern);
  EXPECT_FALSE(q.by_comparison);
  EXPECT_EQ(q.refusal, "");
  EXPECT_EQ(q.pattern, "grid");
  EXPECT_EQ(plain.face_stats[0].quads, 1600);
  EXPECT_EQ(plain.face_stats[0].irregular_interior, 0);
  EXPECT_EQ(bounded.quasi_reports[0].refusal, "too_many_quads");
  EXPECT_FALSE(bounded.quasi_reports[0].by_pattern);
}

TEST(Pipeline, SizeMapAndCurveMeshesDoNotDependOnRanks) {
  const Comm comm = Comm::world();
  check_size_map(comm, shared_model(comm, "pipe_sm"), 0.6);
}

// The CLI's default sizing (--sizing clamped, drivers' kClampedSizeMinRatio) floors the sizes at
// 0.17 x the size cap; --sizing paper (SizeMapOptions' defaults) lets a curve size the mesh by its
// length below every floor.
constexpr double kClampedRatio = 0.17;

TEST(Pipeline, SizeMapOnSharedModels) {
  const std::string dir = QSMESH_SHARED_CAD_DIR;
  if (!std::filesystem::exists(dir + "/A319.brep")) GTEST_SKIP() << "no " << dir;
  const Comm comm = Comm::world();
  int clamped_curves = 0;  // curves shorter than the clamped floor, over the models
  // Block.stp with the default rules only (it is the slower model); A319.brep both ways.
  for (const auto& [name, ratio] : std::vector<std::pair<const char*, double>>{
           {"A319.brep", kClampedRatio}, {"Block.stp", kClampedRatio}, {"A319.brep", 0.0}}) {
    const cad::CadModel model = cad::load_cad(dir + "/" + name);
    const double size = 0.02 * model.diagonal();
    const double floor = ratio * size;
    // The checks on the real size map: opposite sides of the four-sided faces of conformal
    // chains have equal counts, and (rule (i) of Sec. 4.1) the size never exceeds the length of its
    // curve where that length is above the floor (degenerate curves, poles, have no length: their
    // vertices carry the pole corner's size); with the clamp no size is below the floor, so a
    // curve shorter than it keeps the floor, except that its corners are at 5 x its length and
    // the sizes grow from them at the gradation (rule (i'), sizemap's kSliverCornerRatio): no
    // size below min(floor, 5 L + g d) for the distance d to such a corner. Every rank holds the
    // same curve data, so every rank checks.
    PipelineResult r;
    check_size_map(comm, model, size, &r, ratio);
    background::SizeOptions sizes;
    sizes.size = size;
    const auto curves = background::mesh_curves(model, sizes, TaskArena(1));
    std::vector<std::pair<Vec3, double>> sliver_corners;  // (point, 5 x the curve's length)
    for (const cad::Curve& curve : model.curves())
      if (!curve.degenerate && curve.length < floor)
        for (const LO k : curve.corners)
          if (k >= 0) sliver_corners.emplace_back(model.corners()[k].point, 5 * curve.length);
    const double gradation = sizemap::SizeMapOptions{}.gradation;
    auto lowest = [&](const Vec3& p) {
      double s = floor;
      for (const auto& [corner, cap] : sliver_corners)
        s = std::min(s, cap + gradation * distance(p, corner));
      return s;
    };
    int graded = 0;  // vertices below the floor, graded toward a sliver's corner
    const auto& q = r.quantization;
    int pairs = 0, unequal = 0, too_large = 0, below_floor = 0;
    for (const auto& face : model.faces()) {
      if (face.loops.size() != 1 || face.loops[0].uses.size() != 4 || !face.loops_closed) continue;
      const auto& uses = face.loops[0].uses;
      for (int k = 0; k < 2; ++k) {
        const LO a = uses[k].curve, b = uses[k + 2].curve;
        if (q.curve2chord[a] == kNoIndex || q.curve2chord[a] != q.curve2chord[b]) continue;
        ++pairs;
        unequal += q.edges[a] != q.edges[b] ? 1 : 0;
      }
    }
    for (LO c = 0; c < model.num_curves(); ++c) {
      const cad::Curve& curve = model.curves()[c];
      if (!curve.degenerate && curve.length < floor) ++clamped_curves;
      for (std::size_t i = 0; i < r.curve_sizes.at[c].size(); ++i) {
        const double s = r.curve_sizes.at[c][i];
        if (!curve.degenerate && curve.length >= floor && s > curve.length * (1 + 1e-12)) {
          ++too_large;
          ADD_FAILURE() << name << ": curve " << c << " of length " << curve.length << " has size "
                        << s;
        }
        if (s < floor * (1 - 1e-12)) ++graded;
        if (s < lowest(curves[c].points[i]) * (1 - 1e-12)) {
          ++below_floor;
          ADD_FAILURE() << name << ": curve " << c << " has size " << s << " below the floor "
                        << floor << " and below the growth from the slivers' corners";
        }
      }
    }
    EXPECT_GT(pairs, 0) << name;
    EXPECT_EQ(unequal, 0) << name;
    EXPECT_EQ(too_large, 0) << name;
    EXPECT_EQ(below_floor, 0) << name;
    if (comm.rank() == 0)
      std::cout << name << " (floor " << floor << "): " << q.num_chords << " chords, " << pairs
                << " opposite pairs in chords, " << graded
                << " curve-mesh vertices graded below the floor toward sliver corners\n";
  }
  EXPECT_GT(clamped_curves, 0);  // the clamp was put to the test
}

}  // namespace
}  // namespace qsmesh::parallel

namespace qsmesh::parallel {
namespace {

// Paper 003 (--method separatrix): the faces meshed from the mesher's own cross field do not
// depend on the ranks either, and some faces of the filleted box take that path.
TEST(Pipeline, SeparatrixMethodDoesNotDependOnRanks) {
  const Comm comm = Comm::world();
  const cad::CadModel model = shared_model(comm, "pipe_sep");
  PipelineOptions options;
  options.background.sizes.size = 0.7;
  options.sizemap.size_max = 0.7;
  options.until = Stage::QuasiStructured;
  options.separatrix_method = true;
  std::ostringstream sink;
  Logger log(sink, LogLevel::Quiet);
  const PipelineResult dist = run_pipeline(comm, model, options, TaskArena(2), log);
  if (comm.rank() != 0) return;
  const PipelineResult serial = expect_quads_as_on_one_rank(dist, model, options, log, 500, 0.0);
  int by_field = 0;
  for (std::size_t f = 0; f < dist.quasi_reports.size(); ++f) {
    EXPECT_EQ(dist.quasi_reports[f].by_field, serial.quasi_reports[f].by_field);
    EXPECT_EQ(dist.quasi_reports[f].field_refusal, serial.quasi_reports[f].field_refusal);
    by_field += dist.quasi_reports[f].by_field ? 1 : 0;
    // The partition's regions reach rank 0 in the assembled numbering, as on one rank: one grid
    // per region, the face's quads once.
    const auto& grids = dist.field_grids[f];
    const auto& one = serial.field_grids[f];
    ASSERT_EQ(grids.size(), one.size()) << "face " << f;
    EXPECT_EQ(static_cast<std::int64_t>(grids.size()),
              dist.quasi_reports[f].by_field ? dist.quasi_reports[f].field_regions : 0);
    std::int64_t cells = 0;
    for (std::size_t k = 0; k < grids.size(); ++k) {
      EXPECT_EQ(grids[k].ni, one[k].ni);
      EXPECT_EQ(grids[k].nj, one[k].nj);
      EXPECT_EQ(grids[k].vertices, one[k].vertices);
      cells += static_cast<std::int64_t>(grids[k].ni) * grids[k].nj;
    }
    if (dist.quasi_reports[f].by_field) {
      EXPECT_EQ(cells, dist.face_stats[f].quads) << "face " << f;
    }
  }
  EXPECT_GT(by_field, 0);
}

}  // namespace
}  // namespace qsmesh::parallel
