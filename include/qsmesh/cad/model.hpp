// The CAD model: topology (corners, curves, faces with oriented loops) and geometry access.
// Immutable after load; every const member is safe to call from many threads at once.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "qsmesh/cad/geometry.hpp"
#include "qsmesh/core/adjacency.hpp"
#include "qsmesh/core/types.hpp"

namespace qsmesh::cad {

enum class SurfaceType : std::uint8_t {
  Plane,
  Cylinder,
  Cone,
  Sphere,
  Torus,
  Bezier,
  BSpline,
  Revolution,
  Extrusion,
  Offset,
  Other
};
enum class CurveType : std::uint8_t {
  Line,
  Circle,
  Ellipse,
  Hyperbola,
  Parabola,
  Bezier,
  BSpline,
  Offset,
  Other,
  Degenerate
};
[[nodiscard]] const char* to_string(SurfaceType t);
[[nodiscard]] const char* to_string(CurveType t);

/// A CAD vertex.
struct Corner {
  Vec3 point;
  double tolerance = 0;  ///< OpenCASCADE tolerance of the vertex (model units)
};

/// A CAD edge.
struct Curve {
  std::array<LO, 2> corners{kNoIndex,
                            kNoIndex};  ///< corner at t0, corner at t1 (equal when closed)
  /// Parameter range, t0 < t1: the edge's range, trimmed at an end where the curve runs past its
  /// corner (sloppy CAD: the curve passes within the corner's tolerance of it, goes on and comes
  /// back no closer) to the parameter of the curve's point nearest the corner. Without the trim,
  /// curve vertices placed on the overshoot lie beyond the corner, outside the faces
  /// (A319.brep: 0.66 past corner 100, a folded quad at size factor 0.002).
  double t0 = 0, t1 = 0;
  double length = 0;  ///< 3D arc length over [t0, t1] (0 when degenerate)
  /// Whether the range was trimmed at the start and at the end (see t0, t1).
  std::array<bool, 2> trimmed{false, false};
  bool degenerate = false;  ///< collapses to one point (pole of a sphere or cone)
  CurveType type = CurveType::Other;
};

/// One use of a curve in a face loop. reversed: traversed from t1 to t0.
struct CurveUse {
  LO curve = kNoIndex;
  bool reversed = false;
};

/// A closed chain of curve uses bounding a face. Consecutive uses share a corner.
struct Loop {
  std::vector<CurveUse> uses;
  bool outer = false;
};

/// A CAD face.
struct Face {
  std::vector<Loop> loops;  ///< loops[0] is the outer loop; the others bound holes
  std::vector<LO> seams;    ///< curves used twice in this face's loops (seams of periodic surfaces)
  SurfaceType type = SurfaceType::Other;
  bool reversed = false;  ///< face normal opposite to the surface's natural normal du x dv
  double area = 0;        ///< model units squared
  Box3 box;               ///< 3D bounding box
  Box2 uv_box;            ///< parameter-plane bounds of the trimmed face
  bool u_periodic = false, v_periodic = false;
  double u_period = 0, v_period = 0;
  /// True when every loop is a closed chain (consecutive uses share a corner, last meets first).
  /// False on broken input (e.g. a wire whose edges could not be ordered); the loops are still
  /// recorded, in the best order found.
  bool loops_closed = true;
};

/// Every item's value of `measure` for items [0, count), in item order: how load_cad has its
/// per-face measurements done. measure(i) is thread-safe and depends on i only, so whoever computes
/// a value (this thread, a task, another process) gets the same bits, and the model is the same
/// whatever the split.
using MeasureItems =
    std::function<std::vector<double>(LO count, const std::function<double(LO)>& measure)>;

/// Options of load_cad.
struct LoadOptions {
  bool sew = false;          ///< sew disconnected faces before building the topology
  double sew_tolerance = 0;  ///< 0: 1e-6 of the bounding-box diagonal
  /// Runs the faces' area integrals, the dearest part of building the topology on B-spline faces
  /// (A319.brep: 0.35 of 0.49 s; done on every rank). Empty: every face in turn on this thread.
  /// The driver splits them over its ranks and threads (parallel::measure_split).
  MeasureItems measure_faces;
};

class CadModel {
 public:
  CadModel();
  ~CadModel();
  CadModel(CadModel&&) noexcept;
  CadModel& operator=(CadModel&&) noexcept;

  [[nodiscard]] std::span<const Corner> corners() const { return corners_; }
  [[nodiscard]] std::span<const Curve> curves() const { return curves_; }
  [[nodiscard]] std::span<const Face> faces() const { return faces_; }
  [[nodiscard]] LO num_corners() const { return static_cast<LO>(corners_.size()); }
  [[nodiscard]] LO num_curves() const { return static_cast<LO>(curves_.size()); }
  [[nodiscard]] LO num_faces() const { return static_cast<LO>(faces_.size()); }

  /// curve -> faces using it (each face once, increasing ids). A free curve of an open shell has 1.
  [[nodiscard]] const Adjacency& curve2faces() const { return curve2faces_; }
  /// corner -> curves ending at it (increasing ids).
  [[nodiscard]] const Adjacency& corner2curves() const { return corner2curves_; }
  /// face -> faces sharing at least one curve (increasing ids, no self).
  [[nodiscard]] const Adjacency& face2faces() const { return face2faces_; }

