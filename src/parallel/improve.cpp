#include "improve.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <string>

#include "exchange.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/mesh/pieces.hpp"
#include "qsmesh/parallel/record.hpp"
#include "qsmesh/qstruct/cavity.hpp"
#include "qsmesh/remesh/disk_remesh.hpp"
#include "qsmesh/smooth/smooth.hpp"
#include "qsmesh/smooth/untangle.hpp"

namespace qsmesh::parallel {

namespace {

// A task of any rank, as this rank sees it: a whole face, or a piece of one (issue 28).
struct Work {
  LO face = kNoIndex;
  LO piece = kNoIndex;      // kNoIndex: the whole face
  LO pass = 0;              // Pass: both passes, or one of a face's two pass tasks
  int owner = 0;            // not exchanged: the sender
  std::size_t local = 0;    // index in the owner's tasks; not exchanged: the order received
  std::int64_t offset = 0;  // the task's bytes in the owner's SharedBytes (several ranks)
  std::int64_t length = 0;
  std::int64_t quads = 0;
  // What every rank learns of every task.
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("face", self.face);
    visit("piece", self.piece);
    visit("pass", self.pass);
    visit("quads", self.quads);
    visit("offset", self.offset);
    visit("length", self.length);
  }
};

// What a task holds: a mesh (a face's or a piece's) and the singularities within it.
struct Input {
  mesh::FaceMesh mesh;
  std::vector<crossfield::Singularity> singularities;
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("mesh", self.mesh);
    visit("singularities", self.singularities);
  }
};

// Which passes of the improvement a task runs: both in a row (the first, then the second where
// second_pass_applies), or one of them, the face's other pass being a task of its own
// (ImproveSettings::second_pass_task_irregular).
enum Pass : LO { kBothPasses = 0, kFirstPass = 1, kSecondPass = 2 };

// A task of this rank.
struct Task {
  LO face = kNoIndex;
  LO piece = kNoIndex;
  LO pass = kBothPasses;
  Input input;
};

// What improving one task gives, wherever it ran.
struct Result {
  bool done = false;  // not exchanged: a received result is done
  mesh::FaceMesh mesh;
  ImprovementReport report;
  double seconds = 0;
  std::array<double, 3> steps{};  // not exchanged: summed over all tasks by a reduction
  // A first pass's result asks for the second pass (second_pass_applies).
  bool second_wanted = false;
  // A second pass not run: its first, ended on the same rank before it, did not want it.
  bool skipped = false;
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("mesh", self.mesh);
    visit("report", self.report);
    visit("seconds", self.seconds);
    visit("second_wanted", self.second_wanted);
    visit("skipped", self.skipped);
  }
};

