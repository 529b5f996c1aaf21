#!/usr/bin/env python3
"""Writes the robustness corpus of sffd (tests/data/bad/README.md lists every file and its origin).

    python3 tests/data/bad/generate.py        # rewrites the files beside this script; deterministic

Files directly in this folder must be refused by `sffd deform` (exit 2, one error line naming the
file); files in odd/ are odd but valid and must be processed. Big inputs (a 100,000-character line,
a 5-million-triangle mesh) are made by the tests and tools at run time, not kept here.
odd/cube.om is not written here: it was written once by OpenMesh (README.md says how); nor is
odd/fuzz_om_nan_normal.om, found by fuzz_mesh_binary.
"""
import math
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
ODD = os.path.join(HERE, "odd")


def put(name, data, folder=HERE):
    if isinstance(data, str):
        data = data.encode("utf-8")
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


TRI_OBJ = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
CUBE_V = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]
CUBE_F = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]


def obj(verts, faces, extra=""):
    s = "".join("v %r %r %r\n" % v for v in verts)
    return s + extra + "".join("f " + " ".join(str(i + 1) for i in f) + "\n" for f in faces)


def off(verts, faces):
    s = "OFF\n%d %d 0\n" % (len(verts), len(faces))
    s += "".join("%r %r %r\n" % v for v in verts)
    return s + "".join("%d %s\n" % (len(f), " ".join(map(str, f))) for f in faces)


def stl_binary(tris, header=b"sffd robustness corpus", count=None):
    h = header.ljust(80, b"\0")[:80]
    out = h + struct.pack("<I", len(tris) if count is None else count)
    for t in tris:
        out += struct.pack("<3f", 0, 0, 0)
        for p in t:
            out += struct.pack("<3f", *p)
        out += b"\0\0"
    return out


def ply_binary(verts, faces, index_type="i", declared_faces=None):
    n = len(faces) if declared_faces is None else declared_faces
    head = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
            "property float z\nelement face %d\nproperty list uchar %s vertex_indices\nend_header\n"
            % (len(verts), n, {"i": "int", "I": "uint"}[index_type])).encode()
    body = b"".join(struct.pack("<3f", *v) for v in verts)
    body += b"".join(struct.pack("<B%d%s" % (len(f), index_type), len(f), *f) for f in faces)
    return head + body


def npy(shape, values, descr="<f8"):
    header = "{'descr': '%s', 'fortran_order': False, 'shape': (%s), }" % (descr, ", ".join(map(str, shape)))
    pad = 64 - (10 + len(header) + 1) % 64
    header = header + " " * pad + "\n"
    out = b"\x93NUMPY\x01\x00" + struct.pack("<H", len(header)) + header.encode()
    return out + struct.pack("<%d%s" % (len(values), {"<f8": "d", "<f4": "f", "<i8": "q"}[descr]), *values)


def identity_points(counts, lo=(-1, -1, -1), hi=(1, 1, 1), degree=(2, 2, 2)):
    """Greville points of clamped uniform knots (the identity lattice), (i*cv + j)*cw + k order."""
    axes = []
    for a in range(3):
        n, p = counts[a], degree[a]
        spans = n - p
        knots = [0.0] * (p + 1) + [i / spans for i in range(1, spans)] + [1.0] * (p + 1)
        xi = [sum(knots[i + 1:i + p + 1]) / p for i in range(n)]
        axes.append([lo[a] + (hi[a] - lo[a]) * x for x in xi])
    return [[axes[0][i], axes[1][j], axes[2][k]] for i in range(counts[0]) for j in range(counts[1]) for k in range(counts[2])]