  [[nodiscard]] const Box3& box() const { return box_; }
  [[nodiscard]] double diagonal() const { return box_.diagonal(); }
  [[nodiscard]] const std::string& source() const { return source_; }

  /// New evaluator of curve c (the caller owns it and uses it from one thread).
  [[nodiscard]] std::unique_ptr<CurveGeometry> curve_geometry(LO c) const;
  /// New evaluator of face f (the caller owns it and uses it from one thread).
  /// FaceGeometry::contains needs `with_classifier`: building the point classifier costs more than
  /// the evaluator itself, so only the stages that classify points ask for it.
  [[nodiscard]] std::unique_ptr<FaceGeometry> face_geometry(LO f,
                                                            bool with_classifier = false) const;

  /// Implementation data (OpenCASCADE shapes), opaque outside src/cad.
  struct Impl;
  [[nodiscard]] const Impl& impl() const { return *impl_; }

 private:
  friend class ModelBuilder;
  std::vector<Corner> corners_;
  std::vector<Curve> curves_;
  std::vector<Face> faces_;
  Adjacency curve2faces_, corner2curves_, face2faces_;
  Box3 box_;
  std::string source_;
  std::unique_ptr<Impl> impl_;
};

/// Whether face f is planar and bounded only by straight lines (every loop, holes included), each
/// parallel or perpendicular to the others: the crossfield stage's exact-uniform shortcut
/// (CrossFieldOptions::exact_uniform) then gives the face its field without a solve, so its
/// cross-field cost is about nothing. Tolerance: 1e-6 rad on 4x the angle between two lines, the
/// shortcut's own test on the sampled boundary edges. A face without curves is false. Reads the
/// lines' directions from the CAD (OpenCASCADE); thread-safe, the same answer on every rank.
[[nodiscard]] bool planar_with_right_angle_lines(const CadModel& model, LO f);

/// The axis of a surface of revolution, in model units.
struct RevolutionAxis {
  Vec3 point;      ///< a point of the axis
  Vec3 direction;  ///< unit direction of the axis
  /// The surface is a circular cylinder: developable, and the field along its parallels is
  /// parallel (it does not rotate), so the cross field's conformal scaling H is exactly 0.
  bool cylinder = false;
};

/// The axis of face f when its surface is one of revolution: a circular cylinder, a cone, a sphere
/// (the axis of its parametrisation, through its poles), a torus, a surface of revolution, or a
/// plane with circles that share one centre (the normal through it: a washer, an annular
/// sector); nullopt otherwise (other planes: planar_with_right_angle_lines covers the
/// rectilinear ones). With the location of the face applied. Thread-safe, the same answer on
/// every rank.
[[nodiscard]] std::optional<RevolutionAxis> revolution_axis(const CadModel& model, LO f);

/// revolution_axis(model, f) when face f also has every curve of its loops a parallel (a circle
/// about the axis) or a meridian (a curve in a plane through the axis), none degenerate: the
/// crossfield stage's revolution shortcut (CrossFieldOptions::exact_revolution) then gives the
/// face its field without a diffusion solve; nullopt otherwise. From 5 points of each curve, each
/// within 1e-6 of the face's diagonal of the parallel or meridian through the first. A prediction
/// for the partition's cost estimate: the shortcut itself checks the sampled boundary.
[[nodiscard]] std::optional<RevolutionAxis> iso_line_revolution_axis(const CadModel& model, LO f);

/// Reads a STEP (.step, .stp), IGES (.iges, .igs) or BREP (.brep, .brp) file and builds the
/// topology. Entity ids follow OpenCASCADE's unique-shape maps (TopExp::MapShapes order), so they
/// are the same on every rank and every run. Throws InputError for a missing, empty, unreadable or
/// unsupported file, naming the file and the reason.
[[nodiscard]] CadModel load_cad(const std::string& path, const LoadOptions& options = {});

/// Sets how much the CAD kernel (OpenCASCADE) itself prints: by default its readers print progress
/// and statistics on stdout, which would mix with the program's own output (e.g. `info --json`).
/// quiet: nothing; otherwise its warnings and errors, on stderr. Process-wide:
/// the driver calls it once at start-up, before any thread exists.
void set_kernel_messages(bool quiet);

/// The CAD formats the built-in examples are written in.
enum class ExampleFormat { Step, Brep };

/// The names of the built-in examples, in the order `qsmesh example --help` lists them:
/// "wing-body" (a fuselage of revolution fused with a wing lofted from NACA 4-digit sections,
/// millimetres), "far-field" (the wing-body cut out of a box 5 fuselage lengths long: an external
/// flow domain with six huge planar faces) and "perforated-plate" (a 2000 x 1000 x 20 mm plate
/// with 72 holes: two faces of 73 loops each). Each is one valid solid.
std::vector<std::string> example_names();

/// Builds the built-in example `name` with OpenCASCADE and writes it to `path` as `format`,
/// whatever its extension (the driver picks the format by the name the user gave and writes a
/// temporary). Throws InputError for a name not in example_names() or when the file cannot be
/// written, Error when OpenCASCADE fails to build the model.
void write_example(const std::string& name, const std::string& path,
                   ExampleFormat format = ExampleFormat::Step);

}  // namespace qsmesh::cad