// One pass of the steps (cavity, disk, final smoothing) on `mesh` with these cavity options;
// `flagged_kept` gets the flagged vertices the cavity step kept (0 when it did not run).
Result improve_pass(LO face, mesh::FaceMesh mesh, const cad::FaceGeometry* surface,
                    std::span<const crossfield::Singularity> singularities,
                    const ImproveSettings& settings, const qstruct::CavityOptions& cavities,
                    qstruct::CavityMemo& memo, Logger& log, std::int64_t& flagged_kept) {
  Result r;
  r.done = true;
  flagged_kept = 0;
  // A step that throws leaves the face's valid mesh as it was.
  const auto step = [&](int k, const char* what, const auto& run) {
    if (surface == nullptr) return;
    const Stopwatch clock;
    try {
      mesh::FaceMesh out = run(*surface);
      out.face = face;
      mesh = std::move(out);
    } catch (const std::exception& e) {
      log.warn(Error(e.what(), ErrorContext{what, 2, face}).what());
    }
    r.steps[static_cast<std::size_t>(k)] += clock.seconds();
  };
  // Cavity remeshing (Sec. 6.2): irregular vertices that the cross field does not ask for are
  // removed by remeshing convex cavities with patterns.
  step(0, "cavity remeshing", [&](const cad::FaceGeometry& s) {
    qstruct::CavityReport cr;
    mesh::FaceMesh out =
        qstruct::remesh_cavities(mesh, s, singularities, settings.patterns, cavities, &cr, &memo);
    r.report.record(cr);
    flagged_kept = cr.flagged_kept;
    return out;
  });
  // Local clean-up (Sec. 6.3): defects remeshed with the best disk quadrangulation, each
  // replacement a transaction.
  step(1, "disk remeshing", [&](const cad::FaceGeometry& s) {
    remesh::DiskRemeshStats ds;
    // In a piece, a cut vertex is a corner whose valence is what the piece has: it is no defect
    // and keeps it (the angle estimate would call a staircase of the cut a row of defects).
    const bool piece =
        std::any_of(mesh.vclass.begin(), mesh.vclass.end(),
                    [](const mesh::VertexClass& c) { return mesh::is_cut_vertex(c); });
    mesh::FaceMesh out;
    if (piece) {
      remesh::DiskRemeshOptions disk = settings.disk;
      disk.corner_valence = remesh::estimate_corner_valences(mesh);
      std::vector<int> valence(mesh.points.size(), 0);
      for (const auto& q : mesh.quads)
        for (const LO v : q) ++valence[static_cast<std::size_t>(v)];
      for (std::size_t v = 0; v < mesh.vclass.size(); ++v)
        if (mesh::is_cut_vertex(mesh.vclass[v])) disk.corner_valence[v] = valence[v];
      out = remesh::remesh_disk_defects(mesh, s, *settings.table, disk, &ds);
    } else {
      out = remesh::remesh_disk_defects(mesh, s, *settings.table, settings.disk, &ds);
    }
    r.report.record(ds);
    return out;
  });
  if (settings.final_smoothing)
    step(2, "final smoothing", [&](const cad::FaceGeometry& s) {
      mesh::FaceMesh out = smooth::smooth_face(mesh, s, settings.final_smooth);
      // The smoother keeps the quads that split a curve vertex's angle very unevenly (issue 29).
      // The lift judges a patch by its minimum; the kernels after it (each move kept only when
      // the minimum of its quads does not drop, so they cannot undo it) give back most of the
      // mean it cost. Not the uv Laplacian: a global step, it would put the lifted vertices back
      // wherever the face's minimum is elsewhere.
      if (settings.lift.target > 0) {
        smooth::LiftStats ls;
        out = smooth::lift_poor_quads(out, s, settings.lift, &ls);
        if (ls.lifted > 0) {
          smooth::SmoothOptions kernels = settings.final_smooth;
          kernels.laplacian_uv = false;
          out = smooth::smooth_face(out, s, kernels);
        }
      }
      return out;
    });
  r.mesh = std::move(mesh);
  return r;
}

// The face's result of its two passes: the second's where it wins (second_pass_wins), else the
// first's; the steps' times of both.
Result choose_pass(Result first, Result second, const ImproveSettings& settings) {
  std::array<double, 3> steps{};
  for (std::size_t k = 0; k < steps.size(); ++k) steps[k] = first.steps[k] + second.steps[k];
  const bool keep =
      !second.report.time_budget_hit &&
      second_pass_wins(
          mesh::face_quad_stats(first.mesh), mesh::face_quad_stats(second.mesh),
          settings.second_pass_sicn_per_irregular, settings.second_pass_sicn_sum_per_irregular,
          settings.second_pass_cavities.good_sicn, settings.second_pass_cavities.keep_ratio);
  Result r = keep ? std::move(second) : std::move(first);
  if (keep) r.report.second_pass_kept = true;
  r.steps = steps;
  r.second_wanted = true;
  return r;
}

