// Limits on what one run may ask for: a lower estimate of the quads and the memory a request
// needs, computed from the model's measures and the size options before any meshing, so that a
// mistyped size (--size-factor 1e-6) is refused in a second with its estimate instead of running
// until the machine runs out of memory. Pure functions (no MPI, no files) except machine_memory().
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cli.hpp"

namespace qsmesh::cli {

/// What the estimate needs to know of a model.
struct ModelMeasures {
  std::vector<double> face_area;     ///< per CAD face, model units squared
  std::vector<double> curve_length;  ///< per CAD curve, model units
  /// Per face, the curves of its boundary (a curve used twice, a seam, listed twice).
  std::vector<std::vector<int>> face_curves;
};

/// The size requests of a run (as the command line gives them, ids already checked).
struct SizeRequest {
  double size_max = 0;      ///< the size cap (--size or --size-factor times the diagonal), > 0
  double target_quads = 0;  ///< --quads (0: from the size cap)
  std::vector<std::pair<int, double>> face_quads;   ///< --face-quads
  std::vector<std::pair<int, double>> face_sizes;   ///< --face-size
  std::vector<std::pair<int, int>> curve_edges;     ///< --curve-edges
  std::vector<std::pair<int, double>> curve_sizes;  ///< --curve-size
};

/// The size requests of parsed arguments, with the size cap `size_max` the run computed.
[[nodiscard]] SizeRequest size_request(const Arguments& args, double size_max);

/// The size option a run was given, for messages: "--size 0.5", "--size-factor 0.01" or "the
/// default size factor 0.02".
[[nodiscard]] std::string size_option_text(const Arguments& args);

/// A lower estimate of a request's cost. The size map only refines below the size cap (curvature,
/// small features), so the quads of the size cap and the prescriptions bound the mesh from below.
struct RequestEstimate {
  double quads = 0;  ///< may be +inf (a size whose square underflows)
  /// The request that dominates the estimate, for the message: "the size cap", "--quads",
  /// "--face-quads F:N", "--face-size F:H", "--curve-edges C:N" or "--curve-size C:H".
  std::string dominant;
};

/// Per face, the largest of: its share of the size cap's quads (area / size_max^2, or of
/// --quads by area), its --face-quads or area / h^2 for its --face-size, and a quarter of the
/// edges its curves are prescribed (--curve-edges, or length / h for --curve-size; every quad has
/// at most four edges on the boundary). Summed over the faces. Never throws; inputs out of range
/// (non-finite, negative) count as no request.
[[nodiscard]] RequestEstimate estimate_request(const ModelMeasures& model,
                                               const SizeRequest& request);

/// Lower estimate of the peak resident memory (bytes) of rank 0, which assembles and writes the
/// whole mesh, and of any other rank, for a mesh of `quads` quads over `ranks` ranks. From the
/// measured peaks (docs/benchmarks.md, "Request limits"): about 40 MB of libraries per process
/// and at least 350 bytes per quad.
[[nodiscard]] std::pair<double, double> estimate_rank_memory(double quads, int ranks);

/// Memory this machine offers, in bytes: `node` for all processes on this machine (physical
/// memory, or the control group's limit when lower) and `process` for one process (its address
/// space limit, RLIMIT_AS); 0 where unknown or unlimited.
struct MachineMemory {
  double node = 0, process = 0;
};
[[nodiscard]] MachineMemory machine_memory();

/// The refusal of a request, or nothing when it fits: the estimate against max_quads (0: no
/// bound), and rank 0's memory plus that of the other ranks on this machine against `machine`.
/// `what_size` names the size option given ("--size 1e-06", "--size-factor 1e-09", ...).
[[nodiscard]] std::optional<std::string> refuse_request(const RequestEstimate& estimate,
                                                        double max_quads, int ranks,
                                                        int ranks_on_node,
                                                        const MachineMemory& machine,
                                                        const std::string& what_size);

}  // namespace qsmesh::cli
