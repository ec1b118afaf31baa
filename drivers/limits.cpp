#include "limits.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

namespace qsmesh::cli {

namespace {

bool usable(double v) { return std::isfinite(v) && v > 0; }

// a / (h * h), dividing twice so that h * h cannot underflow to 0: +inf beyond doubles.
double per_square(double a, double h) { return usable(a) && usable(h) ? a / h / h : 0; }

// "OPTION ID:VALUE", the request as the user typed it.
template <class T>
std::string option_text(const char* option, int id, T value) {
  std::ostringstream os;
  os << option << " " << id << ":" << value;
  return os.str();
}

bool valid_id(int id, std::size_t count) { return id >= 0 && static_cast<std::size_t>(id) < count; }

std::string number(double v) {
  std::ostringstream os;
  os << std::setprecision(3) << v;
  return os.str();
}

std::string gigabytes(double bytes) {
  std::ostringstream os;
  os << std::setprecision(3) << bytes / 1e9 << " GB";
  return os.str();
}

}  // namespace

SizeRequest size_request(const Arguments& args, double size_max) {
  SizeRequest r;
  r.size_max = size_max;
  r.target_quads = args.quads;
  r.face_quads = args.face_quads;
  r.face_sizes = args.face_sizes;
  r.curve_edges = args.curve_edges;
  r.curve_sizes = args.curve_sizes;
  return r;
}

std::string size_option_text(const Arguments& args) {
  std::ostringstream what;
  if (args.size)
    what << "--size " << *args.size;
  else if (args.size_factor)
    what << "--size-factor " << *args.size_factor;
  else
    what << "the default size factor " << kDefaultSizeFactor;
  return what.str();
}

RequestEstimate estimate_request(const ModelMeasures& model, const SizeRequest& request) {
  const std::size_t nf = model.face_area.size(), nc = model.curve_length.size();
  double total_area = 0;
  for (double a : model.face_area)
    if (usable(a)) total_area += a;

  // Per face: the best lower bound and which request gave it.
  std::vector<double> quads(nf, 0.0);
  std::vector<std::string> why(nf, "the size cap");
  auto raise = [&](std::size_t f, double q, const std::string& reason) {
    if (q > quads[f]) {
      quads[f] = q;
      why[f] = reason;
    }
  };
  const bool by_target = usable(request.target_quads);
  std::ostringstream quads_os;
  quads_os << "--quads " << request.target_quads;
  const std::string quads_text = quads_os.str();
  for (std::size_t f = 0; f < nf; ++f) {
    const double a = usable(model.face_area[f]) ? model.face_area[f] : 0;
    if (by_target)
      raise(f, total_area > 0 ? a / total_area * request.target_quads : request.target_quads / nf,
            quads_text);
    else
      raise(f, per_square(a, request.size_max), "the size cap");
  }
  for (const auto& [f, q] : request.face_quads) {
    if (!valid_id(f, nf) || !usable(q)) continue;
    // A prescription replaces the face's share, so it may lower the bound too.
    quads[static_cast<std::size_t>(f)] = q;
    why[static_cast<std::size_t>(f)] = option_text("--face-quads", f, q);
  }
  for (const auto& [f, h] : request.face_sizes) {
    if (!valid_id(f, nf) || !usable(h)) continue;
    raise(static_cast<std::size_t>(f), per_square(model.face_area[static_cast<std::size_t>(f)], h),
          option_text("--face-size", f, h));
  }
  // Edges of the curves with a prescription, and the option that set each.
  std::vector<double> edges(nc, 0.0);
  std::vector<std::string> edge_why(nc);
  for (const auto& [c, h] : request.curve_sizes) {
    if (!valid_id(c, nc) || !usable(h)) continue;
    const double len = model.curve_length[static_cast<std::size_t>(c)];
    if (!usable(len)) continue;
    edges[static_cast<std::size_t>(c)] = len / h;
    edge_why[static_cast<std::size_t>(c)] = option_text("--curve-size", c, h);
  }
  for (const auto& [c, n] : request.curve_edges) {
    if (!valid_id(c, nc) || n <= 0) continue;
    edges[static_cast<std::size_t>(c)] = n;
    edge_why[static_cast<std::size_t>(c)] = option_text("--curve-edges", c, n);
  }
  for (std::size_t f = 0; f < nf && f < model.face_curves.size(); ++f) {
    double sum = 0, largest = 0;
    std::string reason;
    for (int c : model.face_curves[f]) {
      if (!valid_id(c, nc)) continue;
      const double e = edges[static_cast<std::size_t>(c)];
      sum += e;
      if (e > largest) {
        largest = e;
        reason = edge_why[static_cast<std::size_t>(c)];
      }
    }
    if (sum > 0) raise(f, sum / 4, reason);
  }

  RequestEstimate out;
  std::map<std::string, double> by_reason;  // quads each request accounts for
  for (std::size_t f = 0; f < nf; ++f) {
    out.quads += quads[f];
    by_reason[why[f]] += quads[f];
  }
  out.dominant = "the size cap";
  double most = -1;
  for (const auto& [reason, q] : by_reason)
    if (q > most) {
      most = q;
      out.dominant = reason;
    }
  return out;
}

std::pair<double, double> estimate_rank_memory(double quads, int ranks) {
  constexpr double kLibraries = 40e6, kBytesPerQuad = 350;
  const double q = std::max(0.0, quads);
  const double p = std::max(1, ranks);
  return {kLibraries + kBytesPerQuad * q, kLibraries + kBytesPerQuad * q / p};
}

MachineMemory machine_memory() {
  MachineMemory m;
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0) m.node = static_cast<double>(pages) * static_cast<double>(page);
  // A container's limit (cgroup v2, then v1) is what the kernel enforces, not the RAM it sees.
  for (const char* file :
       {"/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory/memory.limit_in_bytes"}) {
    std::ifstream in(file);
    double limit = 0;
    if (in >> limit && limit > 0 && (m.node == 0 || limit < m.node)) m.node = limit;
  }
  rlimit as{};
  if (::getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY)
    m.process = static_cast<double>(as.rlim_cur);
  return m;
}

std::optional<std::string> refuse_request(const RequestEstimate& estimate, double max_quads,
                                          int ranks, int ranks_on_node,
                                          const MachineMemory& machine,
                                          const std::string& what_size) {
  const std::string request = estimate.dominant == "the size cap" ? what_size : estimate.dominant;
  const std::string asks =
      request + (std::isfinite(estimate.quads)
                     ? " asks for at least " + number(estimate.quads) + " quads"
                     : " asks for more quads than a double can count");
  const std::string fix =
      estimate.dominant == "the size cap" ? "give a larger size" : "ask for fewer";
  if (max_quads > 0 && !(estimate.quads <= max_quads))
    return asks + ", more than --max-quads " + number(max_quads) + " allows; " + fix +
           ", or raise --max-quads (0: no bound)";
  const auto [root, other] = estimate_rank_memory(estimate.quads, ranks);
  const int local = std::clamp(ranks_on_node, 1, std::max(1, ranks));
  const double node_need = root + (local - 1) * other;
  if (machine.node > 0 && !(node_need <= machine.node))
    return asks + ", which need at least " + gigabytes(node_need) +
           " of memory on this machine (it has " + gigabytes(machine.node) + "); " + fix +
           ", or run on more machines";
  if (machine.process > 0 && !(root <= machine.process))
    return asks + ", which need at least " + gigabytes(root) +
           " of memory in one process (its limit, ulimit -v, is " + gigabytes(machine.process) +
           "); " + fix + ", or raise the limit";
  return std::nullopt;
}

}  // namespace qsmesh::cli