// Improves one task: its mesh through both passes (kBothPasses), or one of them.
Result improve_one(const cad::CadModel& model, LO face, mesh::FaceMesh mesh,
                   std::span<const crossfield::Singularity> singularities,
                   const ImproveSettings& settings, Logger& log, LO pass,
                   qstruct::CavityMemo* shared_memo = nullptr) {
  const Stopwatch total;
  std::unique_ptr<cad::FaceGeometry> surface;
  try {
    surface = model.face_geometry(face);
  } catch (const std::exception& e) {
    log.warn(Error(e.what(), ErrorContext{"topological improvement", 2, face}).what());
  }
  const bool piece = std::any_of(mesh.vclass.begin(), mesh.vclass.end(),
                                 [](const mesh::VertexClass& c) { return mesh::is_cut_vertex(c); });
  const bool second_pass = settings.second_pass_sicn_per_irregular > 0 && !piece &&
                           surface != nullptr && !mesh.quads.empty() && mesh.triangles.empty();
  // The candidates the first pass refused are refused by the second too when its bounds still
  // refuse them: it starts from the same mesh (qstruct::CavityMemo). One memo per task, or the
  // one a first pass leaves its second where both run on this rank in turn (`shared_memo`).
  qstruct::CavityMemo own_memo;
  qstruct::CavityMemo& memo = shared_memo != nullptr ? *shared_memo : own_memo;
  if (pass == kSecondPass) {
    // The second pass alone, from the face's input, while the first runs as another task.
    Result r;
    if (second_pass) {
      std::int64_t flagged = 0;
      r = improve_pass(face, std::move(mesh), surface.get(), singularities, settings,
                       settings.second_pass_cavities, memo, log, flagged);
    } else {
      r.done = true;
      r.mesh = std::move(mesh);
    }
    r.seconds = total.seconds();
    return r;
  }
  std::optional<mesh::FaceMesh> input;
  if (second_pass && pass == kBothPasses) input = mesh;
  std::int64_t flagged = 0;
  Result r = improve_pass(face, std::move(mesh), surface.get(), singularities, settings,
                          settings.cavities, memo, log, flagged);
  r.second_wanted =
      second_pass &&
      second_pass_applies(mesh::face_quad_stats(r.mesh), flagged, r.report.time_budget_hit,
                          settings.second_pass_min_unnecessary, settings.second_pass_max_quads);
  if (r.second_wanted && pass == kBothPasses) {
    std::int64_t flagged2 = 0;
    Result again = improve_pass(face, std::move(*input), surface.get(), singularities, settings,
                                settings.second_pass_cavities, memo, log, flagged2);
    r = choose_pass(std::move(r), std::move(again), settings);
  }
  r.seconds = total.seconds();
  return r;
}

