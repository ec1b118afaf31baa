#include "qsmesh/parallel/pipeline.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>

#include "improve.hpp"
#include "qsmesh/background/curve_mesh.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/mesh/assemble.hpp"
#include "qsmesh/parallel/partition.hpp"
#include "serialize.hpp"

namespace qsmesh::parallel {

const char* to_string(Stage s) {
  switch (s) {
    case Stage::Background:
      return "background";
    case Stage::Unstructured:
      return "unstructured";
    case Stage::QuasiStructured:
      return "quasi-structured";
  }
  return "?";
}

Stage parse_stage(const std::string& name) {
  if (name == "background") return Stage::Background;
  if (name == "unstructured") return Stage::Unstructured;
  if (name == "quasi-structured") return Stage::QuasiStructured;
  throw InputError("--until: unknown stage '" + name +
                   "' (valid: background, unstructured, quasi-structured)");
}

std::vector<double> estimate_face_costs(const cad::CadModel& model, double size) {
  std::vector<double> cost;
  cost.reserve(static_cast<std::size_t>(model.num_faces()));
  for (const cad::Face& f : model.faces()) cost.push_back(std::max(1.0, f.area / (size * size)));
  return cost;
}

void pack(const mesh::FaceMesh& m, const background::FaceReport& r, std::vector<char>& out) {
  pack_mesh(m, out);
  put<LO>(out, r.face);
  put<std::uint8_t>(out, r.ok ? 1 : 0);
  put<std::uint8_t>(out, r.fell_back ? 1 : 0);
  put<double>(out, r.seconds);
  put_string(out, r.error);
}

void unpack(const std::vector<char>& in, std::size_t& pos, mesh::FaceMesh& m,
            background::FaceReport& r) {
  unpack_mesh(in, pos, m);
  r.face = get<LO>(in, pos);
  r.ok = get<std::uint8_t>(in, pos) != 0;
  r.fell_back = get<std::uint8_t>(in, pos) != 0;
  r.seconds = get<double>(in, pos);
  r.error = get_string(in, pos);
}

CrossFieldOutput summarize(const crossfield::FaceCrossField& cf) {
  CrossFieldOutput out;
  out.ok = true;
  const std::size_t nt = cf.triangles.size();
  out.directions = cf.directions;
  out.u_norm.resize(nt);
  out.H.resize(nt);
  for (std::size_t t = 0; t < nt; ++t) {
    double un = 0, h = 0;
    for (int k = 0; k < 3; ++k) {
      un += cf.u_norm[cf.tri2edges[t][k]];
      h += cf.H[cf.triangles[t][k]];
    }
    out.u_norm[t] = un / 3;
    out.H[t] = h / 3;
  }
  out.singularities = cf.singularities;
  out.euler = cf.euler;
  out.levels = cf.stats.levels;
  out.factorizations = cf.stats.factorizations;
  out.solves = cf.stats.solves;
  out.seconds = cf.stats.seconds;
  return out;
}

void pack(const CrossFieldOutput& c, std::vector<char>& out) {
  put<std::uint8_t>(out, c.ok ? 1 : 0);
  put_string(out, c.error);
  put_vec(out, c.directions);
  put_vec(out, c.u_norm);
  put_vec(out, c.H);
  put_vec(out, c.singularities);
  put(out, c.euler);
  put<int>(out, c.levels);
  put<int>(out, c.factorizations);
  put<int>(out, c.solves);
  put<double>(out, c.seconds);
}

void unpack(const std::vector<char>& in, std::size_t& pos, CrossFieldOutput& c) {
  c.ok = get<std::uint8_t>(in, pos) != 0;
  c.error = get_string(in, pos);
  get_vec(in, pos, c.directions);
  get_vec(in, pos, c.u_norm);
  get_vec(in, pos, c.H);
  get_vec(in, pos, c.singularities);
  c.euler = get<crossfield::EulerCheck>(in, pos);
  c.levels = get<int>(in, pos);
  c.factorizations = get<int>(in, pos);
  c.solves = get<int>(in, pos);
  c.seconds = get<double>(in, pos);
}

void pack(const sizemap::FaceSizes& s, std::vector<char>& out) {
  put_vec(out, s.s);
  put_vec(out, s.s_min);
  put_vec(out, s.s_cf);
}

void unpack(const std::vector<char>& in, std::size_t& pos, sizemap::FaceSizes& s) {
  get_vec(in, pos, s.s);
  get_vec(in, pos, s.s_min);
  get_vec(in, pos, s.s_cf);
}

void pack(const quad::UnstructuredReport& r, std::vector<char>& out) {
  put<std::uint8_t>(out, r.ok ? 1 : 0);
  put<std::uint8_t>(out, r.fell_back ? 1 : 0);
  put<std::uint8_t>(out, r.frontal ? 1 : 0);
  put<std::int64_t>(out, r.frontal_points);
  put_string(out, r.error);
  put<double>(out, r.sicn_min);
  put<std::int64_t>(out, r.quads);
}

void unpack(const std::vector<char>& in, std::size_t& pos, quad::UnstructuredReport& r) {
  r.ok = get<std::uint8_t>(in, pos) != 0;
  r.fell_back = get<std::uint8_t>(in, pos) != 0;
  r.frontal = get<std::uint8_t>(in, pos) != 0;
  r.frontal_points = get<std::int64_t>(in, pos);
  r.error = get_string(in, pos);
  r.sicn_min = get<double>(in, pos);
  r.quads = get<std::int64_t>(in, pos);
}

void pack(const QuasiReport& r, std::vector<char>& out) {
  put<std::uint8_t>(out, r.by_pattern ? 1 : 0);
  put<std::uint8_t>(out, r.by_comparison ? 1 : 0);
  put_string(out, r.pattern);
  put_string(out, r.refusal);
  put<std::int64_t>(out, r.irregular_before);
  put<std::int64_t>(out, r.irregular_after);
  for (auto c : r.cavities) put<std::int64_t>(out, c);
  put<std::int64_t>(out, r.defects_before);
  put<std::int64_t>(out, r.defects_after);
  put<std::int64_t>(out, r.disk_replaced);
  put<std::uint8_t>(out, r.time_budget_hit ? 1 : 0);
}

void unpack(const std::vector<char>& in, std::size_t& pos, QuasiReport& r) {
  r.by_pattern = get<std::uint8_t>(in, pos) != 0;
  r.by_comparison = get<std::uint8_t>(in, pos) != 0;
  r.pattern = get_string(in, pos);
  r.refusal = get_string(in, pos);
  r.irregular_before = get<std::int64_t>(in, pos);
  r.irregular_after = get<std::int64_t>(in, pos);
  for (auto& c : r.cavities) c = get<std::int64_t>(in, pos);
  r.defects_before = get<std::int64_t>(in, pos);
  r.defects_after = get<std::int64_t>(in, pos);
  r.disk_replaced = get<std::int64_t>(in, pos);
  r.time_budget_hit = get<std::uint8_t>(in, pos) != 0;
}

PipelineResult run_pipeline(const Comm& comm, const cad::CadModel& model,
                            const PipelineOptions& options, const TaskArena& tasks, Logger& log,
                            linalg::PetscLane* lane) {
  PipelineResult result;
  const int rank = comm.rank();
  const int nranks = comm.size();
  const LO nfaces = model.num_faces();

  // Curves: every rank computes the same meshes (cheap next to the faces, and no communication).
  Stopwatch clock;
  // Each stage ends with the slowest rank's time; the stages split by faces also add this rank's
  // own time to `busy` (PipelineResult::rank_busy_seconds). The clock is read before the
  // reduction, so a rank's time is its work, not its wait for the others.
  double busy = 0;
  const auto end_stage = [&](const char* stage, bool by_faces) {
    const double seconds = clock.seconds();
    if (by_faces) busy += seconds;
    result.times.add(stage, comm.allreduce_max(seconds));
  };
  const std::vector<mesh::CurveMesh> curves =
      background::mesh_curves(model, options.background.sizes, tasks);
  std::int64_t curve_edges = 0;
  for (const auto& c : curves) curve_edges += c.num_edges();
  end_stage("curves", false);
  log.info(cat("curves: ", model.num_curves(), " curves meshed, ", curve_edges, " edges (",
               result.times.get("curves"), " s)"));

  // Faces: METIS partition weighted by the estimated cost.
  clock.reset();
  result.face_rank = partition_faces(
      model.face2faces(), estimate_face_costs(model, options.background.sizes.size), nranks);
  std::vector<LO> mine;
  for (LO f = 0; f < nfaces; ++f)
    if (result.face_rank[f] == rank) mine.push_back(f);
  end_stage("partition", false);
  if (nranks > 1) {
    std::vector<std::int64_t> per_rank(static_cast<std::size_t>(nranks), 0);
    per_rank[rank] = static_cast<std::int64_t>(mine.size());
    comm.allreduce_sum(per_rank);
    std::string line = "partition: faces per rank";
    for (auto n : per_rank) line += cat(" ", n);
    log.info(line);
  }

  // Background triangulation of this rank's faces, one task per face. Progress is counted on this
  // rank; rank 0's logger prints it (the other ranks' loggers are quiet by default).
  clock.reset();
  std::vector<mesh::FaceMesh> meshes(mine.size());
  std::vector<background::FaceReport> reports(mine.size());
  std::atomic<std::int64_t> done{0};
  const auto total = static_cast<std::int64_t>(mine.size());
  tasks.parallel_for(static_cast<std::int64_t>(mine.size()), [&](std::int64_t i) {
    meshes[i] =
        background::mesh_face_background(model, mine[i], curves, options.background, &reports[i]);
    const std::int64_t n = ++done;
    if (n * 10 / total != (n - 1) * 10 / total)  // every tenth of the faces
      log.info(cat("background: ", n, "/", mine.size(), " faces on rank ", rank));
  });
  end_stage("background", true);

  // Cross fields (paper 000 Sec. 3) on the same faces, one task per face. The size map (it needs H
  // at every vertex) and the frontal insertion (the crosses) keep the whole fields; the drivers
  // that asked for them (options.cross_fields) get summaries.
  const bool quads = options.until >= Stage::Unstructured;
  const bool size_map = options.size_map || quads;
  const bool cf_sizes = size_map && options.sizemap.method == sizemap::Method::CrossField;
  const bool keep_fields = cf_sizes || quads;
  const bool want_fields = options.cross_fields || keep_fields;
  std::vector<CrossFieldOutput> fields;
  std::vector<std::unique_ptr<crossfield::FaceCrossField>> full(mine.size());
  if (want_fields) {
    clock.reset();
    fields.resize(mine.size());
    std::atomic<std::int64_t> cf_done{0};
    tasks.parallel_for(total, [&](std::int64_t i) {
      try {
        auto cf = std::make_unique<crossfield::FaceCrossField>(
            crossfield::compute_face_cross_field(meshes[i], options.crossfield, lane));
        if (options.cross_fields)
          fields[i] = summarize(*cf);
        else
          crossfield::shrink_cross_field(*cf, crossfield::CrossFieldUse::SizeMapAndGuide);
        if (keep_fields) full[i] = std::move(cf);
      } catch (const std::exception& e) {
        // A face without a cross field keeps its background mesh; later stages fall back to
        // methods that need no field.
        fields[i] = CrossFieldOutput{};
        fields[i].error = Error(e.what(), ErrorContext{"crossfield", 2, mine[i]}).what();
      }
      const std::int64_t n = ++cf_done;
      if (n * 10 / total != (n - 1) * 10 / total)
        log.info(cat("crossfield: ", n, "/", mine.size(), " faces on rank ", rank));
    });
    end_stage("crossfield", true);
  }

  // Size map (paper 000 Sec. 4.1-4.2): curve sizes known to every rank, face fields on the faces'
  // ranks, their union on shared curves by an MPI min-reduction, then quantization (Sec. 4.3)
  // computed identically on every rank.
  std::vector<sizemap::FaceSizes> sizes(size_map ? mine.size() : 0);
  if (size_map) {
    clock.reset();
    const sizemap::SizeMapOptions& so = options.sizemap;
    const sizemap::CurveSizes initial = sizemap::initial_curve_sizes(model, curves, so, tasks);
    const std::vector<double> targets = sizemap::face_quad_targets(model, so);
    auto face_pass = [&](const sizemap::CurveSizes& on_curves) {
      tasks.parallel_for(total, [&](std::int64_t i) {
        sizes[i] = sizemap::face_sizes(meshes[i], cf_sizes ? full[i].get() : nullptr, curves,
                                       on_curves, targets[mine[i]], so);
      });
    };
    face_pass(initial);
    // The union on shared curves and corners starts from the initial sizes on every rank (the
    // minimum is idempotent), so curves that no face of this rank touches keep their values.
    sizemap::CurveSizes united = initial;
    for (std::size_t i = 0; i < mine.size(); ++i)
      sizemap::fold_boundary_min(meshes[i], sizes[i].s, united);
    std::vector<double> flat = united.pack();
    comm.allreduce_min(flat);
    united.unpack(flat);
    sizemap::grade_curves(model, curves, so.gradation, united);
    face_pass(united);  // faces now agree on their shared curves
    // The frontal insertion reads only the crosses of each field; the rest was for the size map.
    if (!options.cross_fields)
      tasks.parallel_for(total, [&](std::int64_t i) {
        if (full[i] != nullptr)
          crossfield::shrink_cross_field(*full[i], crossfield::CrossFieldUse::Guide);
      });
    result.curve_sizes = std::move(united);
    end_stage("sizemap", true);

    clock.reset();
    const std::vector<double> ideal = quantize::ideal_edge_counts(curves, result.curve_sizes.at);
    result.quantization = quantize::quantize_curves(model, ideal, options.quantize);
    if (options.balance_counts) {
      // Every rank balances the whole model the same way (deterministic, model-wide data only).
      std::vector<LO> fixed;
      for (const auto& [c, n] : options.quantize.prescribed) fixed.push_back(c);
      const auto patterns = qstruct::builtin_patterns();
      std::vector<int> edges = qstruct::balance_curve_counts(
          model, curves, result.quantization, patterns, fixed, options.balance, &result.balance);
      result.quantization.total_edges = 0;
      for (const int e : edges) result.quantization.total_edges += e;
      result.quantization.edges = std::move(edges);
      log.info(cat("quantize: faces fitting a pattern ", result.balance.fitting_before, " -> ",
                   result.balance.fitting_after, " of ", result.balance.faces_considered,
                   ", grids ", result.balance.grids_before, " -> ", result.balance.grids_after,
                   " (", result.balance.curves_changed, " curves changed)"));
    }
    // Boundary repair: a face whose boundary crosses itself in its parameter plane cannot be
    // triangulated. Each rank checks its own faces; the flags are summed, so every rank refines
    // the same curves and keeps the same quantization.
    std::vector<LO> fixed;
    for (const auto& [c, n] : options.quantize.prescribed) fixed.push_back(c);
    bool placed_final = false;  // result.quantized_curves holds the final quantization's meshes
    for (int round = 0; round < options.boundary_repair_rounds; ++round) {
      std::vector<std::int64_t> flags(static_cast<std::size_t>(model.num_curves()), 0);
      std::vector<std::vector<LO>> found(mine.size());
      // The final curve meshes, and the halved boundaries made from them (paper 000 Sec. 5.2).
      result.quantized_curves =
          quantize::place_vertices(model, curves, result.curve_sizes.at, result.quantization,
                                   /*halved=*/false, tasks, options.place);
      for (const bool halved : {true, false}) {
        tasks.parallel_for(static_cast<std::int64_t>(mine.size()), [&](std::int64_t i) {
          try {
            const auto c =
                halved ? quantize::crossing_curves_halved(model, mine[i], result.quantized_curves)
                       : quantize::crossing_curves(model, mine[i], result.quantized_curves);
            found[i].insert(found[i].end(), c.begin(), c.end());
          } catch (const std::exception& e) {
            // The face's own stages report its geometry errors; this check only looks for
            // crossings.
            log.debug(Error(e.what(), ErrorContext{"quantize", 2, mine[i]}).what());
          }
        });
      }
      placed_final = true;
      for (const auto& list : found)
        for (const LO c : list) flags[c] = 1;
      comm.allreduce_sum(flags);
      std::vector<LO> flagged;
      for (LO c = 0; c < model.num_curves(); ++c)
        if (flags[c] > 0) flagged.push_back(c);
      if (flagged.empty()) break;
      const std::int64_t before = result.quantization.total_edges;
      quantize::refine_curves(result.quantization, flagged, fixed);
      if (result.quantization.total_edges == before) break;  // only fixed curves are involved
      placed_final = false;
      result.curves_refined_for_crossings.push_back(static_cast<LO>(flagged.size()));
      log.info(
          cat("quantize: ", flagged.size(),
              " curves refined where face boundaries crossed themselves in the parameter plane"));
    }
    if (!placed_final)
      result.quantized_curves =
          quantize::place_vertices(model, curves, result.curve_sizes.at, result.quantization,
                                   /*halved=*/false, tasks, options.place);
    end_stage("quantize", false);
    log.info(cat("quantize: ", model.num_curves(), " curves, ", result.quantization.num_chords,
                 " chords, ", result.quantization.total_edges, " edges"));
  }

  // Unstructured all-quad meshes (paper 000 Sec. 5) on the quantized curve meshes: frontal points
  // guided by the face's cross field and size map (read on its background mesh) on the halved
  // curves, recombined, subdivided onto the full ones, smoothed. The background meshes stay
  // until every face of the rank is done; the quad meshes replace them afterwards.
  std::vector<quad::UnstructuredReport> quad_reports(quads ? mine.size() : 0);
  const bool quasi = options.until >= Stage::QuasiStructured;
  std::vector<QuasiReport> quasi_reports(quasi ? mine.size() : 0);
  // The coarse patterns serve both whole faces (Sec. 6.1.2) and cavities (Sec. 6.2).
  const std::vector<qstruct::Pattern> patterns =
      quasi ? qstruct::builtin_patterns() : std::vector<qstruct::Pattern>{};
  std::vector<mesh::FaceMesh> quad_meshes(quads ? mine.size() : 0);
  // Valid pattern meshes refused on quality, for the comparison with the unstructured path's
  // result (PipelineOptions::pattern_compare_tolerance).
  struct RefusedFill {
    mesh::FaceMesh mesh;
    std::string pattern;
    // A kept fill with a poor mean (qstruct::fill_to_compare), held back until the face's
    // unstructured mesh is known (qstruct::unstructured_clearly_better decides between them).
    bool kept = false;
  };
  std::vector<RefusedFill> refused(quasi ? mine.size() : 0);
  // The quad bound of each face's fills (0: none), by face id: computed by the face's owner,
  // known to every rank (the fills are dealt out), read again by the second look below.
  std::vector<std::int64_t> fill_bound(quasi ? static_cast<std::size_t>(nfaces) : 0, 0);
  std::vector<double> face_seconds(quads ? mine.size() : 0, 0.0);
  if (quasi) {
    // Simple CAD faces meshed directly by a pattern (paper 000 Sec. 6.1.2, pipeline step 4); the
    // others go through the unstructured path below. A fill needs only the model, the curve meshes
    // (every rank has them) and the face's quad bound (if any), which its owner computes from its
    // size map and shares with the quads the size map asks for; the faces are then dealt out over
    // all ranks (deal_out), those asking for the most quads first: a few faces whose fills are
    // refused and searched take most of the stage.
    clock.reset();
    std::vector<double> expected(static_cast<std::size_t>(nfaces), 0.0);
    if (!sizes.empty())
      tasks.parallel_for(total, [&](std::int64_t i) {
        expected[static_cast<std::size_t>(mine[i])] =
            sizemap::expected_quads(meshes[i], sizes[i].s);
      });
    comm.allreduce_sum(expected);  // each face's entry is set by its owner alone
    if (options.pattern_max_quad_ratio > 0)
      for (LO f = 0; f < nfaces; ++f)
        fill_bound[f] = std::max<std::int64_t>(
            options.pattern_min_quad_bound,
            static_cast<std::int64_t>(std::ceil(options.pattern_max_quad_ratio * expected[f])));
    std::vector<LO> order(static_cast<std::size_t>(nfaces));
    std::iota(order.begin(), order.end(), LO{0});
    std::sort(order.begin(), order.end(), [&](LO a, LO b) {
      return expected[a] != expected[b] ? expected[a] > expected[b] : a < b;
    });
    struct Fill {
      bool done = false;
      qstruct::PatternFaceReport report;  // refused_mesh kept only for the comparison
      mesh::FaceMesh mesh;
      double seconds = 0;
    };
    std::vector<Fill> fills(static_cast<std::size_t>(nfaces));
    DealProgress progress("patterns", nfaces, comm, log);
    deal_out(comm, nfaces, tasks, [&](std::int64_t k) {
      const LO f = order[static_cast<std::size_t>(k)];
      const Stopwatch face_clock;
      Fill& fill = fills[static_cast<std::size_t>(f)];
      qstruct::PatternFaceOptions po = options.patterns;
      po.max_quads = fill_bound[static_cast<std::size_t>(f)];
      fill.mesh =
          qstruct::mesh_face_pattern(model, f, result.quantized_curves, patterns, po, &fill.report);
      if (fill.report.ok || options.pattern_compare_tolerance < 0)
        fill.report.refused_mesh = mesh::FaceMesh{};
      fill.seconds = face_clock.seconds();
      fill.done = true;
      progress.done();
    });
    // Fills to their owners.
    const auto take = [&](std::int64_t i, Fill&& fill) {
      const qstruct::PatternFaceReport& pr = fill.report;
      if (pr.ok && qstruct::fill_to_compare(pr.sicn_avg, pr.quads, options.patterns)) {
        refused[i] = {std::move(fill.mesh), pr.pattern_name, true};
      } else if (pr.ok) {
        quasi_reports[i].by_pattern = true;
        quasi_reports[i].pattern = pr.pattern_name;
        quad_reports[i].ok = true;
        quad_reports[i].sicn_min = pr.sicn_min;
        quad_reports[i].quads = pr.quads;
        quad_meshes[i] = std::move(fill.mesh);
      } else {
        quasi_reports[i].refusal = qstruct::to_string(pr.refusal);
        if (!fill.report.refused_mesh.quads.empty())
          refused[i] = {std::move(fill.report.refused_mesh), pr.pattern_name};
      }
      face_seconds[i] += fill.seconds;
    };
    std::vector<std::int64_t> local_of(static_cast<std::size_t>(nfaces), -1);
    for (std::int64_t i = 0; i < total; ++i) local_of[static_cast<std::size_t>(mine[i])] = i;
    std::vector<std::vector<char>> to_owner(static_cast<std::size_t>(nranks));
    for (LO f = 0; f < nfaces; ++f) {
      Fill& fill = fills[static_cast<std::size_t>(f)];
      if (!fill.done) continue;
      if (local_of[static_cast<std::size_t>(f)] >= 0) {
        take(local_of[static_cast<std::size_t>(f)], std::move(fill));
      } else {
        const qstruct::PatternFaceReport& pr = fill.report;
        std::vector<char>& outgoing = to_owner[static_cast<std::size_t>(result.face_rank[f])];
        put<LO>(outgoing, f);
        put<std::uint8_t>(outgoing, pr.ok ? 1 : 0);
        put<qstruct::Refusal>(outgoing, pr.refusal);
        put_string(outgoing, pr.pattern_name);
        put<double>(outgoing, pr.sicn_min);
        put<double>(outgoing, pr.sicn_avg);
        put<std::int64_t>(outgoing, pr.quads);
        pack_mesh(fill.mesh, outgoing);
        pack_mesh(pr.refused_mesh, outgoing);
        put<double>(outgoing, fill.seconds);
      }
      fill = Fill{};
    }
    if (nranks > 1)
      for (const auto& bytes : comm.alltoall_bytes(to_owner)) {
        std::size_t pos = 0;
        while (pos < bytes.size()) {
          const auto f = get<LO>(bytes, pos);
          Fill fill;
          qstruct::PatternFaceReport& pr = fill.report;
          pr.ok = get<std::uint8_t>(bytes, pos) != 0;
          pr.refusal = get<qstruct::Refusal>(bytes, pos);
          pr.pattern_name = get_string(bytes, pos);
          pr.sicn_min = get<double>(bytes, pos);
          pr.sicn_avg = get<double>(bytes, pos);
          pr.quads = get<std::int64_t>(bytes, pos);
          unpack_mesh(bytes, pos, fill.mesh);
          unpack_mesh(bytes, pos, pr.refused_mesh);
          fill.seconds = get<double>(bytes, pos);
          QSMESH_CHECK(f >= 0 && f < nfaces && local_of[static_cast<std::size_t>(f)] >= 0,
                       "pattern fill of face " << f << " sent to rank " << rank
                                               << ", which does not own it");
          take(local_of[static_cast<std::size_t>(f)], std::move(fill));
        }
      }
    end_stage("patterns", true);
  }
  if (quads) {
    clock.reset();
    quad::UnstructuredOptions qo;
    qo.size = options.background.sizes.size;
    auto mesh_unstructured = [&](std::int64_t i) {
      const Stopwatch face_clock;
      quad::FaceFields face_fields;
      if (reports[i].ok && full[i] != nullptr) {
        face_fields.background = &meshes[i];
        face_fields.cross_field = full[i].get();
        face_fields.sizes = sizes[i].s;
      }
      quad_meshes[i] = quad::mesh_face_unstructured(model, mine[i], result.quantized_curves,
                                                    face_fields, qo, &quad_reports[i]);
      face_seconds[i] += face_clock.seconds();
    };
    // Of a face's cross field, the later steps need only its singularities; the field, the
    // background mesh and the size map (the largest per-face data) go as soon as the face's
    // unstructured mesh is made, so that they are not held through the improvement and the output
    // (Block.stp at its reference count, one rank: peak heap 131 -> 101 MB, and 74 MB with
    // crossfield::shrink_cross_field; docs/benchmarks.md).
    std::vector<std::vector<crossfield::Singularity>> singularities(
        quasi ? static_cast<std::size_t>(total) : 0);
    std::atomic<std::int64_t> q_done{0};
    tasks.parallel_for(total, [&](std::int64_t i) {
      if (!(quasi && quasi_reports[i].by_pattern)) mesh_unstructured(i);
      if (full[i] != nullptr && quasi) singularities[i] = std::move(full[i]->singularities);
      full[i].reset();
      meshes[i] = mesh::FaceMesh{};
      if (!options.size_map) sizes[i] = sizemap::FaceSizes{};
      const std::int64_t n = ++q_done;
      if (n * 10 / total != (n - 1) * 10 / total)
        log.info(cat("unstructured: ", n, "/", mine.size(), " faces on rank ", rank));
    });
    end_stage("unstructured", true);
    if (quasi) {
      // Topological improvement of the faces the unstructured path meshed with quads only (Sec.
      // 6.2-6.3, then the final smoothing), dealt out over ranks and threads as faces finish.
      clock.reset();
      std::vector<ImproveFace> to_improve;
      for (std::int64_t i = 0; i < total; ++i) {
        if (quasi_reports[i].by_pattern || !quad_reports[i].ok || !quad_meshes[i].triangles.empty())
          continue;
        ImproveFace f;
        f.face = mine[i];
        f.mesh = &quad_meshes[i];
        f.singularities = singularities[i];
        f.report = &quasi_reports[i];
        f.seconds = &face_seconds[i];
        to_improve.push_back(f);
      }
      const remesh::DiskQuadTable table = remesh::DiskQuadTable::builtin();
      ImproveSettings settings;
      settings.patterns = patterns;
      settings.table = &table;
      settings.cavities = options.cavities;
      settings.disk = options.disk;
      settings.final_smoothing = options.final_smoothing;
      settings.final_smooth = options.final_smooth;
      result.improvement_seconds = improve_faces(comm, model, to_improve, settings, tasks, log);
      end_stage("improvement", true);
      // Second chance for the fills that the size map's quad bound refused (other refusals would
      // give the same answer again):
      //  - a face that the unstructured path could not mesh validly (its fallback folded a quad
      //    too: t20's chamfer slivers with a 0-degree cusp at size factor 0.01) takes the fill
      //    whatever its size, if it is valid: poor quads beat folded ones;
      //  - a face whose unstructured mesh came out with more quads than the bound lays out the
      //    fills of at most that many quads. The bound keeps fills from carrying a size
      //    transition across a whole face; here the curve counts forced the unstructured mesh to
      //    the same size (wing_fuselage's blunt trailing edges at size factor 0.02: strips
      //    [2, 48, 2, 48] sized for one quad, 101 unstructured quads with 3 irregular vertices
      //    inside a strip two quads wide). The comparison below then decides.
      // The unstructured path left the face without a valid all-quad mesh.
      const auto no_valid_quads = [&](std::int64_t i) {
        return !quad_reports[i].ok || !quad_meshes[i].triangles.empty() ||
               quad_meshes[i].quads.empty();
      };
      clock.reset();
      const std::string over_bound = qstruct::to_string(qstruct::Refusal::TooManyQuads);
      if (options.pattern_compare_tolerance >= 0)
        tasks.parallel_for(total, [&](std::int64_t i) {
          if (quasi_reports[i].by_pattern || !refused[i].mesh.quads.empty() ||
              quasi_reports[i].refusal != over_bound)
            return;
          const bool failed = no_valid_quads(i);
          const auto unstructured_quads = static_cast<std::int64_t>(quad_meshes[i].quads.size());
          const std::int64_t bound = fill_bound[static_cast<std::size_t>(mine[i])];
          if (!failed && (bound <= 0 || unstructured_quads <= bound)) return;
          const Stopwatch face_clock;
          qstruct::PatternFaceOptions po = options.patterns;
          po.max_quads = failed ? 0 : unstructured_quads;
          qstruct::PatternFaceReport pr;
          mesh::FaceMesh m = qstruct::mesh_face_pattern(model, mine[i], result.quantized_curves,
                                                        patterns, po, &pr);
          if (pr.ok)
            refused[i] = {std::move(m), pr.pattern_name};
          else if (!pr.refused_mesh.quads.empty())
            refused[i] = {std::move(pr.refused_mesh), pr.pattern_name};
          face_seconds[i] += face_clock.seconds();
        });
      // Second look at the pattern meshes refused on quality: where the unstructured path did no
      // better, the pattern's fewer irregular vertices win (a small triangle face is often the
      // same three quads either way).
      const double tol = options.pattern_compare_tolerance;
      tasks.parallel_for(total, [&](std::int64_t i) {
        if (refused[i].mesh.quads.empty()) return;
        const mesh::FaceQuadStats pat = mesh::face_quad_stats(refused[i].mesh);
        const bool kept = refused[i].kept;
        bool take = no_valid_quads(i);
        if (!take) {
          const mesh::FaceQuadStats uns = mesh::face_quad_stats(quad_meshes[i]);
          take = qstruct::fill_wins(pat, uns, kept, tol, options.patterns);
          if (kept) {
            log.debug(cat("face ", mine[i], ": kept fill (", refused[i].pattern, ", ", pat.quads,
                          " quads, SICN ", pat.sicn_min, " / ", pat.sicn_avg,
                          ") against unstructured (", uns.quads, " quads, SICN ", uns.sicn_min,
                          " / ", uns.sicn_avg, "): ", take ? "fill" : "unstructured"));
            if (!take)
              quasi_reports[i].refusal = qstruct::to_string(qstruct::Refusal::UnstructuredBetter);
          }
        }
        if (take) {
          quad_meshes[i] = std::move(refused[i].mesh);
          quad_reports[i] = quad::UnstructuredReport{};
          quad_reports[i].ok = true;
          quad_reports[i].sicn_min = pat.sicn_min;
          quad_reports[i].quads = pat.quads;
          quasi_reports[i].by_pattern = true;
          quasi_reports[i].by_comparison = !kept;  // that one passed the thresholds
          quasi_reports[i].pattern = refused[i].pattern;
          if (kept) quasi_reports[i].refusal.clear();
        }
        refused[i] = RefusedFill{};
      });
      end_stage("pattern_compare", true);
    }
    meshes = std::move(quad_meshes);
  }

  // Gather on rank 0 and assemble. The assembled mesh is sized first from every face's counts;
  // the faces then arrive one rank at a time and each is written in place and dropped, so that
  // rank 0 holds the assembled mesh and one rank's faces, not every face twice over.
  clock.reset();
  const std::span<const mesh::CurveMesh> final_curves =
      quads ? std::span<const mesh::CurveMesh>(result.quantized_curves)
            : std::span<const mesh::CurveMesh>(curves);
  std::vector<std::int64_t> counts(3 * static_cast<std::size_t>(nfaces), 0);
  for (std::size_t i = 0; i < mine.size(); ++i) {
    const mesh::FaceContribution c = mesh::face_contribution(meshes[i]);
    const auto at = 3 * static_cast<std::size_t>(mine[i]);
    counts[at] = c.interior_vertices;
    counts[at + 1] = c.triangles;
    counts[at + 2] = c.quads;
  }
  comm.allreduce_sum(counts);  // each face's entries are set by its owner alone
  std::vector<char> buffer;
  for (std::size_t i = 0; i < mine.size(); ++i) {
    pack(meshes[i], reports[i], buffer);
    if (options.cross_fields) pack(fields[i], buffer);
    if (options.size_map) pack(sizes[i], buffer);
    if (quads) pack(quad_reports[i], buffer);
    if (quasi) pack(quasi_reports[i], buffer);
    if (quads) {
      const mesh::FaceQuadStats st = mesh::face_quad_stats(meshes[i]);
      for (std::int64_t x :
           {st.vertices, st.quads, st.triangles, st.irregular_interior, st.irregular_boundary})
        put<std::int64_t>(buffer, x);
      put<double>(buffer, st.sicn_min);
      put<double>(buffer, st.sicn_avg);
      put<double>(buffer, face_seconds[i]);
    }
  }
  meshes.clear();
  std::optional<mesh::MeshAssembler> assembler;
  const bool keep_background = size_map && !quads;  // the size map's output draws them
  if (rank == 0) {
    std::vector<mesh::FaceContribution> contributions(static_cast<std::size_t>(nfaces));
    for (LO f = 0; f < nfaces; ++f) {
      const auto at = 3 * static_cast<std::size_t>(f);
      contributions[f] = {counts[at], counts[at + 1], counts[at + 2]};
    }
    assembler.emplace(model, final_curves, contributions);
    result.reports.resize(static_cast<std::size_t>(nfaces));
    if (options.cross_fields) result.cross_fields.resize(static_cast<std::size_t>(nfaces));
    if (options.size_map) result.face_sizes.resize(static_cast<std::size_t>(nfaces));
    if (quads) result.quad_reports.resize(static_cast<std::size_t>(nfaces));
    if (quasi) result.quasi_reports.resize(static_cast<std::size_t>(nfaces));
    if (quads) {
      result.face_stats.resize(static_cast<std::size_t>(nfaces));
      result.face_seconds.resize(static_cast<std::size_t>(nfaces));
    }
    if (keep_background) result.background.resize(static_cast<std::size_t>(nfaces));
  }
  comm.gather_bytes_each(std::move(buffer), 0, [&](int, std::vector<char>& bytes) {
    std::size_t pos = 0;
    while (pos < bytes.size()) {
      mesh::FaceMesh m;
      background::FaceReport r;
      unpack(bytes, pos, m, r);
      const LO f = r.face;
      QSMESH_CHECK(f >= 0 && f < nfaces, "gathered report for unknown face " << f);
      result.reports[f] = std::move(r);
      m.face = f;
      assembler->add_face(f, m);
      if (keep_background) result.background[f] = std::move(m);
      if (options.cross_fields) unpack(bytes, pos, result.cross_fields[f]);
      if (options.size_map) unpack(bytes, pos, result.face_sizes[f]);
      if (quads) unpack(bytes, pos, result.quad_reports[f]);
      if (quasi) unpack(bytes, pos, result.quasi_reports[f]);
      if (quads) {
        mesh::FaceQuadStats& st = result.face_stats[f];
        for (std::int64_t* x : {&st.vertices, &st.quads, &st.triangles, &st.irregular_interior,
                                &st.irregular_boundary})
          *x = get<std::int64_t>(bytes, pos);
        st.sicn_min = get<double>(bytes, pos);
        st.sicn_avg = get<double>(bytes, pos);
        result.face_seconds[f] = get<double>(bytes, pos);
      }
    }
    std::vector<char>().swap(bytes);
  });
  if (rank == 0) result.mesh = assembler->finish();
  end_stage("assemble", false);
  result.rank_busy_seconds.assign(static_cast<std::size_t>(nranks), 0.0);
  result.rank_busy_seconds[static_cast<std::size_t>(rank)] = busy;
  comm.allreduce_sum(result.rank_busy_seconds);
  return result;
}

}  // namespace qsmesh::parallel
