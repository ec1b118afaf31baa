// Equal loop counts on annulus faces for the holomorphic grid (holomorphic.hpp,
// balance_annulus_counts).
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

#include "qsmesh/holomorphic/holomorphic.hpp"

namespace qsmesh::holomorphic {

std::vector<std::vector<cad::CurveUse>> annulus_chains(const cad::CadModel& model, LO f) {
  const cad::Face& face = model.faces()[static_cast<std::size_t>(f)];
  for (const auto& loop : face.loops)
    for (const auto& use : loop.uses)
      if (model.curves()[static_cast<std::size_t>(use.curve)].degenerate) return {};
  if (face.loops.size() == 2 && face.seams.empty()) return {face.loops[0].uses, face.loops[1].uses};
  if (face.loops.size() != 1 || face.seams.size() != 1) return {};
  // A cylinder's side: [end 1 ..., seam, end 2 ..., seam back]; the runs between the seam's uses.
  const auto& uses = face.loops[0].uses;
  const LO seam = face.seams[0];
  std::vector<std::size_t> at;
  for (std::size_t k = 0; k < uses.size(); ++k)
    if (uses[k].curve == seam) at.push_back(k);
  if (at.size() != 2) return {};
  std::vector<std::vector<cad::CurveUse>> chains(2);
  for (std::size_t r = 0; r < 2; ++r)
    for (std::size_t k = at[r] + 1; k % uses.size() != at[1 - r]; ++k)
      chains[r].push_back(uses[k % uses.size()]);
  if (chains[0].empty() || chains[1].empty()) return {};
  return chains;
}

namespace {

// Direction of a curve use at its end (at_end) or start, from the curve mesh's end segments.
Vec3 use_direction(const mesh::CurveMesh& m, bool reversed, bool at_end) {
  const std::size_t n = m.points.size();
  if (n < 2) return {0, 0, 0};
  const bool last = at_end != reversed;  // the segment at the curve's t1 end
  const Vec3 d = last ? m.points[n - 1] - m.points[n - 2] : m.points[1] - m.points[0];
  return reversed ? d * -1.0 : d;
}

// The largest turn (degrees) between consecutive uses of a chain, cyclically: at a seam's corner
// the chain's last use meets its first once the seam's copies are merged.
double max_turn(std::span<const mesh::CurveMesh> curves, const std::vector<cad::CurveUse>& chain) {
  double worst = 0;
  for (std::size_t k = 0; k < chain.size(); ++k) {
    const auto& a = chain[k];
    const auto& b = chain[(k + 1) % chain.size()];
    const Vec3 da = use_direction(curves[static_cast<std::size_t>(a.curve)], a.reversed, true);
    const Vec3 db = use_direction(curves[static_cast<std::size_t>(b.curve)], b.reversed, false);
    if (norm(da) == 0 || norm(db) == 0) continue;
    const double c = std::clamp(dot(normalized(da), normalized(db)), -1.0, 1.0);
    worst = std::max(worst, std::acos(c) * 180 / std::numbers::pi);
  }
  return worst;
}

}  // namespace

std::vector<int> balance_annulus_counts(const cad::CadModel& model,
                                        std::span<const mesh::CurveMesh> curves,
                                        std::span<const int> edges, std::span<const double> ideal,
                                        std::span<const LO> curve2chord, std::span<const LO> fixed,
                                        const AnnulusCountOptions& options,
                                        AnnulusCountReport* report) {
  std::vector<int> out(edges.begin(), edges.end());
  AnnulusCountReport local;
  AnnulusCountReport& R = report != nullptr ? *report : local;
  R = AnnulusCountReport{};
  const std::set<LO> user(fixed.begin(), fixed.end());
  // The variables: a chord's curves move together (the four-sided faces across it stay as
  // balanced as the quantization made them), a curve in no chord alone.
  std::map<LO, std::vector<LO>> chord_curves;
  for (std::size_t c = 0; c < curve2chord.size(); ++c)
    if (curve2chord[c] != kNoIndex) chord_curves[curve2chord[c]].push_back(static_cast<LO>(c));
  auto members = [&](LO c) {
    const auto i = static_cast<std::size_t>(c);
    if (i < curve2chord.size() && curve2chord[i] != kNoIndex) return chord_curves[curve2chord[i]];
    return std::vector<LO>{c};
  };
  std::vector<char> locked(out.size(), 0);
  for (LO f = 0; f < model.num_faces(); ++f) {
    const auto chains = annulus_chains(model, f);
    if (chains.empty()) continue;
    if (std::max(max_turn(curves, chains[0]), max_turn(curves, chains[1])) >
        options.max_corner_turn_deg)
      continue;
    ++R.annuli;
    std::array<std::map<LO, int>, 2> on;  // curve -> its uses in the chain
    std::array<long, 2> total{0, 0};
    for (std::size_t r = 0; r < 2; ++r)
      for (const auto& u : chains[r]) {
        ++on[r][u.curve];
        total[r] += out[static_cast<std::size_t>(u.curve)];
      }
    if (total[0] == total[1]) {
      ++R.equal_before;
      ++R.equal_after;
    } else if (double(std::abs(total[1] - total[0])) <=
               options.max_loop_difference * double(std::max(total[0], total[1]))) {
      const std::size_t lo = total[0] < total[1] ? 0 : 1;
      long need = std::abs(total[1] - total[0]);
      std::vector<int> trial = out;
      // One step of 2 on every member of one variable of loop r (up: +2, down: -2), each within
      // its room, the loop's total moving by at most what is still needed.
      auto step = [&](std::size_t r, int sign) {
        std::vector<LO> best;
        double best_ratio = 0;
        long best_delta = 0;
        std::set<LO> seen;
        for (const auto& [c0, unused] : on[r]) {
          const std::vector<LO> var = members(c0);
          if (!seen.insert(var.front()).second) continue;
          long delta = 0;
          double ratio = 0;
          bool ok = true;
          for (const LO c : var) {
            const auto i = static_cast<std::size_t>(c);
            if (locked[i] != 0 || user.count(c) != 0 || model.curves()[i].degenerate ||
                on[1 - r].count(c) != 0) {
              ok = false;
              break;
            }
            const auto it = on[r].find(c);
            delta += it == on[r].end() ? 0 : 2L * it->second;
            const double id = std::max(ideal[i], 1.0);
            const double room = std::max(options.max_change * id, 2.0);
            const int next = trial[i] + 2 * sign;
            const bool closed = model.curves()[i].corners[0] == model.curves()[i].corners[1];
            if ((std::abs(double(next) - id) > room &&
                 std::abs(double(next) - id) >= std::abs(double(trial[i]) - id)) ||
                next < (closed ? 4 : 2) - (trial[i] % 2)) {
              ok = false;
              break;
            }
            ratio += double(trial[i]) / id * sign / double(var.size());
          }
          if (!ok || delta == 0 || delta > need) continue;
          // The fewest curves first: each curve moved off the loop changes another face.
          if (best.empty() || var.size() < best.size() ||
              (var.size() == best.size() && ratio < best_ratio)) {
            best = var;
            best_ratio = ratio;
            best_delta = delta;
          }
        }
        if (best.empty()) return false;
        for (const LO c : best) trial[static_cast<std::size_t>(c)] += 2 * sign;
        need -= best_delta;
        return true;
      };
      while (need > 0 && step(lo, +1)) {
      }
      while (need > 0 && step(1 - lo, -1)) {
      }
      if (need == 0) {
        for (std::size_t i = 0; i < out.size(); ++i)
          if (trial[i] != out[i]) ++R.curves_changed;
        out = std::move(trial);
        ++R.equal_after;
      }
    }
    for (std::size_t r = 0; r < 2; ++r)
      for (const auto& [c, uses] : on[r])
        for (const LO m : members(c)) locked[static_cast<std::size_t>(m)] = 1;
  }
  return out;
}

}  // namespace qsmesh::holomorphic
