#include "improve.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>
#include <numeric>
#include <optional>
#include <string>

#include "exchange.hpp"
#include "qsmesh/core/error.hpp"
#include "qsmesh/core/timer.hpp"
#include "qsmesh/parallel/record.hpp"
#include "qsmesh/qstruct/cavity.hpp"
#include "qsmesh/remesh/disk_remesh.hpp"
#include "qsmesh/smooth/smooth.hpp"

namespace qsmesh::parallel {

namespace {

// A face of any rank, as this rank sees it.
struct Work {
  LO face = kNoIndex;
  int owner = 0;            // not exchanged: the sender
  std::size_t local = 0;    // index in the owner's `mine`; not exchanged: the order received
  std::int64_t offset = 0;  // the face's bytes in the owner's SharedBytes (several ranks)
  std::int64_t length = 0;
  std::int64_t quads = 0;
  // What every rank learns of every face.
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("face", self.face);
    visit("quads", self.quads);
    visit("offset", self.offset);
    visit("length", self.length);
  }
};

// What a face taken away from its owner holds: its mesh and singularities.
struct Input {
  mesh::FaceMesh mesh;
  std::vector<crossfield::Singularity> singularities;
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("mesh", self.mesh);
    visit("singularities", self.singularities);
  }
};

// What improving one face gives, wherever it ran.
struct Result {
  bool done = false;  // not exchanged: a received result is done
  mesh::FaceMesh mesh;
  ImprovementReport report;
  double seconds = 0;
  std::array<double, 3> steps{};  // not exchanged: summed over all faces by a reduction
  template <class S, class V>
  static void fields(S& self, V&& visit) {
    visit("mesh", self.mesh);
    visit("report", self.report);
    visit("seconds", self.seconds);
  }
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
    r.report.record(cr);
    return out;
  });
  // Local clean-up (Sec. 6.3): defects remeshed with the best disk quadrangulation, each
  // replacement a transaction.
  step(1, "disk remeshing", [&](const cad::FaceGeometry& s) {
    remesh::DiskRemeshStats ds;
    mesh::FaceMesh out = remesh::remesh_disk_defects(mesh, s, *settings.table, settings.disk, &ds);
    r.report.record(ds);
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
      // Input's fields in order, without copying the mesh into one.
      write_record(buffer, *mine[i].mesh);
      write_record(buffer, std::vector<crossfield::Singularity>(mine[i].singularities.begin(),
                                                                mine[i].singularities.end()));
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
      Input in;
      read_record(bytes, pos, in);
      QSMESH_CHECK(in.mesh.face == w.face, "improvement: rank " << w.owner << " sent face "
                                                                << in.mesh.face << " for face "
                                                                << w.face);
      results[w_at] =
          improve_one(model, w.face, std::move(in.mesh), in.singularities, settings, log);
    }
    progress.done();
  });
  shared.reset();  // collective: every rank is past its last read

  // Results to their owners only; the time of each step summed over the faces of all ranks.
  std::vector<double> steps(3, 0.0);
  ToOwners<Result> to_owners(nranks);
  for (std::size_t i = 0; i < work.size(); ++i) {
    Result& r = results[i];
    if (!r.done) continue;
    for (std::size_t k = 0; k < 3; ++k) steps[k] += r.steps[k];
    if (work[i].owner == rank) {
      apply(std::move(r), mine[work[i].local]);
    } else {
      to_owners.add(work[i].owner, work[i].face, r);
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
    to_owners.deliver(comm, [&](LO face, Result&& r) {
      const auto f = static_cast<std::size_t>(face);
      QSMESH_CHECK(face >= 0 && f < local_of_face.size() && local_of_face[f] != 0,
                   "improvement: the result of face " << f << " came to a rank not owning it");
      apply(std::move(r), mine[local_of_face[f] - 1]);
    });
    comm.allreduce_sum(steps);
  }
  return {steps[0], steps[1], steps[2]};
}

}  // namespace qsmesh::parallel
