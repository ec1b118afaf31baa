#include "improve.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <numeric>
#include <optional>
#include <string>

#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/qstruct/cavity.hpp"
#include "qsmesh/remesh/disk_remesh.hpp"
#include "qsmesh/smooth/smooth.hpp"
#include "serialize.hpp"

namespace qsmesh::parallel {

namespace {

// A face of any rank, as this rank sees it.
struct Work {
  LO face = kNoIndex;
  int owner = 0;
  std::size_t local = 0;    // index in the owner's `mine`
  std::int64_t offset = 0;  // the face's bytes in the owner's SharedBytes (several ranks)
  std::int64_t length = 0;
  std::int64_t quads = 0;
};

// What improving one face gives, wherever it ran.
struct Result {
  bool done = false;
  mesh::FaceMesh mesh;
  QuasiReport fields;  // the cavity and disk fields only
  double seconds = 0;
  std::array<double, 3> steps{};
};

Result improve_one(const cad::CadModel& model, LO face, mesh::FaceMesh mesh,
                   std::span<const crossfield::Singularity> singularities,
                   const ImproveSettings& settings, Logger& log) {
  Result r;
  r.done = true;
  const Stopwatch total;
  std::unique_ptr<cad::FaceGeometry> surface;
  try {
    surface = model.face_geometry(face);
  } catch (const std::exception& e) {
    log.warn(Error(e.what(), ErrorContext{"topological improvement", 2, face}).what());
  }
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
    r.steps[static_cast<std::size_t>(k)] = clock.seconds();
  };
  // Cavity remeshing (Sec. 6.2): irregular vertices that the cross field does not ask for are
  // removed by remeshing convex cavities with patterns.
  step(0, "cavity remeshing", [&](const cad::FaceGeometry& s) {
    qstruct::CavityReport cr;
    mesh::FaceMesh out =
        qstruct::remesh_cavities(mesh, s, singularities, settings.patterns, settings.cavities, &cr);
    r.fields.irregular_before = cr.irregular_before;
    r.fields.irregular_after = cr.irregular_after;
    r.fields.cavities = cr.remeshed;
    r.fields.time_budget_hit = cr.time_budget_hit;
    return out;
  });
  // Local clean-up (Sec. 6.3): defects remeshed with the best disk quadrangulation, each
  // replacement a transaction.
  step(1, "disk remeshing", [&](const cad::FaceGeometry& s) {
    remesh::DiskRemeshStats ds;
    mesh::FaceMesh out = remesh::remesh_disk_defects(mesh, s, *settings.table, settings.disk, &ds);
    r.fields.defects_before = ds.defects_before;
    r.fields.defects_after = ds.defects_after;
    r.fields.disk_replaced = ds.replaced;
    return out;
  });
  if (settings.final_smoothing)
    step(2, "final smoothing", [&](const cad::FaceGeometry& s) {
      return smooth::smooth_face(mesh, s, settings.final_smooth);
    });
  r.mesh = std::move(mesh);
  r.seconds = total.seconds();
  return r;
}

void copy_fields(const QuasiReport& from, QuasiReport& to) {
  to.irregular_before = from.irregular_before;
  to.irregular_after = from.irregular_after;
  to.cavities = from.cavities;
  to.time_budget_hit = from.time_budget_hit;
  to.defects_before = from.defects_before;
  to.defects_after = from.defects_after;
  to.disk_replaced = from.disk_replaced;
}

void apply(Result&& r, ImproveFace& f) {
  *f.mesh = std::move(r.mesh);
  copy_fields(r.fields, *f.report);
  *f.seconds += r.seconds;
}

void pack_result(LO face, const Result& r, std::vector<char>& out) {
  put<LO>(out, face);
  pack_mesh(r.mesh, out);
  const QuasiReport& q = r.fields;
  for (std::int64_t x :
       {q.irregular_before, q.irregular_after, q.defects_before, q.defects_after, q.disk_replaced})
    put<std::int64_t>(out, x);
  put(out, q.cavities);
  put<std::uint8_t>(out, q.time_budget_hit ? 1 : 0);
  put<double>(out, r.seconds);
}

LO unpack_result(const std::vector<char>& in, std::size_t& pos, Result& r) {
  const auto face = get<LO>(in, pos);
  unpack_mesh(in, pos, r.mesh);
  QuasiReport& q = r.fields;
  for (std::int64_t* x : {&q.irregular_before, &q.irregular_after, &q.defects_before,
                          &q.defects_after, &q.disk_replaced})
    *x = get<std::int64_t>(in, pos);
  q.cavities = get<std::array<std::int64_t, 4>>(in, pos);
  q.time_budget_hit = get<std::uint8_t>(in, pos) != 0;
  r.seconds = get<double>(in, pos);
  r.done = true;
  return face;
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
              const std::function<void(std::int64_t)>& body) {
  SharedCounter counter(comm);
  tasks.parallel_for(tasks.threads(), [&](std::int64_t) {
    for (std::int64_t k = counter.next(); k < n; k = counter.next()) body(k);
  });
}

std::array<double, 3> improve_faces(const Comm& comm, const cad::CadModel& model,
                                    std::span<ImproveFace> mine, const ImproveSettings& settings,
                                    const TaskArena& tasks, Logger& log) {
  QSMESH_CHECK(settings.table != nullptr, "improvement: no disk quadrangulation table");
  const int rank = comm.rank();
  const int nranks = comm.size();

  // Every rank's faces as records (owner, where its bytes lie); this rank's are read in place,
  // another rank's are fetched by whichever rank takes the face, when it takes it.
  std::vector<Work> work;
  std::vector<char> buffer;  // this rank's faces, packed (several ranks)
  for (std::size_t i = 0; i < mine.size(); ++i) {
    Work w{mine[i].face, rank, i, 0, 0, static_cast<std::int64_t>(mine[i].mesh->quads.size())};
    if (nranks > 1) {
      w.offset = static_cast<std::int64_t>(buffer.size());
      pack_mesh(*mine[i].mesh, buffer);
      put_vec(buffer, std::vector<crossfield::Singularity>(mine[i].singularities.begin(),
                                                           mine[i].singularities.end()));
      w.length = static_cast<std::int64_t>(buffer.size()) - w.offset;
    }
    work.push_back(w);
  }
  std::optional<SharedBytes> shared;
  if (nranks > 1) {
    std::vector<char> records;
    for (const Work& w : work) {
      put<LO>(records, w.face);
      put<std::int64_t>(records, w.quads);
      put<std::int64_t>(records, w.offset);
      put<std::int64_t>(records, w.length);
    }
    const auto all = comm.allgather_bytes(records);
    work.clear();
    for (int r = 0; r < nranks; ++r) {
      const std::vector<char>& bytes = all[static_cast<std::size_t>(r)];
      std::size_t pos = 0;
      for (std::size_t i = 0; pos < bytes.size(); ++i) {
        Work w;
        w.owner = r;
        w.local = i;
        w.face = get<LO>(bytes, pos);
        w.quads = get<std::int64_t>(bytes, pos);
        w.offset = get<std::int64_t>(bytes, pos);
        w.length = get<std::int64_t>(bytes, pos);
        QSMESH_CHECK(r != rank || (i < mine.size() && mine[i].face == w.face),
                     "improvement: face record " << w.face << " out of order");
        work.push_back(w);
      }
    }
    shared.emplace(comm, buffer);
    std::vector<char>().swap(buffer);  // the window holds the copy now
  }

  // Largest first, so that the last faces dealt out are short.
  std::vector<std::size_t> order(work.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return work[a].quads != work[b].quads ? work[a].quads > work[b].quads
                                          : work[a].face < work[b].face;
  });
  const auto n = static_cast<std::int64_t>(work.size());
  std::vector<Result> results(work.size());
  DealProgress progress("improvement", n, comm, log);
  deal_out(comm, n, tasks, [&](std::int64_t k) {
    const std::size_t w_at = order[static_cast<std::size_t>(k)];
    const Work& w = work[w_at];
    if (w.owner == rank) {
      ImproveFace& f = mine[w.local];
      results[w_at] =
          improve_one(model, w.face, std::move(*f.mesh), f.singularities, settings, log);
    } else {
      const std::vector<char> bytes = shared->read(w.owner, w.offset, w.length);
      std::size_t pos = 0;
      mesh::FaceMesh in;
      std::vector<crossfield::Singularity> singularities;
      unpack_mesh(bytes, pos, in);
      get_vec(bytes, pos, singularities);
      QSMESH_CHECK(in.face == w.face, "improvement: rank " << w.owner << " sent face " << in.face
                                                           << " for face " << w.face);
      results[w_at] = improve_one(model, w.face, std::move(in), singularities, settings, log);
    }
    progress.done();
  });
  shared.reset();  // collective: every rank is past its last read

