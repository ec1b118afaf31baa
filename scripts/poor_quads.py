#!/usr/bin/env python3
"""Lists the quads below a SICN threshold in a qsmesh MSH 4.1 output (issue 29's diagnosis).

Each poor quad is counted as the statistics count it: `forced` when it touches a CAD corner whose
angle in the quad's face (summed over that face's quads there) is below 8 degrees
(quads_sicn_below_0_1_forced_by_corner), else avoidable. Prints the per-face counts; with
--where, one line per avoidable quad (forced ones too with --all):
  face, SICN, its longest / shortest edge, the nearest CAD corner (its angle in the face, its
  distance), the nearest curve of the face (its length and edge count), and the local width: the
  distance from the point of that curve nearest the quad to the nearest other curve of the face
  that shares no corner with it (a strip's or neck's other side; '-' when none within 10 long
  edges), and the nearest curve that does share a corner (a wedge's other side).
With --ref OTHER.msh (another run of the same model, e.g. main's), the per-face counts of both.

Usage: scripts/poor_quads.py MESH.msh [--threshold 0.1] [--where] [--all] [--ref OTHER.msh]
       [--face F ...]
The SICN is mesh::quad_sicn's (src/mesh/quality.cpp); face and curve ids are the MSH tags, CAD ids
+ 1.
"""
import argparse
import math
import sys

FORCING_CORNER_DEG = 8.0


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(a):
    return math.sqrt(dot(a, a))


def quad_sicn(p):
    """mesh::quad_sicn: the worst corner's 2 (n_i . n) / (|prev|^2 + |next|^2)."""
    ns, denom = [], []
    total = (0.0, 0.0, 0.0)
    for i in range(4):
        prev = sub(p[(i + 3) % 4], p[i])
        nxt = sub(p[(i + 1) % 4], p[i])
        n = cross(nxt, prev)
        ns.append(n)
        denom.append(dot(prev, prev) + dot(nxt, nxt))
        total = (total[0] + n[0], total[1] + n[1], total[2] + n[2])
    length = norm(total)
    if not length > 0:
        return -1.0
    normal = (total[0] / length, total[1] / length, total[2] / length)
    return min(2.0 * dot(ns[i], normal) / denom[i] if denom[i] > 0 else -1.0 for i in range(4))


def angle_deg(p, a, b):
    u, v = sub(a, p), sub(b, p)
    return math.degrees(math.atan2(norm(cross(u, v)), dot(u, v)))


def point_segment(p, a, b):
    ab = sub(b, a)
    l2 = dot(ab, ab)
    s = max(0.0, min(1.0, dot(sub(p, a), ab) / l2)) if l2 > 0 else 0.0
    q = (a[0] + ab[0] * s, a[1] + ab[1] * s, a[2] + ab[2] * s)
    return norm(sub(p, q)), q


