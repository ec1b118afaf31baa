// Mesh output: CGNS (cgnslib), VTK XML UnstructuredGrid (.vtu), Gmsh MSH 4.1 ASCII (.msh), plain
// HDF5 datasets for solvers (.h5, with an XDMF description beside it for ParaView) and
// multi-block PLOT3D grids of the quad layout (.xyz / .p3d, with a JSON connectivity sidecar).
//
// Every writer writes to a temporary file in the destination folder and renames it to the requested
// name only once the file is complete (io/atomic_file.hpp): a failed write leaves nothing under the
// requested name and no temporary behind. Files carry no timestamps, so the same mesh and options
// give byte-identical files.
//
// Numbering shared by the writers (SurfaceMesh documents the mesh itself):
//  - vertex v of the mesh is vertex v+1 in CGNS and node v+1 in MSH, point v in VTU;
//  - CAD face f / curve c / corner k is CGNS section and family "Face_<f>" / "Curve_<c>", MSH
//  entity
//    tag f+1 / c+1 / k+1 of dimension 2 / 1 / 0;
//  - CGNS elements: one section per non-empty CAD face in increasing face id (the face's triangles
//  in
//    mesh order, then its quads), then one BAR_2 section per non-empty CAD curve; ids 1..n
//    contiguous.
//  - VTU cells: the triangles in mesh order, then the quads, then (optionally) the bars, then one
//    VTK_VERTEX per marker (WriteOptions::vtu_markers; their points follow the mesh vertices).
// CAD faces and curves without elements get no section, family, BC nor element block.
#pragma once

#include <string>
#include <vector>

#include "qsmesh/layout/quad_layout.hpp"
#include "qsmesh/mesh/surface_mesh.hpp"

