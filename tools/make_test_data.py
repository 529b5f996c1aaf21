#!/usr/bin/env python3
"""Regenerates the test models and lattices of tests/data/ and the demo's data/ (tests/data/README.md).

Standard library only, deterministic: running it again rewrites the same bytes. Everything here is
either built from first principles (cubes, sphere, torus, lattices) or derived from Newell's
public-domain teapot (tests/data/teapot/teapot_newell_original.txt), so the repository carries no file
whose licence does not allow it.

    tools/make_test_data.py            rewrite tests/data/... and data/...
    tools/make_test_data.py --check    exit 1 if any committed file differs from what it would write
"""
import math
import os
import struct
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
TESTS = os.path.join(ROOT, "tests", "data")
DEMO = os.path.join(ROOT, "data")

outputs = {}   # path -> bytes


def emit(path, data):
    outputs[path] = data.encode() if isinstance(data, str) else data


def num(x):
    """Shortest round-trip decimal of a double; integers without a fraction ('1', '-1')."""
    if x == 0:
        return "0"
    if x == int(x) and abs(x) < 1e15:
        return str(int(x))
    return repr(float(x))


def norm(v):
    n = math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    return (v[0] / n, v[1] / n, v[2] / n)


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


# ---------------------------------------------------------------------------------------------------
# Cubes: [-1,1]^3, 8 corners, 12 outward triangles. cube2.obj carries the 6 face normals (every edge a
# crease), cube.obj one smooth normal per corner (the corner direction).

CUBE_V = [(1, -1, 1), (1, -1, -1), (-1, -1, -1), (-1, -1, 1), (1, 1, 1), (1, 1, -1), (-1, 1, -1), (-1, 1, 1)]
# Two triangles per face, counter-clockwise seen from outside, and the face's axis normal.
CUBE_FACES = [((0, 2, 1), (0, 3, 2), (0, -1, 0)), ((0, 7, 3), (0, 4, 7), (0, 0, 1)), ((0, 1, 4), (5, 4, 1), (1, 0, 0)),
              ((5, 1, 6), (2, 6, 1), (0, 0, -1)), ((2, 7, 6), (2, 3, 7), (-1, 0, 0)), ((4, 6, 7), (4, 5, 6), (0, 1, 0))]


def cubes():
    normals = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    head = "".join("v %d %d %d\n" % p for p in CUBE_V)
    s = "# cube [-1,1]^3 with face normals: every edge is a crease (tools/make_test_data.py)\n" + head
    s += "".join("vn %d %d %d\n" % n for n in normals)
    for t1, t2, n in CUBE_FACES:
        k = normals.index(n) + 1
        for t in (t1, t2):
            s += "f " + " ".join("%d//%d" % (i + 1, k) for i in t) + "\n"
    emit(os.path.join(TESTS, "cube2.obj"), s)
    s = "# cube [-1,1]^3 with one smooth normal per corner (tools/make_test_data.py)\n" + head
    s += "".join("vn %d %d %d\n" % p for p in CUBE_V)
    for t1, t2, _ in CUBE_FACES:
        for t in (t1, t2):
            s += "f " + " ".join("%d//%d" % (i + 1, i + 1) for i in t) + "\n"
    emit(os.path.join(TESTS, "cube.obj"), s)


# ---------------------------------------------------------------------------------------------------
# Geodesic sphere: the icosahedron's faces split into f^2 triangles each, points pushed onto the unit
# sphere. Frequency 6: 362 vertices, 720 triangles. Written with v/vt/vn corners (vt: longitude,
# latitude) so that the reader's three-index corners are exercised.

