// The pattern fill's move search lent to ranks that have finished their own faces (issue 28):
// qstruct::MoveLayoutHelpers over parallel::RankHelpers (src/parallel only; qstruct sees the
// interface alone, without MPI).
#pragma once

#include <functional>
#include <span>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"
#include "qsmesh/parallel/comm.hpp"
#include "qsmesh/qstruct/face_pattern.hpp"
#include "qsmesh/qstruct/patterns.hpp"

namespace qsmesh::parallel {

/// Lays out a face's move layouts over the free ranks of `ranks` (RankHelpers::claim) and the
/// caller: request u goes to worker u mod (claimed + 1), worker 0 being the caller; the results
/// come back in request order. A helper lays out with qstruct::lay_out_move, on the same model,
/// final curve meshes, pattern list and options as the owner (every rank holds them), so each
/// layout is bit for bit the owner's. The referenced objects must outlive this one; one thread.
class RankLayoutHelpers final : public qstruct::MoveLayoutHelpers {
 public:
  RankLayoutHelpers(RankHelpers& ranks, const cad::CadModel& model,
                    std::span<const mesh::CurveMesh> curves,
                    std::span<const qstruct::Pattern> patterns,
                    const qstruct::PatternFaceOptions& options);
  int claim(int wanted) override;
  std::vector<qstruct::MoveLayoutResult> lay_out(
      const std::vector<qstruct::MoveLayoutRequest>& requests,
      const std::function<qstruct::MoveLayoutResult(const qstruct::MoveLayoutRequest&)>& here)
      override;
  /// This rank's own faces are done: it lays out other ranks' shares until every rank is done
  /// (RankHelpers::serve_until_all_done). Every rank calls it once.
  void serve_until_all_done();
  /// The answer to one packed share (a vector of requests): the packed vector of results.
  [[nodiscard]] std::vector<char> serve(const std::vector<char>& share);
  /// Layouts this rank made for other ranks.
  [[nodiscard]] std::int64_t served() const { return served_; }

 private:
  RankHelpers& ranks_;
  const cad::CadModel& model_;
  std::span<const mesh::CurveMesh> curves_;
  std::span<const qstruct::Pattern> patterns_;
  const qstruct::PatternFaceOptions& options_;
  std::vector<int> claimed_;
  LO sides_face_ = kNoIndex;  // the face whose sides are kept (the shares of one search repeat it)
  qstruct::FaceSides sides_;
  std::int64_t served_ = 0;
};

}  // namespace qsmesh::parallel
