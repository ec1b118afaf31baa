#include "qsmesh/parallel/pattern_helpers.hpp"

#include "qsmesh/core/error.hpp"
#include "qsmesh/parallel/record.hpp"

namespace qsmesh::parallel {

RankLayoutHelpers::RankLayoutHelpers(RankHelpers& ranks, const cad::CadModel& model,
                                     std::span<const mesh::CurveMesh> curves,
                                     std::span<const qstruct::Pattern> patterns,
                                     const qstruct::PatternFaceOptions& options)
    : ranks_(ranks), model_(model), curves_(curves), patterns_(patterns), options_(options) {}

int RankLayoutHelpers::claim(int wanted) {
  const std::vector<int> got = ranks_.claim(wanted);
  claimed_.insert(claimed_.end(), got.begin(), got.end());
  return static_cast<int>(got.size());
}

std::vector<qstruct::MoveLayoutResult> RankLayoutHelpers::lay_out(
    const std::vector<qstruct::MoveLayoutRequest>& requests,
    const std::function<qstruct::MoveLayoutResult(const qstruct::MoveLayoutRequest&)>& here) {
  const std::vector<int> helpers = std::move(claimed_);
  claimed_.clear();
  const std::size_t workers = helpers.size() + 1;
  // Each claimed rank gets its share, possibly empty (that releases it).
  std::vector<std::vector<char>> shares(helpers.size());
  for (std::size_t h = 0; h < helpers.size(); ++h) {
    std::vector<qstruct::MoveLayoutRequest> mine;
    for (std::size_t u = h + 1; u < requests.size(); u += workers) mine.push_back(requests[u]);
    if (!mine.empty()) write_record(shares[h], mine);
    ranks_.send(helpers[h], shares[h]);
  }
  std::vector<qstruct::MoveLayoutResult> results(requests.size());
  for (std::size_t u = 0; u < requests.size(); u += workers) results[u] = here(requests[u]);
  ranks_.wait_sent();
  for (std::size_t h = 0; h < helpers.size(); ++h) {
    const std::vector<char> answer = ranks_.receive(helpers[h]);
    if (shares[h].empty()) continue;
    std::vector<qstruct::MoveLayoutResult> theirs;
    std::size_t pos = 0;
    read_record(answer, pos, theirs);
    std::size_t k = 0;
    for (std::size_t u = h + 1; u < requests.size(); u += workers, ++k) {
      QSMESH_CHECK(k < theirs.size(), "rank " << helpers[h] << " answered " << theirs.size()
                                              << " move layouts, fewer than asked");
      results[u] = std::move(theirs[k]);
    }
  }
  return results;
}

std::vector<char> RankLayoutHelpers::serve(const std::vector<char>& share) {
  std::vector<qstruct::MoveLayoutRequest> requests;
  std::size_t pos = 0;
  read_record(share, pos, requests);
  std::vector<qstruct::MoveLayoutResult> results;
  results.reserve(requests.size());
  for (const qstruct::MoveLayoutRequest& r : requests) {
    if (r.face != sides_face_) {
      try {
        const auto surface = model_.face_geometry(r.face);
        sides_ = qstruct::face_sides(model_, r.face, *surface, curves_, options_);
        sides_face_ = r.face;
      } catch (const Error& e) {
        // The owner got these sides from the same call: it cannot fail here and not there.
        qstruct::MoveLayoutResult failed;
        failed.error = e.message();
        results.push_back(std::move(failed));
        sides_face_ = kNoIndex;
        continue;
      }
    }
    results.push_back(qstruct::lay_out_move(model_, sides_, patterns_, options_.smooth, r));
    ++served_;
  }
  std::vector<char> out;
  write_record(out, results);
  return out;
}

void RankLayoutHelpers::serve_until_all_done() {
  ranks_.serve_until_all_done([&](const std::vector<char>& share) { return serve(share); });
}

}  // namespace qsmesh::parallel
