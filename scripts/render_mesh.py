#!/usr/bin/python3
"""Draws a qsmesh surface mesh (.vtu, as written by `qsmesh mesh ... -o MESH.vtu`) from four
standard views into one PNG: iso, top, front and side in a 2x2 grid, quads coloured by SICN (the
signed inverse condition number of src/mesh/quality.cpp, mesh::quad_sicn: the worst corner's
2 (n_i . n) / (|e_prev|^2 + |e_next|^2) with n the quad's mean normal), irregular interior vertices
marked (valence 3 blue, valence 5 red, others magenta; 5 and 7 in a triangle mesh), CAD curves drawn in black, with a colour bar
and the mesh's counts beside the views. Triangles, where the mesh has some, are coloured by their
quality 2 sqrt(3) area / sum of squared edge lengths, in the same scale.

Where the .vtu holds line cells (the curve bars of `qsmesh sizemap`) those are the CAD curves;
otherwise an edge lies on a CAD curve when the cells on its two sides belong to different CAD faces
(cell data cad_face), when it borders one cell only, or when both its vertices lie on CAD curves or
corners (point data cad_dim <= 1) and not on two different curves (cad_entity). Interior vertices are
those with cad_dim 2, as in mesh::compute_stats; regular valence is 4 (6 in a triangle mesh).

Needs Debian's python3-vtk9 and python3-numpy; renders offscreen, and where no X display is set it
runs itself under xvfb-run (Debian xvfb; see scripts/vtk_offscreen.py). Prints one line of counts
(quads, SICN min and mean, irregular interior vertices) that a test compares with `--stats`.

Usage: /usr/bin/python3 scripts/render_mesh.py MESH.vtu -o VIEW.png [--size WxH] [--title TEXT]
                                               [--edges auto|on|off]
Exit codes: 0 success, 2 bad input (missing file, no surface cells, missing package)."""
import argparse
import os
import sys
import time

sys.dont_write_bytecode = True  # no __pycache__ in scripts/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vtk_offscreen  # noqa: E402

TOOL = "render_mesh"