  // Results to their owners only; the time of each step summed over the faces of all ranks.
  std::vector<double> steps(3, 0.0);
  std::vector<std::vector<char>> outgoing(static_cast<std::size_t>(nranks));
  for (std::size_t i = 0; i < work.size(); ++i) {
    Result& r = results[i];
    if (!r.done) continue;
    for (std::size_t k = 0; k < 3; ++k) steps[k] += r.steps[k];
    if (work[i].owner == rank) {
      apply(std::move(r), mine[work[i].local]);
    } else {
      pack_result(work[i].face, r, outgoing[static_cast<std::size_t>(work[i].owner)]);
      r = Result{};
    }
  }
  if (nranks > 1) {
    std::vector<std::size_t> local_of_face;  // face -> index in mine + 1 (0: not this rank's)
    for (std::size_t i = 0; i < mine.size(); ++i) {
      const auto f = static_cast<std::size_t>(mine[i].face);
      if (local_of_face.size() <= f) local_of_face.resize(f + 1, 0);
      local_of_face[f] = i + 1;
    }
    const auto incoming = comm.alltoall_bytes(outgoing);
    outgoing = {};
    for (const auto& bytes : incoming) {
      std::size_t pos = 0;
      while (pos < bytes.size()) {
        Result r;
        const auto f = static_cast<std::size_t>(unpack_result(bytes, pos, r));
        QSMESH_CHECK(f < local_of_face.size() && local_of_face[f] != 0,
                     "improvement: the result of face " << f << " came to a rank not owning it");
        apply(std::move(r), mine[local_of_face[f] - 1]);
      }
    }
    comm.allreduce_sum(steps);
  }
  return {steps[0], steps[1], steps[2]};
}

}  // namespace qsmesh::parallel