namespace qsmesh::io {

/// An extra named field for the VTU writer (cross fields, size maps, quality, ...).
/// values.size() == components * (number of points or cells written); components is 1 or 3.
/// Written as Float64.
struct Field {
  std::string name;
  int components = 1;
  std::vector<double> values;
};

/// A point of interest drawn with the mesh in VTU output (a cross-field singularity, say), as an
/// extra point and a VTK_VERTEX cell after every other point and cell.
struct Marker {
  Vec3 position;
  LO face = kNoIndex;  ///< CAD face it belongs to (cell data cad_face)
};

struct WriteOptions {
  // CGNS
  std::string cgns_base_name = "qsmesh";  ///< CGNS names are at most 32 characters
  std::string cgns_zone_name = "Surface";
  // VTU
  bool vtu_binary = true;           ///< inline base64 (true) or ASCII (false) data arrays
  bool vtu_include_bars = false;    ///< also write the curve bars as VTK_LINE cells
  std::vector<Marker> vtu_markers;  ///< extra points with a vertex cell each
  std::vector<Field> point_fields;  ///< one value (or 3) per mesh vertex, then per marker
  std::vector<Field> cell_fields;   ///< one value (or 3) per VTU cell (see above), markers last
  // MSH
  bool msh_corner_elements = true;  ///< write one point element (type 15) per meshed corner
  // PLOT3D
  /// Fortran unformatted sequential records (a 4-byte length before and after each record: what
  /// CFL3D and most PLOT3D tools read), or false: the same bytes without them (C stream).
  bool plot3d_fortran_records = true;
  bool plot3d_single_precision = false;  ///< float32 coordinates instead of float64
};

/// Writes `mesh` to `path`, the format chosen from the extension (.cgns .vtu .msh .h5, any case;
/// .xyz / .p3d: write_plot3d of layout::extract_quad_layout(mesh)).
/// Throws InputError (one line naming the path) when the extension is not supported or the folder
/// does not exist or is not writable, before any work; qsmesh::Error when the mesh is inconsistent
/// (check_mesh_for_output) or writing fails.
void write_mesh(const mesh::SurfaceMesh& mesh, const std::string& path,
                const WriteOptions& options = {});

/// Output formats, from the extension of the path (case-insensitive): .cgns, .vtu, .msh, .h5,
/// .xyz or .p3d (PLOT3D).
enum class Format { kNone, kCgns, kVtu, kMsh, kHdf5, kPlot3d };
[[nodiscard]] Format output_format(const std::string& path);
/// The extension of `path` in lower case, with its dot (".h5"; "" when it has none).
[[nodiscard]] std::string lowercase_extension(const std::string& path);

/// True when the extension of `path` names a format write_mesh writes (case-insensitive).
[[nodiscard]] bool is_supported_output(const std::string& path);

/// For a program's main, first thing (before any HDF5 or CGNS call; later it does nothing): keeps
/// HDF5 from closing its files at exit. A CGNS file whose write failed (disk full) stays half-open
/// inside the library, whose exit handler would then crash the process after the error was
/// reported; the operating system closes what is left instead.
void prepare_output_libraries();

/// For the CLI at start-up, before meshing: throws InputError (one line naming the path) unless the
/// extension is supported and check_output_file("output", ...) passes for it (and for .h5 its
/// XDMF description, whose file name then may have no ':', which XDMF could not refer to; for
/// PLOT3D its sidecar plot3d_connections_path(path)).
void check_output_path(const std::string& path);

/// For the CLI at start-up, before any work, for any file a run writes (`what` names it in the
/// message: "output", "--stats"): throws InputError (one line) unless `path` names a file, not a
/// folder nor an existing device or pipe (the rename at the end would replace it: as root,
/// /dev/null itself), in an existing folder where this process can create its temporary
/// (created and removed here: permission bits cannot tell, root passes them and still cannot
/// create a file in /proc).
void check_output_file(const std::string& what, const std::string& path);

/// Throws qsmesh::Error unless the arrays of `mesh` agree: per-element CAD ids sized like the
/// elements and in range, vertex ids in range, one classification per vertex, curve_corners sized
/// num_cad_curves, face2curves empty or sized num_cad_faces.
void check_mesh_for_output(const mesh::SurfaceMesh& mesh);

/// CGNS/HDF5: one base (CellDimension 2, PhysicalDimension 3, SI-like units with the mesh's length
/// unit "mm" or "m"), one unstructured zone, a TRI_3/QUAD_4/MIXED section and a family per CAD
/// face, a BAR_2 section, a family and an EdgeCenter BC (FamilySpecified) per CAD curve. A mesh of
/// order N > 1 (SurfaceMesh::order) has QUAD_9 / QUAD_16 / QUAD_25 and BAR_3 / BAR_4 / BAR_5
/// sections instead (CGNS's node order, mesh::quad_grid_positions_recursive); CGNS defines no
/// elements of order 5: that throws InputError. Limit: Debian's cgnslib uses 32-bit ids; larger
/// meshes throw Error.
void write_cgns(const mesh::SurfaceMesh& mesh, const std::string& path,
                const WriteOptions& options = {});

/// Block-structured CGNS/HDF5 (paper 002's block-structured output, from the layout as it is): one
/// base (CellDimension 2, PhysicalDimension 3, units as write_cgns), one structured zone
/// "Block_<k>_Face_<f>" (k and f zero-padded to 6 digits or more) of (ni + 1) x (nj + 1) vertices
/// per block of `layout` (its vertex grid, i fastest) with FamilyName "Face_<f>", and a
/// GridConnectivity1to1 for every maximal stretch of a block side shared with one side of another
/// block (or of itself, across a seam), within a face or across a CAD curve: point ranges, donor
/// ranges and the transform relating the index spaces. Free block edges (no block across: an open
/// shell's border) get a BC (FamilySpecified, family "Curve_<c>" with FamilyBC BCWall, as
/// write_cgns) per run of them on one curve. The faces in layout.unblocked_faces go into one
/// unstructured zone "Unstructured" (a section per face). Where a block side runs along it, both
/// zones get a GridConnectivity (Abutting1to1, Vertex: the block's PointRange against the
/// unstructured zone's PointListDonor, and that zone's PointList against the block's (i, j)
/// PointListDonor), and no BC is written there. Along a CAD curve that three or more faces border
/// (non-manifold), each block side is joined to every other block side (and the unstructured zone)
/// along it: a side edge where m sides meet is in m - 1 interfaces, one per other side, ordered by
/// their first edge along the side, then donor block and side; off the CAD curves only sides of
/// the same face are joined (a face given twice meets its copy on its curves only).
/// `layout` must come from extract_quad_layout(mesh).
void write_cgns_blocks(const mesh::SurfaceMesh& mesh, const layout::QuadLayout& layout,
                       const std::string& path, const WriteOptions& options = {});

/// What write_plot3d wrote, and what PLOT3D could not hold.
struct Plot3dReport {
  GO blocks = 0;
  std::vector<LO> skipped_faces;  ///< faces of layout.unblocked_faces with elements, not written
  GO skipped_triangles = 0, skipped_quads = 0;  ///< their elements
};

/// The JSON sidecar written beside the PLOT3D grid `grid_path`: the same name with ".json" added.
[[nodiscard]] std::string plot3d_connections_path(const std::string& grid_path);

/// Multi-block PLOT3D grid of the blocks of `layout` (from layout::extract_quad_layout(mesh); paper
/// 002's block-structured output as write_cgns_blocks writes it), whole (not planes), 3D, no
/// IBLANK, little-endian: the block count (int32), then idim, jdim, kdim (int32) of every block,
/// then per block x, y, z (each over its points, i fastest; float64, or float32 with
/// options.plot3d_single_precision). A block of ni x nj quads is an (ni + 1) x (nj + 1) x 1 grid,
/// the points of its vertex grid in order (i x j is along the CAD face's normal). With
/// options.plot3d_fortran_records (the default) every one of these three parts (counts,
/// dimensions, each block's coordinates) is one Fortran unformatted sequential record (int32 byte
/// count before and after), else the bytes follow each other with nothing between (C stream).
/// Beside it, plot3d_connections_path(path), JSON ("format": "qsmesh plot3d connectivity",
/// "format_version": 1): per block (1-based "block" as in the grid file, "name" as the CGNS zone,
/// CAD "face", "family" "Face_<f>", idim, jdim, kdim) its 1-to-1 "interfaces" (side, 1-based
/// (i, j) "range", "donor" block, "donor_side", "donor_range", CGNS "transform"; k = 1 throughout),
/// its free "boundaries" (side, range, "family" "Curve_<c>", "curve", "bc": "BCWall") and the
/// runs of its sides "against_left_out_faces"; at the end the "left_out_faces" and their
/// element counts. Interfaces and boundaries are those of write_cgns_blocks (block_connections).
/// PLOT3D holds structured blocks only: the faces in layout.unblocked_faces (triangles, patches
/// that are not grids) are not written (the report and the sidecar list them). Both files are
/// written under temporary names and renamed together (commit_together). Throws qsmesh::Error on an
/// inconsistent mesh or layout, qsmesh::OutputError when the files cannot be written.
Plot3dReport write_plot3d(const mesh::SurfaceMesh& mesh, const layout::QuadLayout& layout,
                          const std::string& path, const WriteOptions& options = {});

/// VTK XML UnstructuredGrid: triangles (VTK type 5), quads (9), optionally bars (3); cell data
/// Int32 "cad_face" (and "cad_curve" with bars; -1 where not applicable), point data Int32
/// "cad_dim" and "cad_entity" (the vertex classification), plus options.point_fields / cell_fields.
/// A mesh of order 2 has biquadratic quads (28) and quadratic edges (21), of order 3 to 5 Lagrange
/// quadrilaterals (70) and Lagrange curves (68) in VTK's node order
/// (mesh::quad_grid_positions_vtk).
void write_vtu(const mesh::SurfaceMesh& mesh, const std::string& path,
               const WriteOptions& options = {});

/// HDF5 (format_version 2) for solvers, plus the XDMF 3 file xdmf_path_for(path) describing it
/// (open that one in ParaView: one block each for the quads, the triangles and the curve bars, with
/// cell data cad_face / cad_curve and point data cad_dim / cad_entity). Both are written under
/// temporary names and renamed together: if either rename fails, an earlier .h5 of the same name
/// is put back, so a failure leaves the earlier pair as it was.
/// Root attributes: format ("qsmesh surface mesh"), format_version (2), length_unit,
/// num_cad_corners, num_cad_curves, num_cad_faces. Datasets (little-endian, ids 0-based, elements
/// in mesh order):
///   coordinates         float64 [n_vertices, 3]
///   vertex_cad_dim      int32 [n_vertices]: 0 corner, 1 curve, 2 face (VertexClass::dim)
///   vertex_cad_entity   int32 [n_vertices]: corner / curve / face id
///   vertex_cad_param    float64 [n_vertices, 2]: (t, 0) on a curve, (u, v) in a face
///   quads               int64 [n_quads, 4], counter-clockwise about the face normal
///   quad_cad_face       int32 [n_quads]
///   triangles           int64 [n_triangles, 3]; triangle_cad_face int32 [n_triangles]
///   bars                int64 [n_bars, 2]; bar_cad_curve int32 [n_bars]
///   curve_corners       int32 [n_curves, 2]: end corners of each curve (-1: none)
///   face_curve_offsets  int64 [n_faces + 1]; face_curves int32: the curves bounding face f are
///                       face_curves[face_curve_offsets[f] .. face_curve_offsets[f + 1])
///   quad<M>, bar<N+1>   int64 [n_quads, M = (N + 1)^2], [n_bars, N + 1]: only for meshes of
///                       order N > 1 (quad9 / bar3, quad16 / bar4, quad25 / bar5, quad36 / bar6):
///                       the whole elements in Gmsh's node order (corners, edge nodes edge by
///                       edge, then the interior numbered the same way again,
///                       mesh::quad_grid_positions_recursive; CGNS's too up to order 3, not for
///                       QUAD_25) and the bars' (ends, then the interior). For order 2
///                       the XDMF file shows these (Quadrilateral_9, Edge_3) instead of the
///                       linear quads and bars; XDMF has no higher-order quads, so for order 3
///                       and up it shows the linear quads and bars of the corners. A node put
///                       back on its straight position (off the CAD) has vertex_cad_param NaN.
///                       Root attribute order: N (1 for linear meshes).
/// (format_version 1, of the seventeenth session, had quad_nodes [n_quads, 5] and bar_nodes
/// [n_bars] instead of quad9 and bar3.)
/// Empty element kinds are zero-row datasets. Objects carry no timestamps: the same mesh gives the
/// same bytes. The file is built in memory (HDF5's core driver; as large as the file) and written
/// by OutputFile, so a full disk is one OutputError and HDF5 never holds a half-written file.
/// Throws qsmesh::Error on an inconsistent mesh or a failed HDF5 call, qsmesh::OutputError when
/// the files cannot be written.
void write_hdf5(const mesh::SurfaceMesh& mesh, const std::string& path,
                const WriteOptions& options = {});

/// The XDMF file written beside the HDF5 file `h5_path`: the same name with the extension .xdmf.
[[nodiscard]] std::string xdmf_path_for(const std::string& h5_path);

/// Gmsh MSH 4.1 ASCII: $Entities (corners, curves with their end corners, faces with their bounding
/// curves), $Nodes and $Elements grouped by CAD entity (parametric 0). A mesh of order N has
/// Gmsh's quads and lines of order N (types 10, 36, 37, 38 and 8, 26, 27, 28; Gmsh's node order).
void write_msh(const mesh::SurfaceMesh& mesh, const std::string& path,
               const WriteOptions& options = {});

}  // namespace qsmesh::io
