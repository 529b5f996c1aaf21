"""sffd.deform, sffd.Deformer and sffd.Lattice: identity and affine lattices, the CLI's output, errors,
dtypes and strides, re-deforming, and memory over repeated calls."""
import resource
import subprocess
import sys
import threading

import numpy as np
import pytest

import sffd
from conftest import CLI, DATA


def test_devices():
    found = sffd.devices()
    assert any(d.label == "cpu" for d in found)
    for d in found:
        assert d.name and d.api in ("vulkan", "gl", "gles", "cpu") and d.type and d.label
    assert sffd.device("cpu").api == "cpu"
    assert sffd.device("cpu") is sffd.device("cpu")   # opened once, shared


def test_device_with_a_shader_cache_folder_gives_the_same_bits(sphere, tmp_path):
    v, t, _ = sphere
    lat = sffd.Lattice.fitted(v)
    lat.control_points = lat.control_points * 1.1
    outs = []
    for cache in ("none", str(tmp_path / "cache"), str(tmp_path / "cache")):
        dev = sffd.Device("auto", shader_cache=cache)
        outs.append(sffd.deform(v, t, lat, backend=dev, tess=2, strict=True)[0])
    for o in outs[1:]:
        np.testing.assert_array_equal(o, outs[0])


def test_identity_and_affine_lattices(sphere):
    v, t, n = sphere
    lat = sffd.Lattice.fitted(v, counts=(4, 5, 6), degree=(2, 3, 2))
    out_v, out_t, out_n = sffd.deform(v, t, lat, method="classic", backend="cpu")
    assert out_v.dtype == np.float64 and out_t.dtype == np.uint32 and out_n.shape == v.shape
    np.testing.assert_allclose(out_v, v, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(out_t, t)   # classic: the input's topology
    # B-splines reproduce affine maps: control points mapped by A x + b map every vertex so.
    a = np.array([[1.2, 0.3, 0.0], [-0.1, 0.9, 0.2], [0.05, 0.0, 1.1]])
    b = np.array([0.5, -1.0, 2.0])
    lat.control_points = lat.control_points @ a.T + b
    out_v, _, _ = sffd.deform(v, t, lat, method="classic", backend="cpu")
    np.testing.assert_allclose(out_v, v @ a.T + b, rtol=0, atol=1e-12)


def test_control_points_edit_in_place(sphere):
    lat = sffd.Lattice.fitted(sphere[0])
    before = lat.control_points.copy()
    lat.control_points[3] += 0.1
    assert np.allclose(lat.control_points[3] - before[3], 0.1)
    view = lat.control_points
    del lat   # the view keeps the lattice's storage alive
    assert np.allclose(view[3] - before[3], 0.1)
    lat = sffd.Lattice.fitted(sphere[0])
    with pytest.raises(sffd.InputError, match="expected 125 points"):
        lat.control_points = np.zeros((4, 3))
    twisted = lat.preset("twist", 0.5)
    assert not np.array_equal(twisted.control_points, lat.control_points)   # a new lattice; this one unchanged
    assert lat.counts == (5, 5, 5) and lat.degree == (2, 2, 2) and lat.outside == "extrapolate"
    v, t, _ = sphere
    finer = twisted.refined((2, 1, 3)).elevated(1)
    assert finer.counts == (14, 8, 20) and finer.degree == (3, 3, 3)
    a = sffd.deform(v, t, twisted, method="classic", backend="cpu", precision="double")[0]
    b = sffd.deform(v, t, finer, method="classic", backend="cpu", precision="double")[0]
    assert np.abs(a - b).max() < 1e-12   # the same volume
    with pytest.raises(sffd.InputError, match="degrees stay within"):
        lat.elevated(4)
    # Lattices past the library's limits are refused before anything is allocated (they were made: 300^3 in
    # 650 MB, 4096^3 a MemoryError).
    with pytest.raises(sffd.InputError, match="27000000 control points is too large"):
        sffd.Lattice.box((0, 0, 0), (1, 1, 1), (300, 300, 300))
    with pytest.raises(sffd.InputError, match="too large"):
        sffd.Lattice.fitted(v, counts=(4096, 4096, 4096))
    with pytest.raises(sffd.InputError, match="control points an axis"):
        sffd.Lattice.fitted(v, counts=(5000, 3, 3))


def test_smooth_equals_the_cli(sphere, tmp_path):
    if not CLI.exists():
        pytest.skip(f"no command-line tool at {CLI}")
    v, t, n = sphere
    lat = sffd.Lattice.fitted(v).preset("twist", 0.5)
    lat.save(str(tmp_path / "twist.json"))
    out = tmp_path / "out.ply"
    subprocess.run([str(CLI), "deform", str(DATA / "sphere.obj"), "-l", str(tmp_path / "twist.json"), "--backend", "cpu",
                    "-o", str(out), "--quiet"], check=True)
    cli_v, cli_t, cli_n = sffd.read_mesh(str(out))
    py_v, py_t, py_n = sffd.deform(v, t, lat, backend="cpu", normals=n)
    assert py_t.shape == cli_t.shape and len(py_t) > 720
    np.testing.assert_array_equal(py_t, cli_t)
    # Float results, written with 9 significant digits: the same float32 values.
    np.testing.assert_array_equal(py_v.astype(np.float32), cli_v.astype(np.float32))
    np.testing.assert_allclose(py_n, cli_n, rtol=0, atol=1e-6)


def test_bad_input_raises_sffds_message(sphere, tmp_path):
    v, t, n = sphere
    lat = sffd.Lattice.fitted(v)
    with pytest.raises(sffd.InputError, match=r"vertex index 362 out of range 0\.\.361"):
        sffd.deform(v, t + 1, lat, backend="cpu")
    with pytest.raises(ValueError, match=r"vertices: expected shape \(n, 3\), got \(362, 2\)"):
        sffd.deform(v[:, :2], t, lat)
    with pytest.raises(sffd.InputError, match="method must be"):
        sffd.deform(v, t, lat, method="fancy", backend="cpu")
    with pytest.raises(sffd.InputError, match="the tessellation level must be"):
        sffd.deform(v, t, lat, tess=0, backend="cpu")
    with pytest.raises(sffd.InputError, match="unknown"):
        lat.preset("wobble", 1.0)
    missing = str(tmp_path / "missing.json")
    with pytest.raises(sffd.Error) as e:
        sffd.Lattice.from_file(missing)
    assert str(e.value).startswith(missing) and "\n" not in str(e.value)
    with pytest.raises(sffd.InputError, match=r"lattice_degree_too_high\.json"):
        sffd.Lattice.from_file(str(DATA / "bad" / "lattice_degree_too_high.json"))
    with pytest.raises(sffd.Error):
        sffd.deform(v, t, lat, backend="no-such-device")


def test_float32_and_non_contiguous_input(sphere):
    v, t, n = sphere
    lat = sffd.Lattice.fitted(v).preset("bend", 0.3)
    ref = sffd.deform(v.astype(np.float32).astype(np.float64), t, lat, method="classic", backend="cpu")
    got = sffd.deform(v.astype(np.float32), t.astype(np.int32), lat, method="classic", backend="cpu")
    for a, b in zip(ref, got):
        np.testing.assert_array_equal(a, b)
    wide = np.zeros((len(v), 6))
    wide[:, 1::2] = v
    ref = sffd.deform(v, t, lat, backend="cpu", tess=3)
    got = sffd.deform(wide[:, 1::2], np.asfortranarray(t), lat, backend="cpu", tess=3)
    for a, b in zip(ref, got):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("method", ["smooth", "classic"])
def test_deformer_redeform_equals_fresh(sphere, method):
    v, t, n = sphere
    base = sffd.Lattice.fitted(v)
    d = sffd.Deformer(v, t, base, method=method, backend="cpu", tess=4)
    for name, amount in (("twist", 0.7), ("taper", 0.4)):
        lat = base.preset(name, amount)
        again = d.deform(lat)
        fresh = sffd.deform(v, t, lat, method=method, backend="cpu", tess=4)
        for a, b in zip(again, fresh):
            np.testing.assert_array_equal(a, b)
    assert d.timings["wall_ms"] >= 0
    # the last result's weld on the host: smooth welds its patches, classic moves the vertices
    assert d.timings["weld_ms"] > 0 if method == "smooth" else d.timings["weld_ms"] == 0
    steps = d.timings["steps_ms"]   # the last deform's dispatches by label
    assert set(steps) == ({"deform"} if method == "smooth" else {"classic_ffd"}), steps
    assert all(ms >= 0 for ms in steps.values())
    with pytest.raises(sffd.InputError, match="differ from the Deformer's"):
        d.deform(sffd.Lattice.fitted(v, counts=(4, 4, 4)))


def test_repeated_calls_do_not_leak(sphere):
    v, t, n = sphere
    lat = sffd.Lattice.fitted(v).preset("twist", 0.5)
    d = sffd.Deformer(v, t, lat, backend="cpu", tess=4)

    def calls(k):
        for _ in range(k):
            out = d.deform(lat)   # about 1.2 MB of arrays each
            for _ in range(5):
                sffd.deform(v, t, lat, method="classic", backend="cpu")
                sffd.deform_points(v, lat, backend="cpu")
        return out

    out = calls(10)   # warm up: allocator pools, the device's buffers
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss   # KiB
    calls(60)
    grown = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before
    leaked_if_kept = 60 * sum(a.nbytes for a in out) // 1024
    assert grown < leaked_if_kept // 4, f"max RSS grew by {grown} KiB over 60 calls ({leaked_if_kept} KiB of results made)"
    positions = out[0]
    del out
    assert sys.getrefcount(positions) == 2   # nothing but this name holds the result (and the call's argument)


def test_lattice_files_round_trip(sphere, tmp_path):
    lat = sffd.Lattice.fitted(sphere[0], counts=(4, 5, 6)).preset("bulge", 0.3)
    lat.save(str(tmp_path / "l.json"))
    again = sffd.Lattice.from_file(str(tmp_path / "l.json"))
    assert again.same_structure(lat)
    np.testing.assert_array_equal(again.control_points, lat.control_points)
    # .npy holds the control points only: the box and degree come from the caller.
    lat.save(str(tmp_path / "l.npy"))
    lo = [k[d] for k, d in zip(lat.knots, lat.degree)]
    hi = [k[-d - 1] for k, d in zip(lat.knots, lat.degree)]
    again = sffd.Lattice.from_file(str(tmp_path / "l.npy"), box=(lo, hi), degree=lat.degree)
    assert again.counts == (4, 5, 6)
    np.testing.assert_array_equal(again.control_points, lat.control_points)
    np.testing.assert_allclose(np.concatenate(again.knots), np.concatenate(lat.knots), rtol=0, atol=1e-15)
    # The structure is read-only: a write to its arrays is refused (it was lost without a word).
    for array in (lat.knots[0], lat.frame_linear, lat.frame_offset):
        with pytest.raises(ValueError):
            array[0] = 7


@pytest.mark.parametrize("label", [d.label for d in sffd.devices()])
def test_every_device_gives_the_cpu_bits_in_strict_mode(sphere, label):
    v, t, n = sphere
    lat = sffd.Lattice.fitted(v).preset("twist", 0.6)
    # gles too, held to OpenGL ES 3.1's minimum limits (4 storage blocks a kernel), within which every
    # kernel fits (docs/GLES.md).
    ref = sffd.deform(v, t, lat, backend="cpu", tess=3, strict=True)
    got = sffd.deform(v, t, lat, backend=label, tess=3, strict=True)
    for a, b in zip(ref, got):
        np.testing.assert_array_equal(a, b)


def coarse_torus(n=8):
    """An n x n torus without normals: smooth, though every edge bends by 40 to 50 degrees."""
    a, b = np.meshgrid(np.arange(n) * 2 * np.pi / n, np.arange(n) * 2 * np.pi / n, indexing="ij")
    v = np.stack([(2 + np.cos(b)) * np.cos(a), (2 + np.cos(b)) * np.sin(a), np.sin(b)], -1).reshape(-1, 3)
    t = []
    for i in range(n):
        for j in range(n):
            p, q, r, s = i * n + j, ((i + 1) % n) * n + j, ((i + 1) % n) * n + (j + 1) % n, i * n + (j + 1) % n
            t += [[p, q, r], [p, r, s]]
    return v, np.array(t, dtype=np.uint32)


def test_crease_angle_for_meshes_without_normals():
    v, t = coarse_torus()
    lat = sffd.Lattice.fitted(v).preset("bend", 0.5)
    run = lambda **kw: sffd.deform(v, t, lat, backend="cpu", tess=2, **kw)
    default, auto, flat = run(), run(crease_angle="auto"), run(crease_angle=180)
    for a, b, c in zip(default, auto, flat):   # the rule finds no crease on a coarse torus
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)
    creased = run(crease_angle=40)   # every edge a crease: its vertices split by normal
    assert len(creased[0]) > len(default[0])
    for bad in (-1, 181, "sharp", float("nan")):
        with pytest.raises(sffd.InputError, match="crease_angle"):
            run(crease_angle=bad)