// Deals `mine` (this rank's tasks; their inputs are consumed) over the threads of all ranks,
// largest first (quads, then face, then piece), and returns the results of this rank's tasks in
// their order; adds the time of each step of the tasks it ran to `steps`. Collective.
std::vector<Result> deal_round(const Comm& comm, const cad::CadModel& model,
                               std::vector<Task>& mine, const ImproveSettings& settings,
                               const TaskArena& tasks, Logger& log, const char* stage,
                               std::vector<double>& steps) {
  const int rank = comm.rank();
  const int nranks = comm.size();

  // Every rank's tasks as records (owner, where its bytes lie); this rank's are read in place,
  // another rank's are fetched by whichever rank takes the task, when it takes it.
  std::vector<Work> work;
  std::vector<char> buffer;  // this rank's tasks, packed (several ranks)
  for (std::size_t i = 0; i < mine.size(); ++i) {
    Work w{mine[i].face,
           mine[i].piece,
           mine[i].pass,
           rank,
           i,
           0,
           0,
           static_cast<std::int64_t>(mine[i].input.mesh.quads.size())};
    if (nranks > 1) {
      w.offset = static_cast<std::int64_t>(buffer.size());
      write_record(buffer, mine[i].input);
      w.length = static_cast<std::int64_t>(buffer.size()) - w.offset;
    }
    work.push_back(w);
  }
  std::optional<SharedBytes> shared;
  if (nranks > 1) {
    std::vector<char> records;
    for (const Work& w : work) write_record(records, w);
    const auto all = comm.allgather_bytes(records);
    work.clear();
    for (int r = 0; r < nranks; ++r) {
      const std::vector<char>& bytes = all[static_cast<std::size_t>(r)];
      std::size_t pos = 0;
      for (std::size_t i = 0; pos < bytes.size(); ++i) {
        Work w;
        w.owner = r;
        w.local = i;
        read_record(bytes, pos, w);
        QSMESH_CHECK(r != rank || (i < mine.size() && mine[i].face == w.face &&
                                   mine[i].piece == w.piece && mine[i].pass == w.pass),
                     "improvement: task record " << w.face << "/" << w.piece << " out of order");
        work.push_back(w);
      }
    }
    shared.emplace(comm, buffer);
    std::vector<char>().swap(buffer);  // the window holds the copy now
  }

  // Largest first, so that the last tasks dealt out are short; the second passes dealt as tasks
  // of their own after all others, so that a thread that takes one after its first pass ended
  // on this rank knows whether the face wants it.
  std::vector<std::size_t> order(work.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    const Work& x = work[a];
    const Work& y = work[b];
    if ((x.pass == kSecondPass) != (y.pass == kSecondPass)) return y.pass == kSecondPass;
    if (x.quads != y.quads) return x.quads > y.quads;
    if (x.face != y.face) return x.face < y.face;
    return x.piece != y.piece ? x.piece < y.piece : x.pass < y.pass;
  });
  const auto n = static_cast<std::int64_t>(work.size());
  std::vector<Result> results(work.size());
  // Per task, once a first pass (kFirstPass) ended on this rank: 1 when its result asks for the
  // second pass, 2 when not. A second pass whose first is known not to want it is skipped; one
  // whose first ran elsewhere or has not ended runs (and may be dropped by the owner). Which
  // runs depends on timing, the mesh does not: a skipped pass is never wanted.
  std::vector<std::atomic<int>> first_ended(work.size());
  // The memo of each first pass run on this rank whose result asks for the second, for the
  // second where it starts after (the same result with less work).
  std::vector<std::unique_ptr<qstruct::CavityMemo>> memos(work.size());
  DealProgress progress(stage, n, comm, log);
  deal_out(comm, n, tasks, [&](std::int64_t k) {
    const std::size_t w_at = order[static_cast<std::size_t>(k)];
    const Work& w = work[w_at];
    // A second pass's first is the task before it (the same owner's).
    qstruct::CavityMemo* memo = nullptr;
    if (w.pass == kSecondPass && w_at > 0 && work[w_at - 1].pass == kFirstPass &&
        work[w_at - 1].face == w.face) {
      const int first = first_ended[w_at - 1].load(std::memory_order_acquire);
      if (first == 2) {
        results[w_at].done = true;
        results[w_at].skipped = true;
        progress.done();
        return;
      }
      if (first == 1) memo = memos[w_at - 1].get();
    }
    std::unique_ptr<qstruct::CavityMemo> first_memo;
    if (w.pass == kFirstPass) {
      first_memo = std::make_unique<qstruct::CavityMemo>();
      memo = first_memo.get();
    }
    if (w.owner == rank) {
      Task& t = mine[w.local];
      results[w_at] = improve_one(model, w.face, std::move(t.input.mesh), t.input.singularities,
                                  settings, log, w.pass, memo);
    } else {
      const std::vector<char> bytes = shared->read(w.owner, w.offset, w.length);
      std::size_t pos = 0;
      Input in;
      read_record(bytes, pos, in);
      QSMESH_CHECK(in.mesh.face == w.face, "improvement: rank " << w.owner << " sent face "
                                                                << in.mesh.face << " for face "
                                                                << w.face);
      results[w_at] = improve_one(model, w.face, std::move(in.mesh), in.singularities, settings,
                                  log, w.pass, memo);
    }
    if (w.pass == kSecondPass && memo != nullptr) memos[w_at - 1].reset();
    if (w.pass == kFirstPass) {
      if (results[w_at].second_wanted) memos[w_at] = std::move(first_memo);
      first_ended[w_at].store(results[w_at].second_wanted ? 1 : 2, std::memory_order_release);
    }
    progress.done();
  });
  shared.reset();  // collective: every rank is past its last read

  // Results to their owners only, keyed by their index in the owner's tasks.
  std::vector<Result> out(mine.size());
  ToOwners<Result> to_owners(nranks);
  for (std::size_t i = 0; i < work.size(); ++i) {
    Result& r = results[i];
    if (!r.done) continue;
    for (std::size_t k = 0; k < 3; ++k) steps[k] += r.steps[k];
    if (work[i].owner == rank) {
      out[work[i].local] = std::move(r);
    } else {
      to_owners.add(work[i].owner, static_cast<LO>(work[i].local), r);
      r = Result{};
    }
  }
  to_owners.deliver(comm, [&](LO local, Result&& r) {
    QSMESH_CHECK(local >= 0 && static_cast<std::size_t>(local) < out.size(),
                 "improvement: result of task " << local << " of " << out.size());
    r.done = true;
    out[static_cast<std::size_t>(local)] = std::move(r);
  });
  for (const Result& r : out) QSMESH_CHECK(r.done, "improvement: a task's result is missing");
  return out;
}