def lattice_json(counts=(3, 3, 3), degree=(2, 2, 2), lo=(-1, -1, -1), hi=(1, 1, 1), points=None, extra="", knots=None):
    s = '{\n  "format": "sffd-lattice", "version": 1,\n'
    s += '  "degree": [%d, %d, %d],\n  "counts": [%d, %d, %d],\n' % (tuple(degree) + tuple(counts))
    s += '  "box": {"min": [%r, %r, %r], "max": [%r, %r, %r]},\n' % (tuple(lo) + tuple(hi))
    if knots is not None:
        s += '  "knots": {"u": %s, "v": [], "w": []},\n' % knots
    s += extra
    if points is None:
        points = identity_points(counts, lo, hi, degree)
    s += '  "control_points": [\n' + ",\n".join("    [%s, %s, %s]" % tuple(
        p if isinstance(p, str) else repr(float(p)) for p in q) for q in points) + "\n  ]\n}\n"
    return s


PRM_BOX = """[Box info]
n control points x: 2
n control points y: 2
n control points z: 2
box length x: 1.0
box length y: 1.0
box length z: 1.0
box origin x: 0.0
box origin y: 0.0
box origin z: 0.0
rotation angle x: 0
rotation angle y: 0
rotation angle z: 0
"""
PRM_WEIGHTS = """[Parameters weights]
parameter x: 0 0 0 0.0
parameter y: 0 0 0 0.0
parameter z: 0 0 0 0.0
"""


