// qsmesh_gen_disk_quads: writes the table of disk quadrangulations (paper 000 Sec. 6.3.1) that the
// remesh module embeds at build time (data/disk_quadrangulations.txt). Not needed at run time.
//
// Usage: qsmesh_gen_disk_quads [OUT.txt] [--max-boundary B] [--max-interior N]
//   (defaults: B = 12, N = 4; writes to stdout without OUT). Prints the count per (b, n) on stderr.
//
// What is enumerated: every quad mesh of a closed disk (simple boundary cycle, simple edge graph)
// with b <= B boundary vertices and n <= N interior vertices, interior quad valences in 3..5 and
// boundary quad valences in 1..3 (the ranges of Sec. 6.3.1), one representative per class of
// isomorphic meshes (rotations and reflections of the disk identified: the matcher of the remesh
// module tries all of them).
//
// How: growth from a single quad by gluing a new quad onto 1, 2 or 3 consecutive boundary edges
// (the "three edge flips that add a quad" of the paper), breadth first by number of quads, each
// level deduplicated by the canonical labelling (nauty) of the face-poset graph of the mesh: one
// node per vertex, edge and quad, vertex-edge and edge-quad incidences, coloured (boundary vertex,
// interior vertex, edge, quad). A regular 2-cell complex is determined by its face poset, and our
// meshes are regular (four distinct vertices per quad, no multiple edge), so two meshes get the
// same canonical graph exactly when they are isomorphic as disks (reflections included).
//
// Why it is exhaustive. (1) Every disk quad mesh M with F >= 2 quads has a quad whose intersection
// with the boundary is one path of 1, 2 or 3 edges, so that removing it leaves a disk: polygonal
// 2-balls are shellable (the two-ears argument: a boundary quad meeting the boundary in several
// pieces cuts the disk into smaller disks, and by induction each of them has an ear away from the
// cut). Reversing the removals grows M from one quad by the three gluings. (2) Every intermediate
// disk M_i of such a sequence passes the pruning below: an interior vertex of M_i has its whole
// star in M_i, so its valence is its final one (3..5); a boundary vertex of M_i has at most its
// final valence (<= 5: it may still become interior); the number of interior vertices never
// decreases, so n_i <= N; and each gluing changes (b, n) by (+2, 0), (0, +1) or (-2, +2), so
// reaching b <= B from b_i needs n_final >= n_i + (b_i - B), hence n_i + max(0, b_i - B) <= N. (3)
// Deduplication keeps one mesh per class, and isomorphic meshes have isomorphic sets of extensions.
// So every mesh of the table is reached. The tests of the remesh module recount the n = 0 classes
// independently (labelled quadrangulations of a polygon, by a recursion) and check that no two
// entries are isomorphic with a second canonical form (planar-map traversal) that does not use
// nauty.
#include <nauty/nauty.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <unordered_set>
#include <utility>
#include <vector>

namespace {

constexpr int kMinInteriorValence = 3;
constexpr int kMaxInteriorValence = 5;
constexpr int kMinBoundaryValence = 1;
constexpr int kMaxBoundaryValence = 3;

struct Disk {
  int num_vertices = 0;
  std::vector<std::array<int, 4>> quads;  // counter-clockwise
  std::vector<int> boundary;              // counter-clockwise cycle (the mesh on its left)
  std::vector<int> valence;               // quads at each vertex
  std::vector<char> interior;             // 1 for interior vertices