def test_deformer_write_streams_the_clis_file(sphere, tmp_path):
    if not CLI.exists():
        pytest.skip(f"no command-line tool at {CLI}")
    # The input as the CLI reads it (sphere.obj's texture coordinates would go into the CLI's file).
    sffd.write_mesh(str(tmp_path / "in.ply"), *sphere, binary=True)
    v, t, n = sffd.read_mesh(str(tmp_path / "in.ply"))
    lat = sffd.Lattice.fitted(v).preset("twist", 0.5)
    lat.save(str(tmp_path / "twist.json"))
    for ext, binary in ((".ply", True), (".ply", False), (".stl", True), (".obj", False)):
        cli = tmp_path / (("cli_b" if binary else "cli_t") + ext)
        subprocess.run([str(CLI), "deform", str(tmp_path / "in.ply"), "-l", str(tmp_path / "twist.json"), "--backend", "cpu",
                        "--tess", "3", "-o", str(cli), "--quiet"] + (["--binary"] if binary else []), check=True)
        d = sffd.Deformer(v, t, lat, backend="cpu", normals=n, tess=3, once=True)
        out = tmp_path / ("py" + ext)
        nv, nt = d.write(str(out), lat, binary=binary)
        assert out.read_bytes() == cli.read_bytes(), ext
        cv, ct, _ = sffd.read_mesh(str(out))
        assert nt == len(ct) and nt > 720 * 9 and (nv == len(cv) or ext == ".stl")
        with pytest.raises(sffd.InputError):   # once: the result was taken
            d.write(str(tmp_path / "again.ply"))
    # A Deformer made for many lattices writes as often as asked.
    d = sffd.Deformer(v, t, lat, backend="cpu", normals=n, tess=3)
    d.deform(lat)
    d.write(str(tmp_path / "again.ply"), binary=True)
    assert d.write(str(tmp_path / "again.ply"), lat, binary=True) == (nv, nt)
    assert (tmp_path / "again.ply").read_bytes() == (tmp_path / "cli_b.ply").read_bytes()
    with pytest.raises(sffd.InputError, match="binary"):
        sffd.write_mesh(str(tmp_path / "x.obj"), v, t, binary=True)


