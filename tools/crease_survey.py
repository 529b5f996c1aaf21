#!/usr/bin/env python3
"""Crease survey (issue 12 item 8): per mesh, the dihedral angles of its edges and how many of them each
candidate crease rule marks, to choose and document the default for meshes without normals.

usage: tools/crease_survey.py [--write-gen DIR] [--hist] MESH...
Prints a Markdown table: triangles, edges, edges where the winding flips, the median and 90th percentile
dihedral angle (degrees between face normals), and the creases under a fixed --crease-angle of 40, 60,
70 and 80 and under the default rule (auto), counted as sffd does (edges that split a vertex).
MESH: an OBJ or OFF file (normals ignored: the rule is for meshes without them), or a generated shape
gen:box, gen:prism, gen:cylinder:N, gen:uvsphere:N, gen:icosphere:L, gen:torus:N, gen:tetra, gen:octa.
Vertices are welded by exact position, as sffd does. Python 3, standard library only.
"""
import math
import sys

LOOSE = 40.0    # the old fixed default; the relative rule never marks an edge below it
SHARP = 80.0    # at or above it an edge is always a crease
RATIO = 3.0     # how many times its crossing edges' largest angle an edge must reach to stand out


def read_mesh(path):
    V, F = [], []
    if path.lower().endswith(".off"):
        tok = [t for line in open(path) for t in line.split("#")[0].split()]
        assert tok[0].upper().endswith("OFF")
        nv, nf = int(tok[1]), int(tok[2])
        p = 4
        for _ in range(nv):
            V.append(tuple(float(x) for x in tok[p:p + 3]))
            p += 3
        for _ in range(nf):
            k = int(tok[p])
            idx = [int(x) for x in tok[p + 1:p + 1 + k]]
            p += 1 + k
            F += [(idx[0], idx[i], idx[i + 1]) for i in range(1, k - 1)]
        return V, F
    for line in open(path):
        s = line.split()
        if not s:
            continue
        if s[0] == "v":
            V.append(tuple(float(x) for x in s[1:4]))
        elif s[0] == "f":
            idx = [int(c.split("/")[0]) for c in s[1:]]
            idx = [i - 1 if i > 0 else len(V) + i for i in idx]
            F += [(idx[0], idx[i], idx[i + 1]) for i in range(1, len(idx) - 1)]
    return V, F


# ---- generated shapes: CAD-like parts and coarse smooth ones -------------------------------------------

def grid_faces(rows, cols, idx, wrap_cols=True, wrap_rows=False):
    F = []
    for i in range(rows if wrap_rows else rows - 1):
        for j in range(cols if wrap_cols else cols - 1):
            a, b = idx(i, j), idx(i, (j + 1) % cols)
            c, d = idx((i + 1) % rows, (j + 1) % cols), idx((i + 1) % rows, j)
            F += [(a, b, c), (a, c, d)]
    return F


