#!/usr/bin/python3
"""Plots columns of a CSV table (a header row, then one row per point) as lines with markers into
a PNG, with VTK's charts (Debian python3-vtk9; offscreen, under xvfb-run where no X display is set,
see scripts/vtk_offscreen.py). For the tables of the benchmark scripts: scripts/scaling_study.sh
--png plots speedup and efficiency against the configuration with it.

The x column may be numeric (a numeric axis) or text (the rows in order, labelled with the text,
e.g. "2x1"). A y cell that is not a number (empty, "n/a") leaves a gap in its line; text after the
number ("1.50 s") is ignored.

Usage: /usr/bin/python3 scripts/plot_table.py TABLE.csv -o PLOT.png --x COL --y COL[,COL...]
                                              [--title TEXT] [--ylabel TEXT] [--size WxH]
Exit codes: 0 success, 2 bad input (missing file or column, no numeric value to plot)."""
import argparse
import csv
import math
import os
import re
import sys

sys.dont_write_bytecode = True  # no __pycache__ in scripts/
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import vtk_offscreen  # noqa: E402

TOOL = "plot_table"
LINE_COLOURS = [(31, 119, 180), (214, 39, 40), (44, 160, 44), (148, 103, 189), (255, 127, 14),
                (23, 190, 207), (140, 86, 75)]
NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)")


def number(text):
    m = NUMBER.match(text or "")
    return float(m.group(1)) if m else math.nan


def parse_args():
    p = argparse.ArgumentParser(prog="plot_table.py", description=__doc__.split("\n\n")[0])
    p.add_argument("table", help="CSV file with a header row")
    p.add_argument("-o", "--output", required=True, help="PNG file to write")
    p.add_argument("--x", required=True, help="column of the x values")
    p.add_argument("--y", required=True, help="column(s) to plot, comma-separated")
    p.add_argument("--title", default="", help="chart title")
    p.add_argument("--ylabel", default="", help="y axis title (default: none)")
    p.add_argument("--size", default="900x600", help="image size WxH in pixels (default 900x600)")
    a = p.parse_args()
    vtk_offscreen.check_picture_args(p, a)
    if not os.path.isfile(a.table):
        p.error(f"{a.table}: no such file")
    a.y = [c for c in a.y.split(",") if c]
    if not a.y:
        p.error("--y names no column")
    return a


def read_table(args):
    """Returns (x values, x labels or None, {y column: values}); exits 2 on a bad table."""
    with open(args.table, newline="") as f:
        rows = list(csv.reader(f))
    if len(rows) < 2:
        print(f"{TOOL}: {args.table}: no data rows", file=sys.stderr)
        sys.exit(2)
    header, data = rows[0], [r for r in rows[1:] if r]
    for c in [args.x] + args.y:
        if c not in header:
            print(f"{TOOL}: {args.table}: no column '{c}' (columns: {', '.join(header)})",
                  file=sys.stderr)
            sys.exit(2)

    def column(name):
        i = header.index(name)
        return [r[i] if i < len(r) else "" for r in data]

    xs = column(args.x)
    xnum = [number(x) for x in xs]
    labels = None
    if any(math.isnan(x) for x in xnum) or any(NUMBER.match(x).end() != len(x.strip()) for x in xs
                                               if NUMBER.match(x)):
        labels, xnum = xs, [float(i + 1) for i in range(len(xs))]
    ys = {c: [number(v) for v in column(c)] for c in args.y}
    if all(math.isnan(v) for vs in ys.values() for v in vs):
        print(f"{TOOL}: {args.table}: no numeric value in {', '.join(args.y)}", file=sys.stderr)
        sys.exit(2)
    return xnum, labels, ys


def plot(args, xnum, labels, ys):
    from vtkmodules.vtkChartsCore import vtkAxis, vtkChart, vtkChartXY
    from vtkmodules.vtkCommonCore import vtkDoubleArray, vtkStringArray
    from vtkmodules.vtkCommonDataModel import vtkTable
    from vtkmodules.vtkViewsContext2D import vtkContextView

    view = vtkContextView()
    view.GetRenderer().SetBackground(1.0, 1.0, 1.0)
    window = view.GetRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(args.width, args.height)
    chart = vtkChartXY()
    view.GetScene().AddItem(chart)
    chart.SetShowLegend(True)
    chart.SetTitle(args.title)
    chart.GetTitleProperties().SetFontSize(16)
    chart.GetTitleProperties().SetColor(0, 0, 0)

    # One table per y column, holding only its numeric rows, so that gaps stay gaps.
    for k, (name, values) in enumerate(ys.items()):
        table = vtkTable()
        xa, ya = vtkDoubleArray(), vtkDoubleArray()
        xa.SetName(args.x)
        ya.SetName(name)
        for x, y in zip(xnum, values):
            if not math.isnan(y):
                xa.InsertNextValue(x)
                ya.InsertNextValue(y)
        table.AddColumn(xa)
        table.AddColumn(ya)
        line = chart.AddPlot(vtkChart.LINE)
        line.SetInputData(table, 0, 1)
        r, g, b = LINE_COLOURS[k % len(LINE_COLOURS)]
        line.SetColor(r, g, b, 255)
        line.SetWidth(2.5)
        line.SetMarkerStyle(4)  # circle
        line.SetMarkerSize(9)

    bottom = chart.GetAxis(vtkAxis.BOTTOM)
    left = chart.GetAxis(vtkAxis.LEFT)
    bottom.SetTitle(args.x)
    left.SetTitle(args.ylabel)
    for axis in (bottom, left):
        axis.GetTitleProperties().SetFontSize(14)
        axis.GetLabelProperties().SetFontSize(13)
        axis.GetTitleProperties().SetColor(0, 0, 0)
        axis.GetLabelProperties().SetColor(0, 0, 0)
    finite = [y for vs in ys.values() for y in vs if not math.isnan(y)]
    lo, hi = min(0.0, min(finite)), max(finite)
    left.SetBehavior(vtkAxis.FIXED)
    left.SetRange(lo, hi + 0.08 * (hi - lo if hi > lo else 1.0))
    if labels is not None:
        positions, names = vtkDoubleArray(), vtkStringArray()
        for x, label in zip(xnum, labels):
            positions.InsertNextValue(x)
            names.InsertNextValue(label)
        bottom.SetCustomTickPositions(positions, names)
        bottom.SetBehavior(vtkAxis.FIXED)
        bottom.SetRange(0.5, len(labels) + 0.5)
    vtk_offscreen.write_png(window, args.output)


def main():
    args = parse_args()
    xnum, labels, ys = read_table(args)
    vtk_offscreen.ensure_display(TOOL)
    vtk_offscreen.import_vtk(TOOL)
    plot(args, xnum, labels, ys)
    print(f"{TOOL}: {args.output}: {len(xnum)} rows, {', '.join(args.y)} against {args.x}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