def test_number_options_take_numpy_scalars_and_refuse_other_things_with_input_error():
    # A stranger's adoption test (2026-11-29): crease_angle=np.float32(30) was refused ("expected None,
    # 'auto' or degrees"), and edge_length="x" raised pybind11's RuntimeError "Unable to cast Python instance".
    v, t = coarse_torus()
    lat = sffd.Lattice.fitted(v).preset("bend", 0.5)
    run = lambda **kw: sffd.deform(v, t, lat, backend="cpu", tess=2, **kw)
    for a, b in zip(run(crease_angle=40, edge_length=0.5), run(crease_angle=np.float32(40), edge_length=np.float32(0.5))):
        np.testing.assert_array_equal(a, b)
    for a, b in zip(run(crease_angle=40), run(crease_angle=np.int64(40))):
        np.testing.assert_array_equal(a, b)
    for kw in ({"edge_length": "x"}, {"edge_length": [1.0]}, {"crease_angle": b"40"}, {"crease_angle": True}):
        with pytest.raises(sffd.InputError, match=next(iter(kw))):
            run(**kw)


def test_deformer_results_need_a_finished_deform_and_finite_control_points(tmp_path):
    # Deformer.write(path) before any deform wrote whatever the device's buffers held; a control point
    # set to NaN after the Deformer was made gave a result of NaN.
    v, t = coarse_torus()
    lat = sffd.Lattice.fitted(v)
    d = sffd.Deformer(v, t, lat, backend="cpu", tess=2)
    with pytest.raises(sffd.InputError, match="deform"):
        d.write(str(tmp_path / "out.ply"))
    assert not (tmp_path / "out.ply").exists()
    bad = lat.copy()
    bad.control_points[5] = np.nan
    with pytest.raises(sffd.InputError, match="not finite"):
        d.deform(bad)
    assert np.isfinite(d.deform(lat)[0]).all()


