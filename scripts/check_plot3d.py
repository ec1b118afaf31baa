#!/usr/bin/env python3
"""Compares a PLOT3D grid written by `qsmesh mesh MODEL -o FILE.xyz` (and its sidecar FILE.xyz.json)
with the block-structured CGNS file of the same run (`-o FILE.cgns --block-structured`, the same
arguments otherwise): block count, dimensions, coordinates (to 1e-12 of the model's size), each
block's family, 1-to-1 interfaces (ranges, donor, transform), free-edge BCs (range, family) and
the runs along left-out faces; and that every interface of the sidecar joins the same coordinates
of the PLOT3D file point by point. The PLOT3D file is read with numpy from the format (the form
and precision the sidecar names), the CGNS file with h5py (CGNS files are HDF5; Debian
python3-numpy and python3-h5py, installed by scripts/setup.sh). Exit 0 when all agree, 1 with the
differences otherwise, 77 when numpy or h5py is missing.
Usage: scripts/check_plot3d.py FILE.xyz FILE.cgns   (with /usr/bin/python3)"""
import json
import sys

try:
    import h5py
    import numpy as np
except ImportError as e:
    print(f"check_plot3d: {e.name} is missing (Debian python3-numpy, python3-h5py)")
    sys.exit(77)


def read_plot3d(path, form, precision):
    """Blocks of a multi-block whole 3D PLOT3D grid: a list of (dims, xyz[3, n])."""
    data = open(path, "rb").read()
    at = 0
    real = np.dtype("<f8" if precision == "double" else "<f4")

    def record(count, dtype):
        nonlocal at
        size = count * dtype.itemsize
        if form == "fortran-unformatted":
            (n,) = np.frombuffer(data, "<i4", 1, at)
            if n != size:
                raise ValueError(f"{path}: record of {n} bytes at {at}, expected {size}")
            at += 4
        values = np.frombuffer(data, dtype, count, at)
        at += size
        if form == "fortran-unformatted":
            (n,) = np.frombuffer(data, "<i4", 1, at)
            if n != size:
                raise ValueError(f"{path}: record ends with {n}, expected {size}")
            at += 4
        return values

    (nb,) = record(1, np.dtype("<i4"))
    dims = record(3 * nb, np.dtype("<i4")).reshape(nb, 3)
    blocks = []
    for d in dims:
        n = int(d[0] * d[1] * d[2])
        blocks.append((tuple(int(x) for x in d), record(3 * n, real).astype(np.float64).reshape(3, n)))
    if at != len(data):
        raise ValueError(f"{path}: {len(data) - at} bytes after the last block")
    return blocks


def text(node):
    return bytes(node[" data"][()]).decode().rstrip("\0")


def label(node):
    return node.attrs["label"].tobytes().decode().rstrip("\0") if "label" in node.attrs else ""


def read_cgns(path):
    """Per structured zone, in zone order: name, dims, xyz[3, n], family, interfaces, BCs, abutments."""
    f = h5py.File(path, "r")
    bases = [f[k] for k in f if isinstance(f[k], h5py.Group) and label(f[k]) == "CGNSBase_t"]
    if len(bases) != 1:
        raise ValueError(f"{path}: {len(bases)} bases")
    base = bases[0]
    zones = []
    for name in sorted(base):  # cgnslib lists zones by name; the writer's names sort as the blocks
        z = base[name]
        if label(z) != "Zone_t" or text(z["ZoneType"]) != "Structured":
            continue
        size = z[" data"][()]  # HDF5 holds the Fortran [2][3] array as (3, 2): vertices first
        dims = (int(size.flat[0]), int(size.flat[1]), 1)
        xyz = np.stack([z["GridCoordinates"][c][" data"][()].reshape(-1)
                        for c in ("CoordinateX", "CoordinateY", "CoordinateZ")])
        zone = {"name": name, "dims": dims, "xyz": xyz, "family": text(z["FamilyName"]),
                "interfaces": [], "boundaries": [], "abutments": []}
        if "ZoneGridConnectivity" in z:
            for c in z["ZoneGridConnectivity"].values():
                rng = [int(x) for x in c["PointRange"][" data"][()].reshape(-1)]
                if label(c) == "GridConnectivity1to1_t":
                    zone["interfaces"].append({
                        "range": rng, "donor_name": text(c),
                        "donor_range": [int(x) for x in c["PointRangeDonor"][" data"][()].reshape(-1)],
                        "transform": [int(x) for x in c["Transform"][" data"][()]]})
                else:
                    zone["abutments"].append(rng)
        if "ZoneBC" in z:
            for bc in z["ZoneBC"].values():
                zone["boundaries"].append(
                    ([int(x) for x in bc["PointRange"][" data"][()].reshape(-1)], text(bc["FamilyName"])))
        zones.append(zone)
    return zones