# View name, direction from the model towards the camera, camera up.
VIEWS = [
    ("iso (+x -y +z)", (1.0, -1.0, 1.0), (0.0, 0.0, 1.0)),
    ("top (+z)", (0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    ("front (-y)", (0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    ("side (+x)", (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
]

# SICN colour scale: poor quads red, fair orange-yellow, good green to blue.
SICN_COLOURS = [(0.0, (0.65, 0.0, 0.0)), (0.3, (0.9, 0.2, 0.1)), (0.6, (1.0, 0.75, 0.2)),
                (0.8, (0.95, 0.95, 0.55)), (0.9, (0.55, 0.85, 0.55)), (1.0, (0.35, 0.6, 0.9))]
INVERTED_COLOUR = (1.0, 0.0, 1.0)  # SICN < 0: an inverted or degenerate quad
BELOW_COLOUR = (0, 90, 255)  # valence one below the regular one (3 in a quad mesh)
ABOVE_COLOUR = (230, 0, 0)  # one above (5)
OTHER_VALENCE_COLOUR = (200, 0, 200)


def parse_args():
    p = argparse.ArgumentParser(prog="render_mesh.py", description=__doc__.split("\n\n")[0])
    p.add_argument("mesh", help="surface mesh, .vtu")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--size", default="1600x1200", help="image size WxH in pixels (default 1600x1200)")
    p.add_argument("--title", help="title above the counts (default: the mesh file's name)")
    p.add_argument("--edges", choices=["auto", "on", "off"], default="auto",
                   help="draw the element edges (auto: when the mesh has at most 60000 elements)")
    a = p.parse_args()
    vtk_offscreen.check_picture_args(p, a)
    if not a.mesh.endswith(".vtu"):
        p.error(f"{a.mesh}: only .vtu meshes are read (write one with qsmesh mesh ... -o MESH.vtu)")
    if not os.path.isfile(a.mesh):
        p.error(f"{a.mesh}: no such file")
    return a


class Mesh:
    """The .vtu's surface cells as numpy arrays, and what the picture shows of them."""

    def __init__(self, path):
        import numpy as np
        from vtkmodules.util.numpy_support import vtk_to_numpy
        from vtkmodules.vtkIOXML import vtkXMLUnstructuredGridReader

        reader = vtkXMLUnstructuredGridReader()
        reader.SetFileName(path)
        reader.Update()
        grid = reader.GetOutput()
        if grid is None or grid.GetNumberOfCells() == 0:
            raise ValueError(f"{path}: no cells (not a VTK XML unstructured grid?)")
        self.points = vtk_to_numpy(grid.GetPoints().GetData()).astype(np.float64)
        types = vtk_to_numpy(grid.GetCellTypesArray()).astype(np.int64)
        cells = grid.GetCells()
        offsets = vtk_to_numpy(cells.GetOffsetsArray()).astype(np.int64)
        conn = vtk_to_numpy(cells.GetConnectivityArray()).astype(np.int64)
        start = offsets[:-1]

        def corners(mask, k):
            return conn[start[mask][:, None] + np.arange(k)[None, :]].reshape(-1, k)

        # Linear and quadratic cells alike: their first nodes are the corners.
        qmask = (types == 9) | (types == 28) | (types == 23)
        tmask = (types == 5) | (types == 22)
        lmask = (types == 3) | (types == 21)
        self.quads = corners(qmask, 4)
        self.triangles = corners(tmask, 3)
        lines = corners(lmask, 2)
        if len(self.quads) + len(self.triangles) == 0:
            raise ValueError(f"{path}: no quads or triangles")
        n = len(self.points)
        pd, cd = grid.GetPointData(), grid.GetCellData()

        def array(data, name, mask=None):
            a = data.GetArray(name)
            if a is None:
                return None
            v = vtk_to_numpy(a).astype(np.int64)
            return v if mask is None else v[mask]

        cad_dim = array(pd, "cad_dim")
        cad_entity = array(pd, "cad_entity")
        cad_face = array(cd, "cad_face")
        face_q = cad_face[qmask] if cad_face is not None else np.zeros(len(self.quads), np.int64)
        face_t = cad_face[tmask] if cad_face is not None else np.zeros(len(self.triangles), np.int64)

        self.sicn = quad_sicn(self.points[self.quads]) if len(self.quads) else np.zeros(0)
        self.tri_quality = (triangle_quality(self.points[self.triangles]) if len(self.triangles)
                            else np.zeros(0))

        # Valence: elements (quads and triangles) around each vertex, as in mesh::compute_stats.
        valence = np.bincount(np.concatenate([self.quads.ravel(), self.triangles.ravel()]),
                              minlength=n)

        # Element edges, each once, with the lowest and highest CAD face on its sides.
        e = [self.quads[:, [k, (k + 1) % 4]] for k in range(4)]
        e += [self.triangles[:, [k, (k + 1) % 3]] for k in range(3)]
        f = [face_q] * 4 + [face_t] * 3
        edges = np.sort(np.concatenate(e), axis=1)
        efaces = np.concatenate(f)
        keys, inverse, count = np.unique(edges[:, 0] * n + edges[:, 1], return_inverse=True,
                                         return_counts=True)
        fmin = np.full(len(keys), np.iinfo(np.int64).max)
        fmax = np.full(len(keys), np.iinfo(np.int64).min)
        np.minimum.at(fmin, inverse, efaces)
        np.maximum.at(fmax, inverse, efaces)
        self.edges = np.stack([keys // n, keys % n], axis=1)

        if len(lines):
            self.curve_edges = lines
        else:
            on_curve = count == 1
            on_curve |= fmin != fmax
            if cad_dim is not None and cad_entity is not None:
                a, b = self.edges[:, 0], self.edges[:, 1]
                da, db = cad_dim[a], cad_dim[b]
                both = (da >= 0) & (da <= 1) & (db >= 0) & (db <= 1)
                other_curves = (da == 1) & (db == 1) & (cad_entity[a] != cad_entity[b])
                on_curve |= both & ~other_curves
            self.curve_edges = self.edges[on_curve]

        self.regular = 4 if len(self.quads) >= len(self.triangles) else 6
        if cad_dim is not None:
            interior = cad_dim == 2
        else:
            interior = np.ones(n, dtype=bool)
            interior[self.curve_edges.ravel()] = False
        interior &= valence > 0
        self.interior_vertices = int(interior.sum())
        self.irregular = np.nonzero(interior & (valence != self.regular))[0]
        self.irregular_valence = valence[self.irregular]


def quad_sicn(q):
    """SICN of quads q[n, 4, 3], as mesh::quad_sicn: -1 for a quad without area."""
    import numpy as np

    prev = np.roll(q, 1, axis=1) - q
    nxt = np.roll(q, -1, axis=1) - q
    normals = np.cross(nxt, prev)
    total = normals.sum(axis=1)
    length = np.linalg.norm(total, axis=1)
    ok = length > 0
    unit = np.zeros_like(total)
    unit[ok] = total[ok] / length[ok][:, None]
    denom = (prev**2).sum(axis=2) + (nxt**2).sum(axis=2)
    dots = np.einsum("nij,nj->ni", normals, unit)
    corner = np.full(dots.shape, -1.0)
    np.divide(2.0 * dots, denom, out=corner, where=denom > 0)
    worst = corner.min(axis=1)
    worst[~ok] = -1.0
    return worst


def triangle_quality(t):
    """2 sqrt(3) area / sum of squared edge lengths of triangles t[n, 3, 3], as
    mesh::triangle_quality."""
    import numpy as np

    area2 = np.linalg.norm(np.cross(t[:, 1] - t[:, 0], t[:, 2] - t[:, 0]), axis=1)
    l2 = sum(((t[:, (k + 1) % 3] - t[:, k]) ** 2).sum(axis=1) for k in range(3))
    out = np.zeros(len(t))
    np.divide(2.0 * np.sqrt(3.0) * area2, l2, out=out, where=l2 > 0)
    return out


def lookup_table():
    from vtkmodules.vtkCommonCore import vtkLookupTable
    from vtkmodules.vtkRenderingCore import vtkColorTransferFunction

    ctf = vtkColorTransferFunction()
    for x, (r, g, b) in SICN_COLOURS:
        ctf.AddRGBPoint(x, r, g, b)
    lut = vtkLookupTable()
    lut.SetNumberOfTableValues(256)
    lut.SetTableRange(0.0, 1.0)
    for i in range(256):
        r, g, b = ctf.GetColor(i / 255.0)
        lut.SetTableValue(i, r, g, b, 1.0)
    lut.SetBelowRangeColor(*INVERTED_COLOUR, 1.0)
    lut.UseBelowRangeColorOn()
    lut.Build()
    return lut


def build_actors(mesh, lut, edges, point_size):
    """The surface, CAD curve and irregular vertex actors (one set per view)."""
    import numpy as np
    from vtkmodules.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray
    from vtkmodules.vtkCommonCore import vtkPoints
    from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
    from vtkmodules.vtkRenderingCore import vtkActor, vtkPolyDataMapper

    points = vtkPoints()
    points.SetData(numpy_to_vtk(mesh.points, deep=True))

    def cell_array(cells):
        k = cells.shape[1] if len(cells) else 0
        ca = vtkCellArray()
        if len(cells):
            offsets = np.arange(0, k * len(cells) + 1, k, dtype=np.int64)
            ca.SetData(numpy_to_vtkIdTypeArray(offsets, deep=True),
                       numpy_to_vtkIdTypeArray(cells.astype(np.int64).ravel(), deep=True))
        return ca

    surface = vtkPolyData()
    surface.SetPoints(points)
    polys = vtkCellArray()
    # Quads then triangles, as the scalars below.
    cells = [c for c in (mesh.quads, mesh.triangles) if len(c)]
    for c in cells:
        polys.Append(cell_array(c))
    surface.SetPolys(polys)
    quality = numpy_to_vtk(np.concatenate([mesh.sicn, mesh.tri_quality]), deep=True)
    quality.SetName("quality")
    surface.GetCellData().SetScalars(quality)

    curves = vtkPolyData()
    curves.SetPoints(points)
    curves.SetLines(cell_array(mesh.curve_edges))

    marks = vtkPolyData()
    mark_points = vtkPoints()
    mark_points.SetData(numpy_to_vtk(mesh.points[mesh.irregular], deep=True))
    marks.SetPoints(mark_points)
    marks.SetVerts(cell_array(np.arange(len(mesh.irregular)).reshape(-1, 1)))
    palette = {mesh.regular - 1: BELOW_COLOUR, mesh.regular + 1: ABOVE_COLOUR}
    rgb = np.array([palette.get(int(v), OTHER_VALENCE_COLOUR) for v in mesh.irregular_valence],
                   dtype=np.uint8).reshape(-1, 3)
    colours = numpy_to_vtk(rgb, deep=True)
    colours.SetName("valence_colour")
    marks.GetPointData().SetScalars(colours)

    surface_mapper = vtkPolyDataMapper()
    surface_mapper.SetInputData(surface)
    surface_mapper.SetLookupTable(lut)
    surface_mapper.SetScalarModeToUseCellData()
    surface_mapper.UseLookupTableScalarRangeOn()
    # Push the faces back so that the curves and edges on them stay visible.
    surface_mapper.SetResolveCoincidentTopologyToPolygonOffset()
    surface_mapper.SetRelativeCoincidentTopologyPolygonOffsetParameters(1.5, 1.5)
    curve_mapper = vtkPolyDataMapper()
    curve_mapper.SetInputData(curves)
    curve_mapper.ScalarVisibilityOff()
    mark_mapper = vtkPolyDataMapper()
    mark_mapper.SetInputData(marks)
    mark_mapper.SetScalarModeToUsePointData()
    mark_mapper.SetColorModeToDirectScalars()

    def actors():
        s = vtkActor()
        s.SetMapper(surface_mapper)
        prop = s.GetProperty()
        prop.SetAmbient(0.35)
        prop.SetDiffuse(0.7)
        prop.SetSpecular(0.0)
        prop.SetInterpolationToFlat()
        if edges:
            prop.EdgeVisibilityOn()
            prop.SetEdgeColor(0.25, 0.25, 0.25)
            prop.SetLineWidth(1.0)
        c = vtkActor()
        c.SetMapper(curve_mapper)
        c.GetProperty().SetColor(0.0, 0.0, 0.0)
        c.GetProperty().SetLineWidth(max(2.0, point_size / 3.0))
        c.GetProperty().LightingOff()
        m = vtkActor()
        m.SetMapper(mark_mapper)
        m.GetProperty().SetPointSize(point_size)
        m.GetProperty().RenderPointsAsSpheresOn()
        return [s, c, m]

    return actors


def fit_camera(renderer, points, direction, up, aspect):
    """Parallel projection along direction, fitted tightly to the points' projection."""
    import numpy as np

    d = np.asarray(direction, float)
    d /= np.linalg.norm(d)
    u = np.asarray(up, float)
    u = u - d * np.dot(u, d)
    u /= np.linalg.norm(u)
    r = np.cross(u, d)
    x, y, z = points @ r, points @ u, points @ d
    cx, cy = (x.min() + x.max()) / 2, (y.min() + y.max()) / 2
    half_w, half_h = (x.max() - x.min()) / 2, (y.max() - y.min()) / 2
    center = cx * r + cy * u + ((z.min() + z.max()) / 2) * d
    depth = max(z.max() - z.min(), half_w, half_h, 1e-12)
    camera = renderer.GetActiveCamera()
    camera.ParallelProjectionOn()
    camera.SetFocalPoint(*center)
    camera.SetPosition(*(center + 4 * depth * d))
    camera.SetViewUp(*u)
    camera.SetParallelScale(max(half_h, half_w / aspect, 1e-12) * 1.08)
    renderer.ResetCameraClippingRange()


def text_actor(text, size, colour=(0.0, 0.0, 0.0), bold=False):
    from vtkmodules.vtkRenderingCore import vtkTextActor

    t = vtkTextActor()
    t.SetInput(text)
    p = t.GetTextProperty()
    p.SetFontSize(size)
    p.SetColor(*colour)
    p.SetBold(bold)
    p.SetFontFamilyToArial()
    return t


def render(mesh, args):
    import numpy as np
    from vtkmodules.vtkRenderingAnnotation import vtkScalarBarActor
    from vtkmodules.vtkRenderingCore import vtkRenderer, vtkRenderWindow

    w, h = args.width, args.height
    nelem = len(mesh.quads) + len(mesh.triangles)
    edges = args.edges == "on" or (args.edges == "auto" and nelem <= 60000)
    point_size = max(5.0, min(w, h) / 110.0)
    lut = lookup_table()
    new_actors = build_actors(mesh, lut, edges, point_size)

    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(w, h)
    window.SetMultiSamples(0)
    panel = 0.18  # right-hand column: colour bar, legend, counts
    grid_w = 1.0 - panel
    font = max(12, int(h / 55))
    for i, (name, direction, up) in enumerate(VIEWS):
        col, row = i % 2, i // 2
        x0, y0 = col * grid_w / 2, (1 - row) * 0.5
        ren = vtkRenderer()
        ren.SetViewport(x0, y0, x0 + grid_w / 2, y0 + 0.5)
        ren.SetBackground(1.0, 1.0, 1.0)
        for a in new_actors():
            ren.AddActor(a)
        label = text_actor(name, font, (0.2, 0.2, 0.2), bold=True)
        label.SetPosition(8, 6)
        ren.AddActor2D(label)
        window.AddRenderer(ren)
        vp_w, vp_h = grid_w / 2 * w, 0.5 * h
        fit_camera(ren, mesh.points[np.unique(np.concatenate([mesh.quads.ravel(),
                                                                mesh.triangles.ravel()]))],
                   direction, up, vp_w / vp_h)

    side = vtkRenderer()
    side.SetViewport(grid_w, 0.0, 1.0, 1.0)
    side.SetBackground(0.94, 0.94, 0.94)
    pw = panel * w
    bar = vtkScalarBarActor()
    bar.SetLookupTable(lut)
    bar.SetTitle("SICN" if len(mesh.triangles) == 0 else "SICN /\ntri quality")
    bar.SetNumberOfLabels(6)
    bar.SetLabelFormat("%.1f")
    bar.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
    bar.GetPositionCoordinate().SetValue(0.12, 0.42)
    bar.SetWidth(0.6)
    bar.SetHeight(0.5)
    bar.SetMaximumWidthInPixels(int(pw * 0.45))
    bar.SetBarRatio(0.45)
    bar.DrawBelowRangeSwatchOn()
    bar.SetBelowRangeAnnotation("< 0")
    bar.UnconstrainedFontSizeOn()
    for prop, size in ((bar.GetTitleTextProperty(), font), (bar.GetLabelTextProperty(), font),
                       (bar.GetAnnotationTextProperty(), int(font * 0.8))):
        prop.SetFontSize(size)
        prop.SetColor(0, 0, 0)
        prop.SetFontFamilyToArial()
        prop.ShadowOff()
        prop.ItalicOff()
    side.AddActor2D(bar)

    title = args.title or os.path.basename(args.mesh)
    small = max(10, int(font * 0.8))
    irr_pct = 100.0 * len(mesh.irregular) / max(1, mesh.interior_vertices)
    lines = [(title, (0, 0, 0), True), ("", None, False)]
    counts = f"{len(mesh.quads)} quads"
    if len(mesh.triangles):
        counts += f"\n{len(mesh.triangles)} triangles"
    lines.append((counts, (0, 0, 0), False))
    if len(mesh.quads):
        lines.append((f"SICN min {mesh.sicn.min():.3f}\nSICN mean {mesh.sicn.mean():.3f}",
                      (0, 0, 0), False))
    lines.append((f"irregular interior\nvertices {len(mesh.irregular)} ({irr_pct:.2f}%)", (0, 0, 0),
                  False))
    lines.append(("", None, False))
    lines.append((f"o valence {mesh.regular - 1}", tuple(c / 255 for c in BELOW_COLOUR), True))
    lines.append((f"o valence {mesh.regular + 1}", tuple(c / 255 for c in ABOVE_COLOUR), True))
    lines.append(("o other valence", tuple(c / 255 for c in OTHER_VALENCE_COLOUR), True))
    lines.append(("- CAD curves", (0, 0, 0), True))
    y = 0.38 * h
    for text, colour, bold in lines:
        if not text:
            y -= small * 0.8
            continue
        t = text_actor(text, small, colour, bold)
        t.GetTextProperty().SetVerticalJustificationToTop()
        t.SetPosition(max(6, int(0.08 * pw)), int(y))
        side.AddActor2D(t)
        y -= small * 1.35 * (text.count("\n") + 1)
    window.AddRenderer(side)
    vtk_offscreen.write_png(window, args.output)


def main():
    args = parse_args()
    vtk_offscreen.ensure_display(TOOL)
    vtk_offscreen.import_vtk(TOOL)
    try:
        import numpy  # noqa: F401
    except ImportError:
        print(f"{TOOL}: numpy is missing (Debian package python3-numpy)", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    try:
        mesh = Mesh(args.mesh)
    except ValueError as e:
        print(f"{TOOL}: {e}", file=sys.stderr)
        return 2
    t1 = time.perf_counter()
    render(mesh, args)
    t2 = time.perf_counter()
    sicn_min = float(mesh.sicn.min()) if len(mesh.quads) else 0.0
    sicn_avg = float(mesh.sicn.mean()) if len(mesh.quads) else 0.0
    print(f"{TOOL}: {args.output}: quads {len(mesh.quads)} triangles {len(mesh.triangles)} "
          f"sicn_min {sicn_min:.6f} sicn_avg {sicn_avg:.6f} "
          f"irregular_interior {len(mesh.irregular)} interior_vertices {mesh.interior_vertices} "
          f"curve_edges {len(mesh.curve_edges)} read {t1 - t0:.2f} s render {t2 - t1:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