@pytest.mark.parametrize("label", [d.label for d in sffd.devices() if d.api in ("gl", "gles")])
def test_a_gl_deformer_is_used_and_collected_on_any_thread(sphere, label):
    """Whichever thread drops a Deformer's last reference (or collects it) runs its destructor: on a GL
    device from another thread than the one that opened it, that aborted the process (EGL keeps a context
    current on one thread only)."""
    v, t, _ = sphere
    lat = sffd.Lattice.fitted(v).preset("twist", 0.3)
    made = {}

    def make():
        made["d"] = sffd.Deformer(v, t, lat, backend=sffd.Device(name=label), tess=2)
        made["out"] = made["d"].deform(lat)

    worker = threading.Thread(target=make)
    worker.start()
    worker.join()
    d = made.pop("d")
    for a, b in zip(d.deform(lat), made["out"]):   # on this thread now
        np.testing.assert_array_equal(a, b)
    del d   # with its device, here

    made["d"] = sffd.Deformer(v, t, lat, backend=sffd.Device(name=label), tess=2)
    made["d"].deform(lat)
    worker = threading.Thread(target=made.clear)   # the last reference dropped on the worker
    worker.start()
    worker.join()
    assert not made


def test_library_errors_name_the_python_keywords(sphere):
    # The library's messages name DeformOptions' C++ members; Python callers see their keywords.
    v, t, n = sphere
    lat = sffd.Lattice.fitted(v)
    if any(d.api == "gles" for d in sffd.devices()):
        with pytest.raises(sffd.InputError) as e:
            sffd.deform(v, t, lat, backend="gles", precision="double")
        assert "precision='float' (or 'auto') with backend='gles'" in str(e.value) and "DeformOptions" not in str(e.value)
    d = sffd.Deformer(v, t, lat, backend="cpu", once=True)
    d.deform(lat)
    with pytest.raises(sffd.InputError) as e:
        d.deform(lat)
    assert "(once=True)" in str(e.value) and "DeformOptions" not in str(e.value)