def gen(name):
    kind, _, arg = name[4:].partition(":")
    n = int(arg) if arg else 0
    if kind == "box":   # 2 x 1 x 0.5, every face split 2 x 2 (flat interior edges, as CAD exports have)
        V, F, key = [], [], {}
        def vid(p):
            if p not in key:
                key[p] = len(V)
                V.append(p)
            return key[p]
        size = (1.0, 0.5, 0.25)
        for ax in range(3):
            for sgn in (-1, 1):
                u, v = (ax + 1) % 3, (ax + 2) % 3
                def P(i, j):
                    p = [0.0] * 3
                    p[ax] = sgn * size[ax]
                    p[u] = size[u] * (i - 1)
                    p[v] = size[v] * (j - 1)
                    return vid(tuple(p))
                for i in range(2):
                    for j in range(2):
                        q = [P(i, j), P(i + 1, j), P(i + 1, j + 1), P(i, j + 1)]
                        if sgn < 0:
                            q.reverse()
                        F += [(q[0], q[1], q[2]), (q[0], q[2], q[3])]
        return V, F
    if kind in ("prism", "cylinder"):   # prism: tools/make_test_data.py's, 6 sides, 3 segments
        sides, segs = (6, 3) if kind == "prism" else (n, 2)
        V = [(0.5 * math.cos(2 * math.pi * k / sides), 0.5 * math.sin(2 * math.pi * k / sides), -1.5 + 3.0 * s / segs)
             for s in range(segs + 1) for k in range(sides)]
        F = grid_faces(segs + 1, sides, lambda s, k: s * sides + k)
        V += [(0.0, 0.0, 1.5), (0.0, 0.0, -1.5)]
        ct, cb = len(V) - 2, len(V) - 1
        for k in range(sides):
            F += [(ct, segs * sides + k, segs * sides + (k + 1) % sides), (cb, (k + 1) % sides, k)]
        return V, F
    if kind == "uvsphere":   # n segments around, n/2 rings
        rings = n // 2
        V = [(0.0, 0.0, 1.0)]
        for r in range(1, rings):
            th = math.pi * r / rings
            V += [(math.sin(th) * math.cos(2 * math.pi * k / n), math.sin(th) * math.sin(2 * math.pi * k / n), math.cos(th))
                  for k in range(n)]
        V.append((0.0, 0.0, -1.0))
        F = grid_faces(rings - 1, n, lambda r, k: 1 + r * n + k)
        for k in range(n):
            F += [(0, 1 + (k + 1) % n, 1 + k), (len(V) - 1, 1 + (rings - 2) * n + k, 1 + (rings - 2) * n + (k + 1) % n)]
        return V, F
    if kind == "torus":   # n x n quads, R = 1, r = 0.4
        V = [((1 + 0.4 * math.cos(2 * math.pi * j / n)) * math.cos(2 * math.pi * i / n),
              (1 + 0.4 * math.cos(2 * math.pi * j / n)) * math.sin(2 * math.pi * i / n), 0.4 * math.sin(2 * math.pi * j / n))
             for i in range(n) for j in range(n)]
        return V, grid_faces(n, n, lambda i, j: i * n + j, True, True)
    if kind in ("icosphere", "tetra", "octa"):
        if kind == "tetra":
            V = [(1, 1, 1), (1, -1, -1), (-1, 1, -1), (-1, -1, 1)]
            return [tuple(float(c) for c in p) for p in V], [(0, 1, 2), (0, 3, 1), (0, 2, 3), (1, 3, 2)]
        if kind == "octa":
            V = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
            F = [(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5), (0, 3, 5)]
            return [tuple(float(c) for c in p) for p in V], F
        t = (1 + 5 ** 0.5) / 2
        V = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
        F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
             (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
             (8, 6, 7), (9, 8, 1)]
        V = [norm(p) for p in V]
        for _ in range(n):
            mid, F2 = {}, []
            def m(a, b):
                k = (min(a, b), max(a, b))
                if k not in mid:
                    mid[k] = len(V)
                    V.append(norm(tuple((x + y) / 2 for x, y in zip(V[a], V[b]))))
                return mid[k]
            for a, b, c in F:
                ab, bc, ca = m(a, b), m(b, c), m(c, a)
                F2 += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
            F = F2
        return V, F
    raise SystemExit("unknown generated shape " + name)


def norm(p):
    l = math.sqrt(sum(c * c for c in p))
    return tuple(c / l for c in p)


def write_obj(path, V, F, what):
    with open(path, "w") as f:
        f.write("# %s (tools/crease_survey.py): positions and triangles, no normals\n" % what)
        f.writelines("v %.9g %.9g %.9g\n" % p for p in V)
        f.writelines("f %d %d %d\n" % (a + 1, b + 1, c + 1) for a, b, c in F)


# ---- the survey ------------------------------------------------------------------------------------------

