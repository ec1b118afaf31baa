// Command-line parsing of the qsmesh driver. Parsing is pure (no MPI, no files touched), so every
// rank parses the same arguments to the same result and tests can call it directly.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "qsmesh/cad/model.hpp"
#include "qsmesh/layout/coarse_layout.hpp"

namespace qsmesh::cli {

enum class Command { Help, Version, Info, Mesh, CrossField, SizeMap, Example };

struct Arguments {
  Command command = Command::Help;
  std::string help_topic;             ///< command whose --help was asked ("" = general)
  std::string model;                  ///< input CAD file (info, mesh)
  std::string output;                 ///< -o
  std::optional<double> size;         ///< --size (model units)
  std::optional<double> size_factor;  ///< --size-factor (fraction of the bounding-box diagonal)
  /// Last stage to run. `unstructured` exists but still fails on some faces of the shared models
  /// (reported per face), so the default stays the furthest stage that is complete.
  std::string until = "quasi-structured";
  /// --method: the per-face method of the quad stages (default, holomorphic, auto, separatrix; see
  /// parallel::PipelineOptions::face_method).
  std::string method = "default";
  int threads = 0;  ///< 0: automatic
  /// --face-time-budget S: wall-clock seconds the topological improvement (cavity remeshing,
  /// paper 000 Sec. 6.2) may spend on one face (0: no bound; the result is then reproducible).
  double face_time_budget = 0;
  std::string stats;  ///< --stats FILE.json
  /// --block-structured: write the CGNS file as structured blocks of the quad layout
  /// (layout::extract_quad_layout, io::write_cgns_blocks) instead of one unstructured zone.
  /// Implied by a PLOT3D output (-o FILE.xyz / .p3d: io::write_plot3d).
  bool block_structured = false;
  /// --block-patches (with --order N): each block of the layout (coarse unless --layout dense)
  /// written as one Lagrange quad of order N on the CAD (highorder::make_block_patches), in any
  /// mesh format but PLOT3D.
  bool block_patches = false;
  /// --plot3d-stream: PLOT3D without Fortran record lengths (C stream; WriteOptions).
  bool plot3d_stream = false;
  /// --plot3d-single: PLOT3D coordinates in single precision.
  bool plot3d_single = false;
  /// Paper 003 (fieldmesh): --cross-field FIELD, the user's cross field of some faces (read by
  /// fieldmesh::read_cross_field_file), and --method separatrix, the separatrix partition on the
  /// mesher's own cross field for the other faces.
  std::string cross_field;
  bool separatrix_method = false;
  /// --smooth-groups (with --method holomorphic|auto): faces joined across smooth curves meshed
  /// as one surface (PipelineOptions::smooth_groups).
  bool smooth_groups = false;
  /// --layout coarse|dense (with --block-structured): the coarse conforming layout of paper 002
  /// Sec. III-IV (layout::build_coarse_layout, a new mesh) or the dense layout of the mesh as it
  /// is (the default: see --help for why).
  bool coarse_layout = false;
  /// --loop-balance B (with --layout coarse): layout::CoarseOptions::loop_balance, in [0, 1].
  double loop_balance = 0;
  /// --loop-widths mean|fit (with --layout coarse): layout::CoarseOptions::fit_loop_widths.
  bool fit_loop_widths = false;
  /// --repairs grow|local|restore (with --layout coarse): layout::CoarseOptions::repairs.
  layout::Repairs repairs = layout::Repairs::Grow;
  /// --fine-placement former|laplacian|spacing|both|patch (with --layout coarse): which of the
  /// fine mesh's placement changes are on (layout::CoarseOptions::laplacian_uv,
  /// input_spacing_on_curves and patch_placement); default both, patch is both with
  /// patch_placement. For measurements.
  bool fine_laplacian = true, fine_input_spacing = true, fine_patch = false;
  /// --cone-angle DEG (with --layout coarse): layout::CoarseOptions::alpha in degrees, in
  /// (0, 90); 0: the option's default (the paper's 45 degrees).
  double cone_angle_deg = 0;
  /// --curves-are-walls (with --layout coarse): every CAD curve a block side, smooth ones too
  /// (layout::CoarseOptions::cross_smooth_curves = false).
  bool sharp_and_smooth_walls = false;
  /// --traces-cross-curves (with --layout coarse): CoarseOptions::traces_across_smooth_curves.
  bool traces_cross_curves = false;
  /// --order N, 2..5: Lagrange quads ((N + 1)^2 nodes) and bars (N + 1 nodes) on the CAD
  /// (highorder::make_high_order); 1: linear.
  int order = 1;
  bool json = false;  ///< info --json
  /// info --partition P,...: the METIS partition of the faces that `mpirun -np P qsmesh mesh`
  /// with the same --size/--size-factor uses, for each P (scripts/simulate_scaling.py).
  std::vector<int> partition;
  bool check = false;                  ///< crossfield --check
  std::string sizemap = "crossfield";  ///< --sizemap features|crossfield
  /// --sizing clamped|paper (gmsh: an alias of clamped, recorded as "clamped"). "clamped", the
  /// default, stands for --curvature-edges 0 --size-min-ratio kClampedSizeMinRatio where those (or
  /// --size-min) are not given (applied by parse, for sizemap and mesh); "paper" keeps rule (i) of
  /// paper 000 Sec. 4.1 (a curve sizes the mesh by its length, below every floor) and the
  /// curvature sizes of sizemap::SizeMapOptions.
  std::string sizing = "clamped";
  double quads = 0;  ///< --quads N: target quad count of the model (0: from the size)
  /// --curvature-edges N: edges per full turn on curved curves and faces (0: no curvature sizes;
  /// unset: sizemap::SizeMapOptions' default).
  std::optional<double> curvature_edges;
  /// --face-curvature: the curvature sizes also from the faces' principal curvatures
  /// (sizemap::SizeMapOptions::face_curvature).
  bool face_curvature = false;
  /// --odd-slivers: curves nearer 1 edge than 2 take 1 (quantize::QuantizeOptions::odd_slivers).
  bool odd_slivers = false;
  /// --one-edge-slivers: curves shorter than a tenth of the floor take 1 edge, their corners graded
  /// (sizemap::SizeMapOptions::one_edge_slivers).
  bool one_edge_slivers = false;
  /// --feature-ratio R: how far small features refine (sizemap::SizeMapOptions::feature_ratio;
  /// unset: its default).
  std::optional<double> feature_ratio;
  /// --thin-aspect K: largest length-to-width ratio of the edges along thin faces
  /// (sizemap::SizeMapOptions::thin_aspect; unset: kDefaultThinAspect, 0: off).
  std::optional<double> thin_aspect;
  /// --size-min H: floor of the automatic sizes, model units (sizemap::SizeMapOptions::size_min;
  /// unset: the size cap / 100, which curves shorter than it still go below).
  std::optional<double> size_min;
  /// --size-min-ratio R: the same floor as R times the size cap (0 < R <= 1; not with --size-min).
  std::optional<double> size_min_ratio;
  std::vector<std::pair<int, int>> curve_edges;      ///< --curve-edges C:N,...
  std::vector<std::pair<int, double>> face_quads;    ///< --face-quads F:N,...
  std::vector<std::pair<int, double>> corner_sizes;  ///< --corner-size K:H,...
  std::vector<std::pair<int, double>> curve_sizes;   ///< --curve-size C:H,...
  std::vector<std::pair<int, double>> face_sizes;    ///< --face-size F:H,...
  /// --max-quads N: refuse, before any work, a run whose estimated quad count is above N
  /// (0: no bound; the machine's memory still bounds it). See kDefaultMaxQuads.
  double max_quads = -1;  ///< -1: kDefaultMaxQuads
  /// --task-quads N: faces of more quads than N are improved in pieces, each a task
  /// (parallel::PipelineOptions::task_quads; 0: never); -1: parallel::kDefaultTaskQuads.
  std::int64_t task_quads = -1;
  /// --pass-after-cuts on|off (parallel::PipelineOptions::whole_pass_after_cuts); unset: on.
  std::optional<bool> pass_after_cuts;
  /// --second-pass-quads N: the largest face given a second improvement pass
  /// (parallel::PipelineOptions::second_pass_max_quads; 0: no second pass); -1: the default.
  std::int64_t second_pass_quads = -1;
  /// --second-pass-task N: a face with at least N interior irregular vertices before its
  /// improvement runs its second pass as a task of its own
  /// (parallel::PipelineOptions::second_pass_task_irregular; 0: never); -1: the default.
  std::int64_t second_pass_task = -1;
  /// --fill-comparison irregular|mean: which kept pattern fills wait for their face's
  /// unstructured mesh (qstruct::PatternFaceOptions::compare_irregular); empty: the default,
  /// irregular, or mean with --layout coarse.
  std::string fill_comparison;
  /// --field-divisions N: the background (where the fields are computed) at the geometry's
  /// resolution, each face's edges at most its bounding-box diagonal / N (and at most the target
  /// size's resolution); 0: the background follows the target size. See kDefaultFieldDivisions.
  std::optional<double> field_divisions;
  /// --distributed-threshold (linalg::SolverOptions::distributed_threshold); unset: its default.
  std::optional<LO> distributed_threshold;
  /// --field-change max|rms (crossfield::CrossFieldOptions::level_change); empty: its default.
  std::string field_change;
  /// --field-iterations N (crossfield::CrossFieldOptions::max_iterations_per_level); unset: its
  /// default.
  std::optional<int> field_iterations;
  /// --field-stall K (crossfield::CrossFieldOptions::stall_window); unset: its default.
  std::optional<int> field_stall;
  /// the R of --field-stall K:R (crossfield::CrossFieldOptions::stall_ratio); unset: its default.
  std::optional<double> field_stall_ratio;
  /// --field-stall-revolution K (crossfield::CrossFieldOptions::revolution_stall_window); unset:
  /// its default.
  std::optional<int> field_stall_revolution;
  /// --field-settled K (crossfield::CrossFieldOptions::settled_level_iterations); unset: its
  /// default.
  std::optional<int> field_settled;
  /// --field-regular on|off (crossfield::CrossFieldOptions::settled_regular_ends); unset:
  /// its default.
  std::optional<bool> field_regular;
  /// --field-shortcuts: "all" (default), "uniform" or "none" (crossfield::CrossFieldOptions::
  /// exact_uniform and exact_revolution); empty: unset.
  std::string field_shortcuts;
  bool sew = false;
  bool quiet = false;
  bool verbose = false;
  std::string example_name;  ///< example NAME
};

/// Default --field-divisions (background::SizeOptions::field_divisions): docs/benchmarks.md,
/// "Fields at the geometry's resolution", has the measurements behind it.
inline constexpr double kDefaultFieldDivisions = 96;

/// Default --size-factor when neither --size nor --size-factor is given: a medium mesh.
inline constexpr double kDefaultSizeFactor = 0.02;
/// The floor of --sizing clamped (the default; Gmsh's implementation sizes alike), as a fraction
/// of the size cap: the value at which all six shared models meet the Gmsh reference runs'
/// criteria (docs/benchmarks.md, fifteenth session; 0.10 and 0.25 miss wing_fuselage's).
inline constexpr double kClampedSizeMinRatio = 0.17;
/// Default --thin-aspect (sizemap::SizeMapOptions::thin_aspect, off in the library): quads along
/// a strip 2 across keep SICN about 1 / K (docs/benchmarks.md, issue 29, has the measurements).
inline constexpr double kDefaultThinAspect = 4;

/// Default --max-quads: far above any mesh the project has been run on (1.2M vertices) and far
/// below what a mistyped size asks for (--size-factor 1e-6: about 1e12 quads), so that a runaway
/// request is refused with its estimate instead of exhausting the machine.
inline constexpr double kDefaultMaxQuads = 2e8;

/// The CAD format a file name asks `example` for by its extension: .step/.stp STEP, .brep/.brp BREP
/// (any case); nothing for any other name.
[[nodiscard]] std::optional<cad::ExampleFormat> example_format(const std::string& path);

/// Parses argv[1..]. Throws InputError (one line naming the option and the reason) on bad input.
[[nodiscard]] Arguments parse(const std::vector<std::string>& args);

/// Help text of a command ("" for the general help).
[[nodiscard]] std::string help(const std::string& topic);

}  // namespace qsmesh::cli