class Mesh:
    def __init__(self, path):
        self.points = {}  # node tag -> xyz
        self.node_entity = {}  # node tag -> (dim, tag)
        self.curve_corners = {}  # curve tag -> [corner tags]
        self.face_curves = {}  # face tag -> [curve tags]
        self.quads, self.quad_face = [], []
        self.bars = {}  # curve tag -> [(a, b)]
        with open(path) as f:
            lines = iter(f.read().split("\n"))
        for line in lines:
            if line == "$Entities":
                npts, ncur, nsur, _ = map(int, next(lines).split())
                for _ in range(npts):
                    next(lines)
                for _ in range(ncur):
                    t = next(lines).split()
                    nb = int(t[8])
                    self.curve_corners[int(t[0])] = [abs(int(x)) for x in t[9:9 + nb]]
                for _ in range(nsur):
                    t = next(lines).split()
                    nb = int(t[8])
                    self.face_curves[int(t[0])] = [abs(int(x)) for x in t[9:9 + nb]]
            elif line == "$Nodes":
                blocks = int(next(lines).split()[0])
                for _ in range(blocks):
                    dim, tag, _, count = map(int, next(lines).split())
                    tags = [int(next(lines)) for _ in range(count)]
                    for t in tags:
                        self.points[t] = tuple(map(float, next(lines).split()[:3]))
                        self.node_entity[t] = (dim, tag)
            elif line == "$Elements":
                blocks = int(next(lines).split()[0])
                for _ in range(blocks):
                    dim, tag, etype, count = map(int, next(lines).split())
                    for _ in range(count):
                        ids = list(map(int, next(lines).split()))[1:]
                        if etype == 3:
                            self.quads.append(ids)
                            self.quad_face.append(tag)
                        elif etype == 1:
                            self.bars.setdefault(tag, []).append(tuple(ids))
        # Angle of each face at each CAD corner node: summed over the face's quads there.
        self.corner_angle = {}
        for q, f in zip(self.quads, self.quad_face):
            for k in range(4):
                if self.node_entity[q[k]][0] == 0:
                    a = angle_deg(self.points[q[k]], self.points[q[(k + 1) % 4]],
                                  self.points[q[(k + 3) % 4]])
                    key = (f, q[k])
                    self.corner_angle[key] = self.corner_angle.get(key, 0.0) + a
        self.corner_node = {tag: n for n, (d, tag) in self.node_entity.items() if d == 0}
        self.curve_length = {c: sum(norm(sub(self.points[a], self.points[b])) for a, b in bars)
                             for c, bars in self.bars.items()}

    def sicn(self, i):
        return quad_sicn([self.points[v] for v in self.quads[i]])

    def forced(self, i):
        f = self.quad_face[i]
        return any(self.corner_angle.get((f, v), 360.0) < FORCING_CORNER_DEG
                   for v in self.quads[i] if self.node_entity[v][0] == 0)

    def nearest_on_curve(self, c, p):
        best = (math.inf, None)
        for a, b in self.bars.get(c, []):
            best = min(best, point_segment(p, self.points[a], self.points[b]),
                       key=lambda x: x[0])
        return best

    def where(self, i):
        q = self.quads[i]
        f = self.quad_face[i]
        pts = [self.points[v] for v in q]
        centre = tuple(sum(p[k] for p in pts) / 4 for k in range(3))
        edges = [norm(sub(pts[(k + 1) % 4], pts[k])) for k in range(4)]
        long_edge = max(edges)
        corner = "-"
        face_corners = {k for c in self.face_curves.get(f, [])
                        for k in self.curve_corners.get(c, [])}
        corners = [(norm(sub(self.points[n], centre)), tag)
                   for tag, n in self.corner_node.items() if tag in face_corners]
        if corners:
            d, tag = min(corners)
            a = self.corner_angle.get((f, self.corner_node[tag]))
            corner = (f"corner {tag} ({'?' if a is None else f'{a:.1f}'} deg) at "
                      f"{d:.3g} ({d / long_edge:.2f} L)")
        curves = sorted((self.nearest_on_curve(c, centre)[0], c)
                        for c in self.face_curves.get(f, []) if c in self.bars)
        text = f"face {f} sicn {self.sicn(i):.3f} L {long_edge:.3g} l {min(edges):.3g} {corner}"
        if not curves:
            return text
        d, c = curves[0]
        text += (f" | curve {c} (len {self.curve_length[c]:.3g}, {len(self.bars[c])} edges) "
                 f"at {d:.3g}")
        _, foot = self.nearest_on_curve(c, centre)
        mine = set(self.curve_corners.get(c, []))
        width, wedge = (math.inf, None), (math.inf, None)
        for o in self.face_curves.get(f, []):
            if o == c or o not in self.bars:
                continue
            dist = self.nearest_on_curve(o, foot)[0]
            if mine & set(self.curve_corners.get(o, [])):
                wedge = min(wedge, (dist, o))
            else:
                width = min(width, (dist, o))
        if width[0] < 10 * long_edge:
            text += f" | width {width[0]:.3g} to curve {width[1]} ({width[0] / long_edge:.2f} L)"
        else:
            text += " | width -"
        if wedge[0] < 10 * long_edge:
            text += f" | wedge side curve {wedge[1]} at {wedge[0]:.3g}"
        return text


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mesh")
    ap.add_argument("--threshold", type=float, default=0.1)
    ap.add_argument("--where", action="store_true", help="one line per avoidable poor quad")
    ap.add_argument("--all", action="store_true", help="with --where, the forced ones too")
    ap.add_argument("--ref", help="another run's .msh: per-face counts side by side")
    ap.add_argument("--face", type=int, nargs="+", help="only these faces (MSH tags)")
    a = ap.parse_args()

    def poor(m):
        out = []
        for i in range(len(m.quads)):
            if a.face and m.quad_face[i] not in a.face:
                continue
            s = m.sicn(i)
            if s < a.threshold:
                out.append((i, s, m.forced(i)))
        return out

    m = Mesh(a.mesh)
    mine = poor(m)
    forced = sum(1 for _, _, fo in mine if fo)
    print(f"{a.mesh}: {len(m.quads)} quads, {len(mine)} below SICN {a.threshold} "
          f"({forced} forced by a corner under {FORCING_CORNER_DEG:g} deg, "
          f"{len(mine) - forced} avoidable)")
    per_face = {}
    for i, _, fo in mine:
        if not fo:
            per_face[m.quad_face[i]] = per_face.get(m.quad_face[i], 0) + 1
    ref_face = {}
    if a.ref:
        r = Mesh(a.ref)
        rp = poor(r)
        rf = sum(1 for _, _, fo in rp if fo)
        print(f"{a.ref}: {len(r.quads)} quads, {len(rp)} below ({rf} forced, {len(rp) - rf} "
              f"avoidable)")
        for i, _, fo in rp:
            if not fo:
                ref_face[r.quad_face[i]] = ref_face.get(r.quad_face[i], 0) + 1
    print("avoidable by face:" + ("  face: this / ref" if a.ref else ""))
    for f in sorted(set(per_face) | set(ref_face)):
        print(f"  {f}: {per_face.get(f, 0)}" + (f" / {ref_face.get(f, 0)}" if a.ref else ""))
    if a.where:
        for i, s, fo in sorted(mine, key=lambda x: (m.quad_face[x[0]], x[1])):
            if fo and not a.all:
                continue
            print(("forced " if fo else "") + m.where(i))
    return 0


if __name__ == "__main__":
    sys.exit(main())