def sphere(freq=6):
    t = (1 + math.sqrt(5)) / 2
    ico = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
           (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
             (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
             (8, 6, 7), (9, 8, 1)]
    verts, index, tris = [], {}, []

    def vid(f, i, j):
        # Grid point (i, j) of face f: corner a + i/f (b - a) + j/f (c - a). Keyed by its exact rational
        # position (sorted corner weights), so that a point on a shared edge is one vertex.
        a, b, c = faces[f]
        w = {a: freq - i - j}
        w[b] = w.get(b, 0) + i
        w[c] = w.get(c, 0) + j
        key = tuple(sorted((k, v) for k, v in w.items() if v))
        if key not in index:
            p = [0.0, 0.0, 0.0]
            for k, v in key:
                for d in range(3):
                    p[d] += v * ico[k][d]
            index[key] = len(verts)
            verts.append(norm(p))
        return index[key]

    for f in range(len(faces)):
        for i in range(freq):
            for j in range(freq - i):
                tris.append((vid(f, i, j), vid(f, i + 1, j), vid(f, i, j + 1)))
                if i + j + 1 < freq:
                    tris.append((vid(f, i + 1, j), vid(f, i + 1, j + 1), vid(f, i, j + 1)))
    assert len(verts) == 10 * freq * freq + 2 and len(tris) == 20 * freq * freq
    s = "# geodesic sphere, icosahedron frequency %d, radius 1 (tools/make_test_data.py)\n" % freq
    s += "".join("v %s %s %s\n" % tuple(num(round(c, 12)) for c in p) for p in verts)
    s += "".join("vt %s %s\n" % (num(round(0.5 + math.atan2(p[1], p[0]) / (2 * math.pi), 9)),
                                 num(round(0.5 + math.asin(max(-1.0, min(1.0, p[2]))) / math.pi, 9))) for p in verts)
    s += "".join("vn %s %s %s\n" % tuple(num(round(c, 12)) for c in p) for p in verts)
    s += "".join("f " + " ".join("%d/%d/%d" % (i + 1, i + 1, i + 1) for i in t) + "\n" for t in tris)
    emit(os.path.join(TESTS, "sphere.obj"), s)


# ---------------------------------------------------------------------------------------------------
# Bumpy torus: the larger smooth closed model (instead of a scanned one). An elliptical ring, 70 x 60
# quads = 8400 triangles, whose tube radius varies with both angles, so its triangles differ in size
# and shape. Written as a UV-mapped mesh: the seam vertices are repeated ('v' lines with the same
# position, 71 x 61 = 4331 of them for 4200 distinct positions), as exporters do; the reader welds them.

def torus(nu=70, nv=60):
    def point(i, j):
        u, v = 2 * math.pi * (i % nu) / nu, 2 * math.pi * (j % nv) / nv
        r = 0.22 * (1 + 0.3 * math.sin(3 * u) * math.cos(2 * v) + 0.15 * math.cos(5 * u + v))
        cx, cy = 0.42 * math.cos(u), 0.78 * math.sin(u)
        # The tube's plane is spanned by the ring's outward normal (in x-y) and z.
        tx, ty = -0.42 * math.sin(u), 0.78 * math.cos(u)
        tl = math.hypot(tx, ty)
        ox, oy = ty / tl, -tx / tl
        return (round(cx + r * math.cos(v) * ox, 12), round(cy + r * math.cos(v) * oy, 12),
                round(r * math.sin(v) + 0.05 * math.sin(2 * u), 12))

    P = {(i, j): point(i, j) for i in range(nu) for j in range(nv)}
    tris = []
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = (i, j), ((i + 1) % nu, j), ((i + 1) % nu, (j + 1) % nv), (i, (j + 1) % nv)
            tris += [(a, b, c), (a, c, d)]
    # Smooth normals: area-weighted sums of the face normals around each distinct position.
    acc = {k: [0.0, 0.0, 0.0] for k in P}
    for t in tris:
        g = cross(sub(P[t[1]], P[t[0]]), sub(P[t[2]], P[t[0]]))
        for k in t:
            for d in range(3):
                acc[k][d] += g[d]
    N = {k: tuple(round(c, 12) for c in norm(v)) for k, v in acc.items()}
    # Written grid: (nu + 1) x (nv + 1), the last row and column repeating the first.
    wid = lambda i, j: i * (nv + 1) + j + 1
    s = "# bumpy elliptical torus, %d x %d quads (tools/make_test_data.py)\n" % (nu, nv)
    grid = [(i, j) for i in range(nu + 1) for j in range(nv + 1)]
    s += "".join("v %s %s %s\n" % tuple(num(c) for c in P[(i % nu, j % nv)]) for i, j in grid)
    s += "".join("vt %s %s\n" % (num(round(i / nu, 9)), num(round(j / nv, 9))) for i, j in grid)
    s += "".join("vn %s %s %s\n" % tuple(num(c) for c in N[(i % nu, j % nv)]) for i, j in grid)
    for i in range(nu):
        for j in range(nv):
            a, b, c, d = wid(i, j), wid(i + 1, j), wid(i + 1, j + 1), wid(i, j + 1)
            for t in ((a, b, c), (a, c, d)):
                s += "f " + " ".join("%d/%d/%d" % (k, k, k) for k in t) + "\n"
    emit(os.path.join(TESTS, "torus.obj"), s)


# ---------------------------------------------------------------------------------------------------
# Teapot. Newell's 32 bicubic patches (public domain, 1-based indices) -> the 36-patch layout of the
# paper's reference implementation: the same patches reordered (lid top, bottom, rim, body upper and
# lower, handle, spout, lid lower), plus 4 flat patches that close the ring between the lid's lower
# edge (radius 1.3) and the rim's inner edge (radius 1.4) at z = 2.4, each row the linear blend of
# those two curves. Control points stay in Newell's order (Su x Sv points inward; the reader turns it).

def newell_patches():
    lines = [l for l in open(os.path.join(TESTS, "teapot", "teapot_newell_original.txt")).read().split("\n") if l.strip()]
    nv = int(lines[0])
    V = [tuple(float(x) for x in l.split(",")) for l in lines[1:1 + nv]]
    n = int(lines[1 + nv])
    return [[V[int(i) - 1] for i in l.split(",")] for l in lines[2 + nv:2 + nv + n]]


REFERENCE_ORDER = [20, 21, 22, 23, 28, 29, 30, 31, 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19,
                   24, 25, 26, 27]


def teapot36():
    N = newell_patches()
    out = [N[i] for i in REFERENCE_ORDER]
    for q in range(4):
        lid, rim = N[24 + q][12:16], N[q][0:4]   # the lid's last row, the rim's first row
        patch = []
        for r in range(4):
            w = r / 3
            patch += [tuple(a[d] + w * (b[d] - a[d]) for d in range(3)) for a, b in zip(lid, rim)]
        out.append(patch)
    return out


def bpt_text(patches):
    s = "%d\n" % len(patches)
    for p in patches:
        s += "3 3\n" + "".join("%s %s %s\n" % tuple(repr(float(c)) for c in q) for q in p)
    return s


def bezier(p, u, v):
    bu = [(1 - u) ** 3, 3 * u * (1 - u) ** 2, 3 * u * u * (1 - u), u ** 3]
    bv = [(1 - v) ** 3, 3 * v * (1 - v) ** 2, 3 * v * v * (1 - v), v ** 3]
    s = [0.0, 0.0, 0.0]
    for r in range(4):
        for c in range(4):
            w = bu[r] * bv[c]
            for d in range(3):
                s[d] += w * p[4 * r + c][d]
    return tuple(s)


def teapot_8x8():
    """Newell's 32 patches, each on a 9 x 9 grid, welded (positions equal to 1e-9), collapsed triangles
    dropped: an open triangle mesh without normals."""
    res = 8
    verts, index, tris = [], {}, []
    for p in newell_patches():
        ids = {}
        for i in range(res + 1):
            for j in range(res + 1):
                x = bezier(p, i / res, j / res)
                key = tuple(round(c * 1e9) for c in x)
                if key not in index:
                    index[key] = len(verts)
                    verts.append(x)
                ids[i, j] = index[key]
        for i in range(res):
            for j in range(res):
                for t in ((ids[i, j], ids[i + 1, j], ids[i, j + 1]), (ids[i + 1, j], ids[i + 1, j + 1], ids[i, j + 1])):
                    if len(set(t)) == 3:
                        tris.append(t)
    s = "# Newell's teapot, 32 patches tessellated 8 x 8 and welded (tools/make_test_data.py)\n"
    s += "".join("v %s %s %s\n" % tuple(num(round(c, 12)) for c in x) for x in verts)
    # Newell's patches have Su x Sv inward: write the triangles turned so that they face outward.
    s += "".join("f %d %d %d\n" % (t[0] + 1, t[2] + 1, t[1] + 1) for t in tris)
    emit(os.path.join(TESTS, "teapot_8x8.obj"), s)


# ---------------------------------------------------------------------------------------------------
# Lattices: float32 .npy arrays (5, 5, 5, 3), point [i][j][k] with i along x, in the .npy convention
# (docs/CLI.md): degree 2, clamped uniform knots over the model's box normalised to a largest
# half-extent of 1. The identity is the Greville points of that box; the deformed ones move them by
# smooth maps written out below.

def npy(points):
    header = "{'descr': '<f4', 'fortran_order': False, 'shape': (5, 5, 5, 3), }"
    header += " " * (63 - len(header)) + "\n"   # 10 + 64 bytes: aligned to 64 as numpy writes it
    data = b"".join(struct.pack("<3f", *p) for p in points)
    return b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode() + data


def greville(lo, hi):
    g = [0.0, 1 / 6, 0.5, 5 / 6, 1.0]   # of the knots 0,0,0,1/3,2/3,1,1,1
    return [(lo[0] + g[i] * (hi[0] - lo[0]), lo[1] + g[j] * (hi[1] - lo[1]), lo[2] + g[k] * (hi[2] - lo[2]))
            for i in range(5) for j in range(5) for k in range(5)]


def normalised_box(points):
    lo = [min(p[d] for p in points) for d in range(3)]
    hi = [max(p[d] for p in points) for d in range(3)]
    c = [(lo[d] + hi[d]) / 2 for d in range(3)]
    half = max((hi[d] - lo[d]) / 2 for d in range(3))
    return [(lo[d] - c[d]) / half for d in range(3)], [(hi[d] - c[d]) / half for d in range(3)]


def twist_bend(p, twist, bend, lean=0.0):
    """Twist about z by `twist` radians per unit z, then bend: x += bend * z^2, and lean: x += lean * y."""
    a = twist * p[2]
    x, y = p[0] * math.cos(a) - p[1] * math.sin(a), p[0] * math.sin(a) + p[1] * math.cos(a)
    return (x + bend * p[2] * p[2] + lean * y, y, p[2])


def lattices(teapot):
    d = os.path.join(TESTS, "lattices")
    cube = greville((-1, -1, -1), (1, 1, 1))
    # A strong twist and bend: every control point not on the z = 0 axis moves.
    emit(os.path.join(d, "cube2_twist.npy"), npy([twist_bend(p, 0.8, 0.35, 0.2) for p in cube]))
    # Only the 9 interior points of the top layer move (up and sideways); the other 116 are the identity.
    top = lambda i, p: (p[0] + 0.3, p[1], p[2] + 0.6) if (i % 5 == 4 and 0 < i // 25 < 4 and 0 < (i // 5) % 5 < 4) else p
    emit(os.path.join(d, "cube2_top.npy"), npy([top(i, p) for i, p in enumerate(cube)]))
    emit(os.path.join(d, "cube_bend.npy"), npy([twist_bend(p, 0.0, 0.5) for p in cube]))
    s = [tuple(float(x) for x in l.split()[1:4]) for l in outputs[os.path.join(TESTS, "sphere.obj")].decode().split("\n")
         if l.startswith("v ")]
    lo, hi = normalised_box(s)
    emit(os.path.join(d, "sphere_twist.npy"), npy([twist_bend(p, 1.0, 0.6) for p in greville(lo, hi)]))
    t = [tuple(float(x) for x in l.split()[1:4]) for l in outputs[os.path.join(TESTS, "torus.obj")].decode().split("\n")
         if l.startswith("v ")]
    lo, hi = normalised_box(t)
    emit(os.path.join(d, "torus_twist.npy"), npy([twist_bend(p, 1.2, 0.4, 0.25) for p in greville(lo, hi)]))
    # The teapot's box is that of its 10 x 10 tessellation (what the reader makes by default).
    pts = [bezier(p, i / 10, j / 10) for p in teapot for i in range(11) for j in range(11)]
    lo, hi = normalised_box(pts)
    g = greville(lo, hi)
    emit(os.path.join(d, "teapot_identity.npy"), npy(g))
    emit(os.path.join(d, "teapot_bend.npy"), npy([twist_bend(p, 0.5, 0.45) for p in g]))
    return lo, hi, g


# ---------------------------------------------------------------------------------------------------
# The demo's model: a coarse hexagonal prism (radius 0.5, height 3, 3 segments along z, flat caps) with
# one normal per face, so every edge between faces is a crease. Coarse on purpose: classic FFD moves
# its 26 vertices and leaves flat facets; smooth FFD bends the faces and keeps the creases sharp.

def prism(sides=6, segs=3, height=3.0, radius=0.5):
    ring = [(radius * math.cos(2 * math.pi * k / sides), radius * math.sin(2 * math.pi * k / sides)) for k in range(sides)]
    V, N, F, idx = [], [], [], {}
    for s in range(segs + 1):
        for k in range(sides):
            V.append((ring[k][0], ring[k][1], -height / 2 + height * s / segs))
            idx[s, k] = len(V)
    for k in range(sides):
        a = 2 * math.pi * (k + 0.5) / sides
        N.append((math.cos(a), math.sin(a), 0.0))
        n = len(N)
        for s in range(segs):
            p00, p10, p11, p01 = idx[s, k], idx[s, (k + 1) % sides], idx[s + 1, (k + 1) % sides], idx[s + 1, k]
            F += [((p00, n), (p10, n), (p11, n)), ((p00, n), (p11, n), (p01, n))]
    N += [(0.0, 0.0, 1.0), (0.0, 0.0, -1.0)]
    V += [(0.0, 0.0, height / 2), (0.0, 0.0, -height / 2)]
    top, bottom, ct, cb = len(N) - 1, len(N), len(V) - 1, len(V)
    for k in range(sides):
        F.append(((ct, top), (idx[segs, k], top), (idx[segs, (k + 1) % sides], top)))
        F.append(((cb, bottom), (idx[0, (k + 1) % sides], bottom), (idx[0, k], bottom)))
    s = "# coarse hexagonal prism with face normals: every edge is a crease (tools/make_test_data.py)\n"
    s += "".join("v %s %s %s\n" % tuple(num(round(c, 12)) for c in p) for p in V)
    s += "".join("vn %s %s %s\n" % tuple(num(round(c, 12)) for c in p) for p in N)
    s += "".join("f " + " ".join("%d//%d" % c for c in f) + "\n" for f in F)
    emit(os.path.join(DEMO, "prism.obj"), s)


def main():
    cubes()
    sphere()
    torus()
    tp = teapot36()
    emit(os.path.join(TESTS, "teapot.bpt"), bpt_text(tp))
    teapot_8x8()
    lattices(tp)
    # The demo's data (scripts/demo.sh) lives beside the program, not the tests.
    prism()
    emit(os.path.join(DEMO, "teapot.bpt"), bpt_text(tp))
    emit(os.path.join(DEMO, "teapot_lattice.npy"), outputs[os.path.join(TESTS, "lattices", "teapot_bend.npy")])
    check = "--check" in sys.argv[1:]
    stale = []
    for path, data in sorted(outputs.items()):
        old = open(path, "rb").read() if os.path.exists(path) else None
        if old != data:
            stale.append(os.path.relpath(path, ROOT))
            if not check:
                os.makedirs(os.path.dirname(path), exist_ok=True)
                open(path, "wb").write(data)
    if check and stale:
        print("out of date: " + " ".join(stale))
        return 1
    for s in stale:
        print("wrote " + s)
    return 0


if __name__ == "__main__":
    sys.exit(main())