def refused():
    # --- meshes: nothing to read, broken indices -------------------------------------------------
    put("empty.obj", "")
    put("only_vertices.obj", "# three vertices and no face\n" + TRI_OBJ)
    put("only_vertices.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n")
    put("index_out_of_range.obj", TRI_OBJ + "f 1 2 4\n")
    put("index_negative.obj", TRI_OBJ + "f -1 -2 -4\n")
    put("index_zero.obj", TRI_OBJ + "f 0 1 2\n")
    put("index_huge.obj", TRI_OBJ + "f 1 2 99999999999999999999\n")
    put("index_out_of_range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n")
    put("index_negative.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n")
    put("index_out_of_range.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
    put("index_negative_binary.ply", ply_binary([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, -1)]))
    put("face_two_corners.obj", TRI_OBJ + "f 1 2\n")
    # --- counts in a header far larger than the file (must not allocate them) -------------------
    put("huge_face_count.off", "OFF\n3 2000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    put("huge_vertex_count.off", "OFF\n4000000000 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    put("huge_face_count.ply", ply_binary([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)], declared_faces=4000000000))
    put("huge_count.stl", stl_binary([[(0, 0, 0), (1, 0, 0), (0, 1, 0)]], count=0xFFFFFFFF))
    om = open(os.path.join(ODD, "cube.om"), "rb").read()
    put("huge_vertex_count.om", om[:4] + struct.pack("<I", 0x7FFFFFFF) + om[8:])
    # --- truncated files ------------------------------------------------------------------------
    cube_tris = [[CUBE_V[f[0]], CUBE_V[f[1]], CUBE_V[f[2]]] for f in CUBE_F] + \
                [[CUBE_V[f[0]], CUBE_V[f[2]], CUBE_V[f[3]]] for f in CUBE_F]
    whole = ply_binary(CUBE_V, CUBE_F)
    put("truncated_binary.ply", whole[:len(whole) - 7])
    whole = stl_binary(cube_tris)
    put("truncated_binary.stl", whole[:84 + 50 * 5 + 20])
    whole = stl_binary(cube_tris, header=b"solid cube, but binary: many exporters write this")
    put("truncated_solid_header.stl", whole[:84 + 50 * 5 + 20])
    put("truncated_ascii.stl", "solid t\n  facet normal 0 0 1\n    outer loop\n      vertex 0 0 0\n      vertex 1 0 0\n")
    put("truncated.om", om[:len(om) // 2])
    put("truncated.off", off(CUBE_V, CUBE_F)[:-12])
    put("truncated.bpt", "1\n3 3\n" + "0 0 0\n" * 9)
    # --- non-finite and unreadable numbers ------------------------------------------------------
    put("nan_coordinate.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")
    put("inf_coordinate.off", "OFF\n3 1 0\n0 0 0\n1 inf 0\n0 1 0\n3 0 1 2\n")
    put("overflow_coordinate.obj", "v 0 0 0\nv 1e400 0 0\nv 0 1 0\nf 1 2 3\n")
    put("nan_coordinate.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 NaN\n0 1 0\n3 0 1 2\n")
    put("nan_coordinate_binary.stl", stl_binary([[(0, 0, 0), (float("nan"), 0, 0), (0, 1, 0)]]))
    put("inf_coordinate_ascii.stl", "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
        "vertex 0 -inf 0\nendloop\nendfacet\nendsolid t\n")
    put("decimal_comma.obj", "v 0,5 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    # --- wrong encodings and not-a-mesh ---------------------------------------------------------
    put("utf16le.obj", b"\xff\xfe" + (TRI_OBJ + "f 1 2 3\n").encode("utf-16-le"))
    put("utf16be.off", b"\xfe\xff" + off([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [(0, 1, 2)]).encode("utf-16-be"))
    put("binary_junk.obj", bytes((i * 151 + 7) % 256 for i in range(512)))
    put("png_named.ply", b"\x89PNG\r\n\x1a\n" + bytes(64))
    put("not_off.off", "COFF? no\n")
    put("no_end_header.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n")
    put("unknown_format.xyz", TRI_OBJ)
    # --- lattices ------------------------------------------------------------------------------
    pts = identity_points((3, 3, 3))
    put("lattice_wrong_point_count.json", lattice_json(points=pts[:-1]))
    put("lattice_degree_ge_counts.json", lattice_json(counts=(3, 3, 3), degree=(3, 2, 2), points=[]))
    put("lattice_degree_too_high.json", lattice_json(counts=(8, 3, 3), degree=(6, 2, 2), points=[]))
    put("lattice_knots_non_monotone.json", lattice_json(knots="[-1, -1, -1, 0.5, 0, 1, 1, 1]", counts=(5, 3, 3),
                                                        points=identity_points((5, 3, 3))))
    put("lattice_knots_too_short.json", lattice_json(knots="[-1, -1, -1, 1, 1]", counts=(5, 3, 3),
                                                     points=identity_points((5, 3, 3))))
    put("lattice_zero_size_box.json", lattice_json(lo=(-1, -1, 0), hi=(1, 1, 0), points=[]))
    put("lattice_inverted_box.json", lattice_json(lo=(1, -1, -1), hi=(-1, 1, 1), points=[]))
    nanpts = [list(map(repr, p)) for p in pts]
    nanpts[13][1] = "NaN"   # what Python's json.dump writes for float('nan')
    put("lattice_nan_control_point.json", lattice_json(points=nanpts))
    infpts = [list(map(repr, p)) for p in pts]
    infpts[4][0] = "1e999"
    put("lattice_overflow_control_point.json", lattice_json(points=infpts))
    put("lattice_huge_counts.json", lattice_json(counts=(4096, 4096, 4096), points=[]))
    put("lattice_truncated.json", lattice_json()[:200])
    put("lattice_missing_format.json", '{"version": 1, "degree": [1, 1, 1], "counts": [2, 2, 2],'
        ' "box": {"min": [0, 0, 0], "max": [1, 1, 1]}}\n')
    put("lattice_unknown_field.json", '{"format": "sffd-lattice", "version": 1, "degree": [1, 1, 1], "counts": [2, 2, 2],\n'
        ' "box": {"min": [0, 0, 0], "max": [1, 1, 1]},\n "controlpoints": []}\n')
    put("lattice_key_with_newline.json", '{"format": "sffd-lattice", "version": 1, "degree": [1, 1, 1], "counts": [2, 2, 2],\n'
        ' "box": {"min": [0, 0, 0], "max": [1, 1, 1]},\n "control\\npoints": []}\n')
    put("lattice_missing_box_info.prm", PRM_WEIGHTS)
    put("lattice_missing_weights.prm", PRM_BOX)
    put("lattice_missing_key.prm", PRM_BOX.replace("box length y: 1.0\n", "") + PRM_WEIGHTS)
    put("lattice_zero_length.prm", PRM_BOX.replace("box length z: 1.0", "box length z: 0.0") + PRM_WEIGHTS)
    put("lattice_nan_weight.prm", PRM_BOX + PRM_WEIGHTS.replace("parameter y: 0 0 0 0.0", "parameter y: 0 0 0 nan"))
    put("lattice_index_out_of_range.prm", PRM_BOX + PRM_WEIGHTS.replace("parameter z: 0 0 0 0.0", "parameter z: 0 2 0 0.1"))
    put("lattice_too_many_points.prm", PRM_BOX.replace("n control points x: 2", "n control points x: 7") + PRM_WEIGHTS)
    put("lattice_empty.prm", "")
    grid = [c for p in identity_points((3, 3, 3)) for c in p]
    put("lattice_truncated.npy", npy((3, 3, 3, 3), grid)[:-40])
    bad = list(grid)
    bad[5] = float("nan")
    put("lattice_nan.npy", npy((3, 3, 3, 3), bad))
    put("lattice_wrong_shape.npy", npy((27, 3), grid))
    put("lattice_huge_shape.npy", npy((4096, 4096, 4096, 3), grid[:3]))
    put("lattice_int_dtype.npy", npy((3, 3, 3, 3), [int(abs(x)) for x in grid], descr="<i8"))
    put("lattice_bad_header.npy", b"\x93NUMPY\x01\x00\x20\x00{'descr': '<f8', 'shape': (3, 3\n" + bytes(8))


def odd():
    # Odd but valid meshes: processed, not refused.
    tet = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
    # Three triangles on the edge 1-2 (a non-manifold "book"), plus a fourth page.
    put("nonmanifold_edge.obj", obj([(0, 0, 0), (0, 0, 1), (1, 0, 0), (-1, 0, 0.5), (0, 1, 0.5), (0, -1, 0.5)],
                                    [(0, 1, 2), (0, 1, 3), (0, 1, 4), (1, 0, 5)]), ODD)
    # Two cubes sharing only a vertex (a non-manifold vertex), and two components.
    v2 = CUBE_V + [(x + 1, y + 1, z + 1) for (x, y, z) in CUBE_V]
    f2 = CUBE_F + [tuple(i + 8 for i in f) for f in CUBE_F]
    put("two_cubes_touching.off", off(v2, f2), ODD)
    # Zero-area triangles: collinear corners, a repeated corner, all corners equal; and a duplicate.
    put("degenerate_triangles.obj", obj(tet + [(2, 0, 0), (0.5, 0, 0)],
                                        [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3), (0, 1, 4), (0, 0, 1), (2, 2, 2),
                                         (1, 2, 3)]), ODD)
    put("duplicate_triangles.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
        "property double z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n3 1 2 3\n3 3 2 1\n", ODD)
    put("isolated_vertices.obj", "v 5 5 5\n" + obj(tet, [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]) + "v -3 2 1\n", ODD)
    # Open boundaries: one triangle; a cube without its top.
    put("single_triangle.stl", "solid one\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
        "   vertex 0 1 0\n  endloop\n endfacet\nendsolid one\n", ODD)
    put("open_box.obj", obj(CUBE_V, [f for f in CUBE_F if f != (4, 5, 7, 6)]), ODD)
    # Polygons of many sides: a 1000-gon (OBJ, fan-triangulated) and a 24-gon prism (OFF).
    n = 1000
    ring = [(math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n), 0.0) for i in range(n)]
    put("polygon_1000.obj", obj(ring + [(0.0, 0.0, 1.0)], [tuple(range(n))] +
                                [(i, (i + 1) % n, n) for i in range(n)]), ODD)
    m = 24
    prism = [(math.cos(2 * math.pi * i / m), math.sin(2 * math.pi * i / m), z) for z in (0.0, 1.0) for i in range(m)]
    faces = [tuple(reversed(range(m))), tuple(range(m, 2 * m))] + [(i, (i + 1) % m, m + (i + 1) % m, m + i) for i in range(m)]
    put("prism_24.off", off(prism, faces), ODD)
    # Text oddities: UTF-8 byte-order mark and CRLF line ends; zero normals (recomputed); comments.
    put("bom_crlf.obj", b"\xef\xbb\xbf" + ("# made on Windows\r\n" + TRI_OBJ.replace("\n", "\r\n") +
                                          "v 0 0 1\r\nf 1 3 2\r\nf 1 2 4\r\nf 1 4 3\r\nf 2 3 4\r\n").encode(), ODD)
    put("zero_normals.obj", obj(tet, [], "vn 0 0 0\n") + "f 1//1 3//1 2//1\nf 1//1 2//1 4//1\nf 1//1 4//1 3//1\nf 2//1 3//1 4//1\n", ODD)
    # File normals with a NaN or an infinite component next to finite ones, a denormal and a huge one:
    # recomputed or rescaled, never NaN (fuzz_mesh_binary found the NaN case in an .om file).
    put("odd_normals.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
        "property float z\nproperty double nx\nproperty double ny\nproperty double nz\nelement face 4\n"
        "property list uchar int vertex_indices\nend_header\n"
        "0 0 0 1 nan 0\n1 0 0 inf 0 0\n0 1 0 0 1e-310 0\n0 0 1 1e300 1e300 1e300\n"
        "3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n", ODD)
    # A binary STL whose 80-byte header starts with "solid" (many exporters write this).
    tris = [[tet[0], tet[2], tet[1]], [tet[0], tet[1], tet[3]], [tet[0], tet[3], tet[2]], [tet[1], tet[2], tet[3]]]
    put("solid_header_binary.stl", stl_binary(tris, header=b"solid tetra exported as binary"), ODD)
    # A mesh reaching outside the box of lattice_small_box*.json ([-0.5, 0.5]^3; the mesh spans [-1, 1]^3).
    big = [(2 * x - 1, 2 * y - 1, 2 * z - 1) for (x, y, z) in CUBE_V]
    put("partly_outside.obj", obj(big + [(0, 0, 0)], CUBE_F), ODD)
    twist = identity_points((3, 3, 3), (-0.5,) * 3, (0.5,) * 3)
    for p in twist:
        if p[2] > 0.4:
            p[0], p[1] = -p[1], p[0]   # top layer turned by 90 degrees
    put("lattice_small_box_keep.json", lattice_json(lo=(-0.5,) * 3, hi=(0.5,) * 3, points=twist, extra='  "outside": "keep",\n'), ODD)
    put("lattice_small_box_extrapolate.json", lattice_json(lo=(-0.5,) * 3, hi=(0.5,) * 3, points=twist), ODD)
    # A lattice that folds over: the top layer of control points pushed below the bottom one.
    fold = identity_points((3, 3, 3), (-1.5,) * 3, (1.5,) * 3)
    for p in fold:
        if p[2] > 1:
            p[2] = -3.0
    put("lattice_folding.json", lattice_json(lo=(-1.5,) * 3, hi=(1.5,) * 3, points=fold), ODD)
    # A lattice mirrored in x: inside out everywhere.
    mirror = identity_points((2, 2, 2), (-1.5,) * 3, (1.5,) * 3, degree=(1, 1, 1))
    for p in mirror:
        p[0] = -p[0]
    put("lattice_mirrored.json", lattice_json(counts=(2, 2, 2), degree=(1, 1, 1), lo=(-1.5,) * 3, hi=(1.5,) * 3, points=mirror), ODD)


if __name__ == "__main__":
    os.makedirs(ODD, exist_ok=True)
    odd()
    refused()