// The singularities within each piece: those whose nearest quad centroid lies in it (ties: the
// lower quad id), so that a piece flags no vertex for a singularity of its neighbour.
std::vector<std::vector<crossfield::Singularity>> singularities_of_pieces(
    const mesh::FaceMesh& m, std::span<const LO> quad_piece, LO pieces,
    std::span<const crossfield::Singularity> singularities) {
  std::vector<std::vector<crossfield::Singularity>> out(static_cast<std::size_t>(pieces));
  if (singularities.empty()) return out;
  const std::vector<Vec3> centroid = mesh::quad_centroids(m);
  for (const auto& s : singularities) {
    double best = std::numeric_limits<double>::max();
    LO at = 0;
    for (std::size_t q = 0; q < centroid.size(); ++q) {
      const double d = norm2(centroid[q] - s.position);
      if (d < best) {
        best = d;
        at = quad_piece[q];
      }
    }
    out[static_cast<std::size_t>(at)].push_back(s);
  }
  return out;
}

// A face of this rank cut into pieces, between the rounds.
struct Split {
  std::size_t face = 0;  // index in `mine`
  LO pieces = 0;         // k, the pieces of the first pass
  mesh::FaceMesh input;  // the mesh the pass started from
  std::vector<mesh::FacePiece> cut;
  std::size_t first_task = 0;  // its first piece among the round's tasks
  std::int64_t irregular_before = 0;
};

// Cuts split.input into pieces by `quad_piece` and appends them to `round` as tasks.
void add_pieces(Split& split, std::span<const LO> quad_piece, LO pieces,
                std::span<const crossfield::Singularity> singularities, std::vector<Task>& round) {
  split.cut = mesh::split_face_mesh(split.input, quad_piece, pieces);
  auto sing = singularities_of_pieces(split.input, quad_piece, pieces, singularities);
  split.first_task = round.size();
  for (LO p = 0; p < pieces; ++p) {
    Task t;
    t.face = split.input.face;
    t.piece = p;
    t.input.mesh = split.cut[static_cast<std::size_t>(p)].mesh;
    t.input.singularities = std::move(sing[static_cast<std::size_t>(p)]);
    round.push_back(std::move(t));
  }
}

// Merges the improved pieces of `split` (results[first_task...]); the counts (ImprovementReport::
// add_piece) and times go to `f`. A piece whose result cannot be merged gives way to its input
// (logged).
mesh::FaceMesh merge_pieces(const Split& split, std::vector<Result>& results, ImproveFace& f,
                            bool first_cut, Logger& log) {
  std::vector<mesh::FaceMesh> improved;
  for (std::size_t p = 0; p < split.cut.size(); ++p) {
    Result& r = results[split.first_task + p];
    improved.push_back(std::move(r.mesh));
    f.report->add_piece(r.report, first_cut);
    *f.seconds += r.seconds;
    if (f.task_seconds != nullptr) f.task_seconds->push_back(r.seconds);
  }
  try {
    return mesh::merge_face_pieces(split.input, split.cut, improved);
  } catch (const std::exception& e) {
    log.warn(Error(e.what(), ErrorContext{"merging the pieces", 2, split.input.face}).what());
  }
  // Piece by piece: a piece that does not fit keeps its input.
  for (std::size_t p = 0; p < split.cut.size(); ++p) {
    const std::array<mesh::FaceMesh, 1> one{improved[p]};
    try {
      (void)mesh::merge_face_pieces(split.input, std::span(&split.cut[p], 1), one);
    } catch (const std::exception&) {
      improved[p] = split.cut[p].mesh;
    }
  }
  try {
    return mesh::merge_face_pieces(split.input, split.cut, improved);
  } catch (const std::exception& e) {
    log.warn(Error(e.what(), ErrorContext{"merging the pieces", 2, split.input.face}).what());
    return split.input;  // the face as this pass found it
  }
}

