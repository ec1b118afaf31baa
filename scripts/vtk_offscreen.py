"""Shared by scripts/render_mesh.py and scripts/plot_table.py: VTK offscreen rendering on a
machine without a display.

Debian 12's VTK 9.1 (python3-vtk9) is built for X only: its render window is
vtkXOpenGLRenderWindow, with neither EGL nor OSMesa compiled in, so even an offscreen window needs
an X server. Where DISPLAY is unset, ensure_display() runs the script again under xvfb-run
(Debian xvfb, with xauth), a virtual X server whose OpenGL is Mesa's software rasterizer; where
DISPLAY is set, the window is still offscreen and nothing appears on screen."""
import os
import shutil
import sys

_MARK = "QSMESH_UNDER_XVFB"


def check_picture_args(parser, args):
    """The arguments both picture scripts take: sets args.width and args.height from args.size
    ("WxH", at least 200x150) and checks that args.output's folder exists; parser.error (exit 2)
    otherwise."""
    try:
        args.width, args.height = (int(x) for x in args.size.lower().split("x"))
        if args.width < 200 or args.height < 150:
            raise ValueError
    except ValueError:
        parser.error(f"--size must be WxH with W >= 200 and H >= 150, not '{args.size}'")
    out_dir = os.path.dirname(os.path.abspath(args.output))
    if not os.path.isdir(out_dir):
        parser.error(f"{args.output}: the folder {out_dir} does not exist")


def ensure_display(tool, screen="2560x1600x24"):
    """Returns when an X display is there; otherwise re-executes this script under xvfb-run (does
    not return), or exits with status 2 naming the missing package."""
    if os.environ.get("DISPLAY"):
        return
    if os.environ.get(_MARK):
        sys.exit(f"{tool}: no X display even under xvfb-run")
    xvfb_run = shutil.which("xvfb-run")
    if not xvfb_run:
        print(f"{tool}: no X display and no xvfb-run; Debian's VTK renders through X even offscreen:"
              " install the Debian packages xvfb and xauth (scripts/setup.sh does)", file=sys.stderr)
        sys.exit(2)
    env = dict(os.environ)
    env[_MARK] = "1"
    args = [xvfb_run, "-a", "-s", f"-screen 0 {screen}", sys.executable, os.path.abspath(sys.argv[0]),
            *sys.argv[1:]]
    sys.stdout.flush()
    sys.stderr.flush()
    os.execve(xvfb_run, args, env)


def import_vtk(tool):
    """Imports the VTK modules for rendering, or exits with status 2 naming the Debian package."""
    try:
        import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (registers the OpenGL render window)
        import vtkmodules.vtkRenderingFreeType  # noqa: F401  (text)
        import vtkmodules.vtkRenderingContextOpenGL2  # noqa: F401  (charts)
    except ImportError:
        print(f"{tool}: VTK's Python module is missing (Debian package python3-vtk9; run it with"
              " /usr/bin/python3)", file=sys.stderr)
        sys.exit(2)


def write_png(window, path):
    """Renders the window and writes it to path (under a temporary name, renamed when complete)."""
    from vtkmodules.vtkIOImage import vtkPNGWriter
    from vtkmodules.vtkRenderingCore import vtkWindowToImageFilter

    window.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    tmp = os.path.join(os.path.dirname(os.path.abspath(path)), "." + os.path.basename(path) + ".tmp")
    writer = vtkPNGWriter()
    writer.SetFileName(tmp)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    if writer.GetErrorCode() != 0 or not os.path.exists(tmp):
        if os.path.exists(tmp):
            os.remove(tmp)
        sys.exit(f"cannot write {path}")
    os.replace(tmp, path)