def flat(r):
    return [r[0][0], r[0][1], r[1][0], r[1][1]]


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    xyz_path, cgns_path = sys.argv[1], sys.argv[2]
    side = json.load(open(xyz_path + ".json"))
    grid = side["grid"]
    blocks = read_plot3d(xyz_path, grid["form"], grid["precision"])
    zones = read_cgns(cgns_path)
    errors = []
    if not (len(blocks) == len(zones) == len(side["blocks"]) == grid["blocks"]):
        errors.append(f"block counts: PLOT3D {len(blocks)}, CGNS {len(zones)}, "
                      f"sidecar {len(side['blocks'])} ({grid['blocks']} in its header)")
    # Coordinates to 1e-12 of the model's size (single precision: to float32's).
    scale = max(1.0, max(float(np.abs(z["xyz"]).max()) for z in zones) if zones else 1.0)
    tol = (1e-12 if grid["precision"] == "double" else 1e-6) * scale
    index = {z["name"]: k for k, z in enumerate(zones)}
    worst = 0.0
    for k, ((dims, xyz), zone, sb) in enumerate(zip(blocks, zones, side["blocks"])):
        where = f"block {k + 1} ({zone['name']})"
        if dims != zone["dims"] or dims != (sb["idim"], sb["jdim"], sb["kdim"]):
            errors.append(f"{where}: dims PLOT3D {dims}, CGNS {zone['dims']}, "
                          f"sidecar {(sb['idim'], sb['jdim'], sb['kdim'])}")
            continue
        worst = max(worst, float(np.abs(xyz - zone["xyz"]).max()))
        if sb["name"] != zone["name"] or sb["family"] != zone["family"]:
            errors.append(f"{where}: sidecar names {sb['name']} / {sb['family']}, CGNS family "
                          f"{zone['family']}")
        got = sorted((flat(i["range"]), i["donor"] - 1, flat(i["donor_range"]), i["transform"])
                     for i in sb["interfaces"])
        want = sorted((i["range"], index.get(i["donor_name"], -1), i["donor_range"], i["transform"])
                      for i in zone["interfaces"])
        if got != want:
            errors.append(f"{where}: interfaces differ: sidecar {got}, CGNS {want}")
        got = sorted((flat(b["range"]), b["family"]) for b in sb["boundaries"])
        want = sorted(zone["boundaries"])
        if got != want:
            errors.append(f"{where}: boundaries differ: sidecar {got}, CGNS {want}")
        got = sorted(flat(a["range"]) for a in sb["against_left_out_faces"])
        if got != sorted(zone["abutments"]):
            errors.append(f"{where}: runs along left-out faces: sidecar {got}, CGNS {sorted(zone['abutments'])}")
    if worst > tol:
        errors.append(f"coordinates differ by up to {worst:g} (tolerance {tol:g})")

    # Every sidecar interface joins the same PLOT3D points, walked in step.
    def points(k, r):
        dims, xyz = blocks[k]
        (i0, j0), (i1, j1) = r
        n = max(abs(i1 - i0), abs(j1 - j0))
        si, sj = np.sign(i1 - i0), np.sign(j1 - j0)
        at = [(j0 - 1 + t * sj) * dims[0] + (i0 - 1 + t * si) for t in range(n + 1)]
        return xyz[:, at]

    joined = 0
    for k, sb in enumerate(side["blocks"]):
        for i in sb["interfaces"]:
            a, b = points(k, i["range"]), points(i["donor"] - 1, i["donor_range"])
            if a.shape != b.shape or np.abs(a - b).max() > tol:
                errors.append(f"block {k + 1}: interface with block {i['donor']} joins different points")
            joined += 1
    for e in errors[:20]:
        print("check_plot3d:", e)
    if errors:
        sys.exit(1)
    print(f"check_plot3d: {len(blocks)} blocks, {sum(b[1].shape[1] for b in blocks)} points, "
          f"{joined} interfaces, {sum(len(b['boundaries']) for b in side['blocks'])} boundaries: "
          f"PLOT3D and CGNS agree (coordinates within {worst:g})")


if __name__ == "__main__":
    main()