void apply(Result&& r, ImproveFace& f) {
  *f.mesh = std::move(r.mesh);
  *f.report = r.report;
  *f.seconds += r.seconds;
}

}  // namespace

void DealProgress::done() {
  const std::int64_t d = ++done_;
  if (n_ <= 0 || d * 10 / n_ == (d - 1) * 10 / n_) return;
  log_.info(ranks_ == 1
                ? cat(stage_, ": ", d, "/", n_, " faces")
                : cat(stage_, ": ", d, " faces on rank ", rank_, " (", n_, " on all ranks)"));
}

void deal_out(const Comm& comm, std::int64_t n, const TaskArena& tasks,
              const std::function<void(std::int64_t)>& body, const std::function<void()>& then) {
  SharedCounter counter(comm);
  tasks.parallel_for(tasks.threads(), [&](std::int64_t) {
    for (std::int64_t k = counter.next(); k < n; k = counter.next()) body(k);
  });
  // The counter's destruction is collective: a rank that waits there cannot help the others.
  if (then) then();
}

std::array<double, 3> improve_faces(const Comm& comm, const cad::CadModel& model,
                                    std::span<ImproveFace> mine, const ImproveSettings& settings,
                                    const TaskArena& tasks, Logger& log) {
  QSMESH_CHECK(settings.table != nullptr, "improvement: no disk quadrangulation table");
  std::vector<double> steps(3, 0.0);

  // Round 1: the whole faces, and the pieces of the first cut of the faces above
  // settings.task_quads.
  std::vector<Task> round;
  // Each whole face: index in `mine`, its task (or first pass), its second pass's task (npos:
  // none of its own).
  constexpr std::size_t kNone = std::numeric_limits<std::size_t>::max();
  std::vector<std::array<std::size_t, 3>> whole;
  std::vector<Split> splits;
  for (std::size_t i = 0; i < mine.size(); ++i) {
    const ImproveFace& f = mine[i];
    const auto quads = static_cast<std::int64_t>(f.mesh->quads.size());
    if (settings.task_quads > 0 && quads > settings.task_quads && f.mesh->triangles.empty()) {
      const Stopwatch clock;  // cutting is part of the face's time
      *f.report = ImprovementReport{};
      Split s;
      s.face = i;
      s.pieces = static_cast<LO>((quads + settings.task_quads - 1) / settings.task_quads);
      s.input = std::move(*f.mesh);
      s.irregular_before = qstruct::count_irregular(s.input);
      const std::vector<LO> part = mesh::bisect_quads(s.input, s.pieces, false);
      const LO n = part.empty() ? 0 : *std::max_element(part.begin(), part.end()) + 1;
      add_pieces(s, part, n, f.singularities, round);
      splits.push_back(std::move(s));
      *f.seconds += clock.seconds();
    } else {
      const bool two_tasks =
          settings.second_pass_task_irregular > 0 && settings.second_pass_sicn_per_irregular > 0 &&
          settings.cavities.time_budget_s <= 0 && !f.mesh->quads.empty() &&
          f.mesh->triangles.empty() &&
          (settings.second_pass_max_quads <= 0 || quads <= settings.second_pass_max_quads) &&
          qstruct::count_irregular(*f.mesh) >= settings.second_pass_task_irregular;
      Task t;
      t.face = f.face;
      t.pass = two_tasks ? kFirstPass : kBothPasses;
      t.input.mesh = std::move(*f.mesh);
      t.input.singularities.assign(f.singularities.begin(), f.singularities.end());
      whole.push_back({i, round.size(), two_tasks ? round.size() + 1 : kNone});
      if (two_tasks) {
        Task second = t;
        second.pass = kSecondPass;
        round.push_back(std::move(t));
        round.push_back(std::move(second));
      } else {
        round.push_back(std::move(t));
      }
    }
  }
  std::vector<Result> results =
      deal_round(comm, model, round, settings, tasks, log, "improvement", steps);
  for (const auto& [i, k, k2] : whole) {
    if (k2 == kNone) {
      apply(std::move(results[k]), mine[i]);
      continue;
    }
    // The two passes' tasks: the second's result where the first's asks for it and it wins.
    ImproveFace& f = mine[i];
    const Stopwatch clock;  // the choice is part of the face's time
    const double passes = results[k].seconds + results[k2].seconds;
    if (f.pass_seconds != nullptr) {
      f.pass_seconds->push_back(results[k].seconds);
      f.pass_seconds->push_back(results[k2].seconds);
    }
    QSMESH_CHECK(!results[k].second_wanted || !results[k2].skipped,
                 "improvement: face " << f.face << " wants the second pass it skipped");
    Result r = results[k].second_wanted
                   ? choose_pass(std::move(results[k]), std::move(results[k2]), settings)
                   : std::move(results[k]);
    r.seconds = passes;
    apply(std::move(r), f);
    *f.seconds += clock.seconds();
  }

  // Round 2, where any face was cut: the merged faces cut again halfway between the first cuts
  // (bisect_quads shifted), so that the cavity and disk passes run across the first cuts and
  // remove the irregular vertices they alone left.
  const bool any_split = comm.size() > 1 ? !comm.allreduce_and(splits.empty()) : !splits.empty();
  if (any_split) {
    round.clear();
    for (Split& s : splits) {
      ImproveFace& f = mine[s.face];
      const Stopwatch clock;
      mesh::FaceMesh merged = merge_pieces(s, results, f, /*first_cut=*/true, log);
      s.input = std::move(merged);
      const std::vector<LO> part = mesh::bisect_quads(s.input, s.pieces, true);
      const LO n = part.empty() ? 0 : *std::max_element(part.begin(), part.end()) + 1;
      add_pieces(s, part, n, f.singularities, round);
      *f.seconds += clock.seconds();
    }
    results =
        deal_round(comm, model, round, settings, tasks, log, "improvement (second cut)", steps);
    for (Split& s : splits) {
      ImproveFace& f = mine[s.face];
      const Stopwatch clock;
      *f.mesh = merge_pieces(s, results, f, /*first_cut=*/false, log);
      f.mesh->face = f.face;
      *f.seconds += clock.seconds();
    }
    // Round 3 (settings.whole_pass_after_cuts): each cut face whole, its cavity and disk steps
    // once more from its merged mesh. A piece's cavities stop at its cut vertices, which keep their
    // valence, and the escalated growths that join sparse pairs far apart (CavityOptions::
    // max_quads_sparse) do not fit in pieces of a few thousand quads; the irregular vertices they
    // would have removed are spread over the face, not at its cuts (docs/benchmarks.md, "Cut
    // faces improved once more whole"). Few seeds are left by then, so the whole face costs a
    // fraction of its first improvement.
    if (settings.whole_pass_after_cuts) {
      round.clear();
      for (const Split& s : splits) {
        const ImproveFace& f = mine[s.face];
        Task t;
        t.face = f.face;
        t.input.mesh = std::move(*f.mesh);
        t.input.singularities.assign(f.singularities.begin(), f.singularities.end());
        round.push_back(std::move(t));
      }
      // The pieces were smoothed and lifted already, and a cavity's replacement is smoothed
      // where it lands: the whole face's final smoothing, most of this task's time where it ran,
      // is left out (docs/benchmarks.md, "Cut faces improved once more whole").
      ImproveSettings whole_face = settings;
      whole_face.final_smoothing = false;
      results = deal_round(comm, model, round, whole_face, tasks, log,
                           "improvement (cut faces whole)", steps);
      for (std::size_t j = 0; j < splits.size(); ++j) {
        ImproveFace& f = mine[splits[j].face];
        Result& r = results[j];
        *f.mesh = std::move(r.mesh);
        f.mesh->face = f.face;
        f.report->add_piece(r.report, /*first_cut=*/false);
        f.report->second_pass_kept = f.report->second_pass_kept || r.report.second_pass_kept;
        *f.seconds += r.seconds;
        if (f.task_seconds != nullptr) f.task_seconds->push_back(r.seconds);
      }
    }
    for (const Split& s : splits) {
      ImproveFace& f = mine[s.face];
      f.report->whole_face(s.irregular_before, qstruct::count_irregular(*f.mesh),
                           remesh::count_defects(*f.mesh, settings.disk));
    }
  }
  if (comm.size() > 1) comm.allreduce_sum(steps);
  return {steps[0], steps[1], steps[2]};
}

}  // namespace qsmesh::parallel
