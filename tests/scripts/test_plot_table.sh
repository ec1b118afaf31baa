#!/usr/bin/env bash
# ctest: scripts/plot_table.py draws a table with a text x column (as scripts/scaling_study.sh
# --png does) and a numeric one, and refuses a missing column (exit 2). Exit 77 (skipped) only
# when VTK's Python module (Debian python3-vtk9) is absent.
# Usage: test_plot_table.sh SOURCE_DIR WORK_DIR
set -euo pipefail
src=$1 work=$2
py=/usr/bin/python3
if ! "$py" -c "import vtkmodules.vtkChartsCore" 2>/dev/null; then
  echo "SKIP: VTK's Python module is absent (Debian python3-vtk9; scripts/setup.sh installs it)"
  exit 77
fi
mkdir -p "$work"
cd "$work"
rm -f table.csv text_x.png numeric_x.png
cat > table.csv <<'CSV'
ranks x threads,cores,speedup,efficiency
1x1,1,1.00,1.00
1x2,2,1.71,0.86
2x1,2,1.80,0.90
2x2,4,n/a,
4x1 (oversubscribed),4,2.10,0.53
CSV
"$py" "$src/scripts/plot_table.py" table.csv -o text_x.png --x "ranks x threads" --y speedup,efficiency \
  --title "test" --size 600x400
"$py" "$src/tests/scripts/check_png.py" text_x.png --size 600x400 --min-colours 10 --min-drawn 0.01
"$py" "$src/scripts/plot_table.py" table.csv -o numeric_x.png --x cores --y speedup --size 600x400
"$py" "$src/tests/scripts/check_png.py" numeric_x.png --size 600x400 --min-colours 10 --min-drawn 0.01
rc=0
"$py" "$src/scripts/plot_table.py" table.csv -o missing.png --x cores --y walltime 2>err.txt || rc=$?
if [ "$rc" -ne 2 ] || ! grep -q "no column 'walltime'" err.txt || [ -e missing.png ]; then
  echo "plot_table.py: a missing column should stop with exit 2 and no picture (got $rc)" >&2
  cat err.txt >&2
  exit 1
fi
echo "plot_table test passed"