def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def dihedrals(V, F):
    """Per manifold interior edge (key: welded vertex pair): its dihedral angle in degrees and its crossing
    edges (the other two edges of each of its two triangles)."""
    weld, W = {}, []
    for p in V:
        W.append(weld.setdefault(p, len(weld)))
    tris, normals = [], []
    for t in F:
        a, b, c = (W[i] for i in t)
        if a == b or b == c or c == a:
            continue
        n = cross(sub(V[t[1]], V[t[0]]), sub(V[t[2]], V[t[0]]))
        l = math.sqrt(sum(x * x for x in n))
        if not l > 0:
            continue
        tris.append((a, b, c))
        normals.append(tuple(x / l for x in n))
    edges, forward = {}, {}
    for ti, (a, b, c) in enumerate(tris):
        for u, v in ((a, b), (b, c), (c, a)):
            edges.setdefault((min(u, v), max(u, v)), []).append(ti)
            forward.setdefault((min(u, v), max(u, v)), []).append(u < v)
    angle = {}
    for e, ts in edges.items():
        if len(ts) != 2:
            continue
        n1, n2 = normals[ts[0]], normals[ts[1]]
        s = math.sqrt(sum(x * x for x in cross(n1, n2)))
        angle[e] = math.degrees(math.atan2(s, sum(x * y for x, y in zip(n1, n2))))
    crossing = {}
    for e, ts in edges.items():
        if e not in angle:
            continue
        cr = []
        for ti in ts:
            a, b, c = tris[ti]
            for u, v in ((a, b), (b, c), (c, a)):
                k = (min(u, v), max(u, v))
                if k != e:
                    cr.append(k)
        crossing[e] = cr
    # Edges both triangles run the same way: the winding flips there, and so does one face normal (the
    # angle reads 180 minus the true one: a crease under any rule).
    flipped = sum(1 for e in angle if forward[e][0] == forward[e][1])
    return len(tris), len(edges), angle, crossing, flipped, (tris, edges)


def effective(marked, topo):
    """The marked edges that split a vertex, as sffd counts creases (`sffd clip --stats`: crease_edges):
    an edge marked inside one smoothing fan (its endpoints joined around it by unmarked edges) has no
    effect."""
    tris, edges = topo
    parent = {}
    def find(x):
        while parent.setdefault(x, x) != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x
    for e, ts in edges.items():
        if len(ts) == 2 and e not in marked:
            for v in e:
                parent[find((ts[0], v))] = find((ts[1], v))
    return sum(1 for e, ts in edges.items() if len(ts) == 2 and e in marked and
               any(find((ts[0], v)) != find((ts[1], v)) for v in e))


def relative_rule(angle, crossing, loose=LOOSE, sharp=SHARP, ratio=RATIO):
    """The rule of sffd's default, `--crease-angle auto` (applyCreaseAuto): an edge is a crease when its
    dihedral angle is at least `sharp`, or above `loose` and at least `ratio` times the angle of each of its
    crossing edges that is below `sharp` (boundary and non-manifold ones count as 0). A crease between
    flat faces passes; so does one that meets other creases; a coarse tessellation of a curved surface,
    whose neighbouring edges bend too, does not."""
    out = set()
    for e, th in angle.items():
        if th >= sharp:
            out.add(e)
        elif th > loose:
            cr = crossing[e]
            if all(ratio * x <= th or x >= sharp for x in (angle.get(k, 0.0) for k in cr)):
                out.add(e)
    return out


def main(argv):
    write_dir, hist = None, False
    paths = []
    it = iter(argv)
    for a in it:
        if a == "--write-gen":
            write_dir = next(it)
        elif a == "--hist":
            hist = True
        else:
            paths.append(a)
    if not paths:
        raise SystemExit(__doc__)
    fixed = (40, 60, 70, 80)
    head = ["mesh", "triangles", "edges", "flipped", "median", "p90"] + ["> %d" % t for t in fixed] + ["auto"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for p in paths:
        if p.startswith("gen:"):
            V, F = gen(p)
            name = p[4:]
            if write_dir:
                write_obj("%s/%s.obj" % (write_dir, name.replace(":", "")), V, F, p)
        else:
            V, F = read_mesh(p)
            name = p.rsplit("/", 1)[-1]
        T, E, angle, crossing, flipped, topo = dihedrals(V, F)
        a = sorted(angle.values())
        q = lambda f: a[min(len(a) - 1, int(f * len(a)))] if a else 0.0
        cells = [name, str(T), str(E), str(flipped), "%.0f" % q(0.5), "%.0f" % q(0.9)]
        for t in fixed:
            cells.append(str(effective({e for e, x in angle.items() if x > t}, topo)))
        cells.append(str(effective(relative_rule(angle, crossing), topo)))
        print("| " + " | ".join(cells) + " |")
        if hist:
            bins = [0] * 18
            for x in a:
                bins[min(17, int(x // 10))] += 1
            print("  hist (10-degree bins):", " ".join(str(b) for b in bins))


if __name__ == "__main__":
    main(sys.argv[1:])