  [[nodiscard]] int num_interior() const {
    return static_cast<int>(std::count(interior.begin(), interior.end(), char(1)));
  }
};

Disk single_quad() {
  Disk d;
  d.num_vertices = 4;
  d.quads = {{0, 1, 2, 3}};
  d.boundary = {0, 1, 2, 3};
  d.valence = {1, 1, 1, 1};
  d.interior = {0, 0, 0, 0};
  return d;
}

bool has_edge(const Disk& d, int a, int b) {
  for (const auto& q : d.quads)
    for (int i = 0; i < 4; ++i) {
      const int x = q[i], y = q[(i + 1) % 4];
      if ((x == a && y == b) || (x == b && y == a)) return true;
    }
  return false;
}

// Glues a quad onto the k consecutive boundary edges starting at boundary position `pos`.
// Returns false when the result would not be a disk with a simple edge graph.
bool glue(const Disk& d, int pos, int k, Disk& out) {
  const int b = static_cast<int>(d.boundary.size());
  if (k == 3 && b < 6) return false;  // b = 4 would close the disk into a sphere
  std::array<int, 4> path{};
  for (int i = 0; i <= k; ++i) path[i] = d.boundary[(pos + i) % b];
  // The new edge p0-p3 must not double an existing (interior) edge.
  if (k == 3 && has_edge(d, path[0], path[3])) return false;
  out = d;
  std::array<int, 4> q{};
  int c = 0;
  for (int i = k; i >= 0; --i) q[c++] = path[i];  // shared edges, reversed
  std::vector<int> fresh;
  for (int i = 0; i < 3 - k; ++i) {
    fresh.push_back(out.num_vertices++);
    out.valence.push_back(0);
    out.interior.push_back(0);
  }
  // The new quad continues from p0 through the fresh vertices back to pk.
  for (int f : fresh) q[c++] = f;
  out.quads.push_back(q);
  for (int v : q) ++out.valence[v];
  for (int i = 1; i < k; ++i) out.interior[path[i]] = 1;
  // New boundary: ... p0, fresh..., pk ...
  std::vector<int> nb;
  nb.reserve(b + 2);
  for (int i = 0; i < b; ++i) {
    const int rel = ((i - pos) % b + b) % b;
    if (rel == 0) {
      nb.push_back(path[0]);
      for (int f : fresh) nb.push_back(f);
    } else if (rel >= k) {
      nb.push_back(d.boundary[i]);
    }
  }
  out.boundary = std::move(nb);
  return true;
}

bool passes_pruning(const Disk& d, int max_b, int max_n) {
  const int b = static_cast<int>(d.boundary.size());
  const int n = d.num_interior();
  if (n > max_n || n + std::max(0, b - max_b) > max_n) return false;
  for (int v = 0; v < d.num_vertices; ++v) {
    if (d.interior[v]) {
      if (d.valence[v] < kMinInteriorValence || d.valence[v] > kMaxInteriorValence) return false;
    } else if (d.valence[v] > kMaxInteriorValence) {
      return false;
    }
  }
  return true;
}

bool is_final(const Disk& d, int max_b, int max_n) {
  if (static_cast<int>(d.boundary.size()) > max_b || d.num_interior() > max_n) return false;
  for (int v : d.boundary)
    if (d.valence[v] < kMinBoundaryValence || d.valence[v] > kMaxBoundaryValence) return false;
  return true;
}

// Canonical form (nauty) of the coloured face-poset graph, prefixed by (b, n) for readability.
std::string canonical_key(const Disk& d) {
  std::map<std::pair<int, int>, int> edge_id;
  for (const auto& q : d.quads)
    for (int i = 0; i < 4; ++i) {
      const int a = std::min(q[i], q[(i + 1) % 4]), c = std::max(q[i], q[(i + 1) % 4]);
      edge_id.emplace(std::make_pair(a, c), 0);
    }
  int e = 0;
  for (auto& [key, id] : edge_id) id = e++;
  const int nv = d.num_vertices, ne = e, nq = static_cast<int>(d.quads.size());
  const int nn = nv + ne + nq;
  const int m = SETWORDSNEEDED(nn);
  nauty_check(WORDSIZE, m, nn, NAUTYVERSIONID);
  std::vector<graph> g(static_cast<size_t>(m) * nn, 0), canon(static_cast<size_t>(m) * nn, 0);
  auto link = [&](int a, int c) { ADDONEEDGE(g.data(), a, c, m); };
  for (const auto& [key, id] : edge_id) {
    link(key.first, nv + id);
    link(key.second, nv + id);
  }
  for (int f = 0; f < nq; ++f)
    for (int i = 0; i < 4; ++i) {
      const int a = std::min(d.quads[f][i], d.quads[f][(i + 1) % 4]);
      const int c = std::max(d.quads[f][i], d.quads[f][(i + 1) % 4]);
      link(nv + edge_id.at({a, c}), nv + ne + f);
    }
  // Colour classes: boundary vertices | interior vertices | edges | quads.
  std::vector<int> lab, ptn, orbits(nn);
  auto cell = [&](const std::vector<int>& nodes) {
    if (nodes.empty()) return;
    for (size_t i = 0; i < nodes.size(); ++i) {
      lab.push_back(nodes[i]);
      ptn.push_back(i + 1 < nodes.size() ? 1 : 0);
    }
  };
  std::vector<int> bnd, inn, edges, quads;
  for (int v = 0; v < nv; ++v) (d.interior[v] ? inn : bnd).push_back(v);
  for (int i = 0; i < ne; ++i) edges.push_back(nv + i);
  for (int f = 0; f < nq; ++f) quads.push_back(nv + ne + f);
  cell(bnd);
  cell(inn);
  cell(edges);
  cell(quads);
  DEFAULTOPTIONS_GRAPH(options);
  options.getcanon = TRUE;
  options.defaultptn = FALSE;
  statsblk stats;
  densenauty(g.data(), lab.data(), ptn.data(), orbits.data(), &options, &stats, m, nn,
             canon.data());
  std::string key;
  key.push_back(static_cast<char>(d.boundary.size()));
  key.push_back(static_cast<char>(d.num_interior()));
  key.append(reinterpret_cast<const char*>(canon.data()), canon.size() * sizeof(graph));
  return key;
}

// The representative as written: boundary vertices 0..b-1 in boundary order, interior after.
std::string format(const Disk& d) {
  std::vector<int> label(d.num_vertices, -1);
  int next = 0;
  for (int v : d.boundary) label[v] = next++;
  for (int v = 0; v < d.num_vertices; ++v)
    if (label[v] < 0) label[v] = next++;
  std::ostringstream s;
  s << d.boundary.size() << ' ' << d.num_interior();
  for (const auto& q : d.quads)
    for (int v : q) s << ' ' << label[v];
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  int max_b = 12, max_n = 4;
  std::string out_path;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--max-boundary" && i + 1 < argc) {
      max_b = std::atoi(argv[++i]);
    } else if (a == "--max-interior" && i + 1 < argc) {
      max_n = std::atoi(argv[++i]);
    } else if (!a.empty() && a[0] != '-') {
      out_path = a;
    } else {
      std::cerr << "usage: qsmesh_gen_disk_quads [OUT.txt] [--max-boundary B] [--max-interior N]\n";
      return 2;
    }
  }
  if (max_b < 4 || max_b > 40 || max_n < 0 || max_n > 8) {
    std::cerr << "qsmesh_gen_disk_quads: bounds out of range\n";
    return 2;
  }

  std::vector<Disk> level{single_quad()};
  std::vector<Disk> found;
  std::map<std::pair<int, int>, int> counts;
  std::size_t explored = 0;
  while (!level.empty()) {
    explored += level.size();
    for (const Disk& d : level)
      if (is_final(d, max_b, max_n)) {
        found.push_back(d);
        ++counts[{static_cast<int>(d.boundary.size()), d.num_interior()}];
      }
    std::unordered_set<std::string> seen;
    std::vector<Disk> next;
    for (const Disk& d : level) {
      const int b = static_cast<int>(d.boundary.size());
      for (int pos = 0; pos < b; ++pos)
        for (int k = 1; k <= 3; ++k) {
          Disk g;
          if (!glue(d, pos, k, g) || !passes_pruning(g, max_b, max_n)) continue;
          if (seen.insert(canonical_key(g)).second) next.push_back(std::move(g));
        }
    }
    level = std::move(next);
  }

  std::sort(found.begin(), found.end(), [](const Disk& a, const Disk& c) {
    const auto ka = std::make_pair(a.boundary.size(), a.num_interior());
    const auto kc = std::make_pair(c.boundary.size(), c.num_interior());
    return ka < kc;
  });
  std::ostringstream text;
  text << "# Quadrangulations of the disk (paper 000 Sec. 6.3.1), written by "
          "qsmesh_gen_disk_quads.\n"
       << "# b <= " << max_b << " boundary vertices, n <= " << max_n
       << " interior vertices, interior valences " << kMinInteriorValence << ".."
       << kMaxInteriorValence << ", boundary valences " << kMinBoundaryValence << ".."
       << kMaxBoundaryValence << ", one per isomorphism class.\n"
       << "# Line: b n, then the b/2+n-1 quads (4 vertex ids each, counter-clockwise);\n"
       << "# vertices 0..b-1 are the boundary in counter-clockwise order, b..b+n-1 the interior.\n";
  for (const Disk& d : found) text << format(d) << '\n';

  if (out_path.empty()) {
    std::cout << text.str();
  } else {
    std::ofstream f(out_path);
    f << text.str();
    if (!f) {
      std::cerr << "qsmesh_gen_disk_quads: cannot write " << out_path << '\n';
      return 1;
    }
  }
  std::cerr << "explored " << explored << " disks; " << found.size() << " quadrangulations\n";
  for (const auto& [bn, c] : counts)
    std::cerr << "b=" << bn.first << " n=" << bn.second << ": " << c << '\n';
  return 0;
}
