"""sffd.FFD against PyGeM's own cases (tests/data/pygem; docs/CONFORMANCE.md)."""
import numpy as np
import pytest

import sffd
from conftest import PYGEM, points_txt

SPHERE_PRM = str(PYGEM / "sphere_ffd" / "parameters_test_ffd_sphere.prm")


@pytest.mark.parametrize("backend", ["cpu", "auto"])
def test_pygem_sphere_case(backend):
    # PyGeM's test_ffd_sphere_mod, with PyGeM's tolerance (assert_array_almost_equal, decimal=6).
    ffd = sffd.FFD(backend=backend)
    ffd.read_parameters(SPHERE_PRM)
    src = points_txt(PYGEM / "sphere_ffd" / "input_points.txt")
    expected = points_txt(PYGEM / "sphere_ffd" / "expected_points.txt")
    out = ffd(src)
    assert out.shape == src.shape and out.dtype == np.float64
    assert np.max(np.abs(out - expected)) < 1.5e-6
    outside = np.all(np.abs(expected - src) < 1e-9, axis=1)
    assert outside.sum() == 3268
    assert np.array_equal(out[outside], src[outside])   # points outside the box: unmoved, bit for bit


def test_identity_parameters_leave_points():
    ffd = sffd.FFD(backend="cpu")
    ffd.read_parameters(str(PYGEM / "identity" / "parameters_test_ffd_identity.prm"))
    src = points_txt(PYGEM / "sphere_ffd" / "input_points.txt")
    np.testing.assert_allclose(ffd(src), src, rtol=0, atol=1e-9)


def test_read_parameters_as_pygem():
    # tests/data/pygem/rotation_convention/case.txt: PyGeM's asserted values.
    ffd = sffd.FFD()
    ffd.read_parameters(str(PYGEM / "rotation_convention" / "parameters_sphere.prm"))
    assert list(ffd.n_control_points) == [3, 2, 2]
    np.testing.assert_array_equal(ffd.rot_angle, [20.3, 11.0, 0.0])
    np.testing.assert_array_equal(ffd.rotation_angle, ffd.rot_angle)
    np.testing.assert_array_almost_equal(ffd.rotation_matrix, [[0.98162718, 0., 0.190809], [0.06619844, 0.93788893, -0.34056147],
                                                               [-0.17895765, 0.34693565, 0.92065727]], decimal=6)
    np.testing.assert_array_almost_equal(ffd.position_vertices, [[-20.0, -55.0, -45.0], [24.17322326, -52.02107006, -53.05309404],
                                                                 [-20., 29.41000412, -13.77579136], [-2.82719042, -85.65053198, 37.85915459]],
                                         decimal=6)
    np.testing.assert_array_equal(ffd.array_mu_x.ravel(), [0.2, 0, 0, 0, 0.5, 0, 0, 0, 1, 0, 0, 0])
    np.testing.assert_array_equal(ffd.array_mu_y.ravel(), [0, 0, 0.5555555555, 0, 0, 0, 0, 0, -1, 0, 0, 0])
    np.testing.assert_array_equal(ffd.array_mu_z.ravel(), [0, -0.2, 0, -0.456229852, 0, 0, 0, 0, -1.22, 0, -1, 0])


def test_lattice_is_the_prm_readers(tmp_path):
    ffd = sffd.FFD()
    ffd.read_parameters(SPHERE_PRM)
    from_file = sffd.Lattice.from_file(SPHERE_PRM)
    assert ffd.lattice().same_structure(from_file)
    np.testing.assert_array_equal(ffd.lattice().control_points, from_file.control_points)
    np.testing.assert_array_equal(ffd.control_points(), from_file.control_points)
    # Written and read back: the same parameters.
    path = str(tmp_path / "again.prm")
    ffd.write_parameters(path)
    again = sffd.FFD()
    again.read_parameters(path)
    for name in ("array_mu_x", "array_mu_y", "array_mu_z", "box_origin", "box_length", "rot_angle", "n_control_points"):
        np.testing.assert_array_equal(getattr(again, name), getattr(ffd, name))


def test_missing_file_is_written_with_defaults(tmp_path):
    path = str(tmp_path / "new.prm")
    sffd.FFD([3, 2, 2]).read_parameters(path)   # PyGeM's behaviour: the file did not exist
    ffd = sffd.FFD()
    ffd.read_parameters(path)
    assert list(ffd.n_control_points) == [3, 2, 2]
    assert not ffd.array_mu_x.any()


def test_trilinear_displacement():
    # A 2x2x2 box, one corner displaced: PyGeM's map is p + u v w mu L along x.
    ffd = sffd.FFD([2, 2, 2], backend="cpu")
    ffd.box_origin = np.array([1.0, 2.0, 3.0])
    ffd.box_length = np.array([2.0, 4.0, 8.0])
    ffd.array_mu_x[1, 1, 1] = 0.5
    rng = np.random.default_rng(1)
    uvw = rng.random((100, 3))
    src = ffd.box_origin + uvw * ffd.box_length
    want = src.copy()
    want[:, 0] += uvw.prod(axis=1) * 0.5 * 2.0
    np.testing.assert_allclose(ffd(src), want, rtol=0, atol=1e-12)
    outside = src + np.array([0.0, 0.0, 100.0])
    np.testing.assert_array_equal(ffd(outside), outside)


def test_float32_and_strided_points():
    ffd = sffd.FFD(backend="cpu")
    ffd.read_parameters(SPHERE_PRM)
    src = points_txt(PYGEM / "sphere_ffd" / "input_points.txt")
    out32 = ffd(src.astype(np.float32))
    assert out32.dtype == np.float32
    np.testing.assert_array_equal(out32, ffd(src.astype(np.float32).astype(np.float64)).astype(np.float32))
    wide = np.zeros((len(src), 6))
    wide[:, ::2] = src
    np.testing.assert_array_equal(ffd(wide[:, ::2]), ffd(src))           # non-contiguous rows
    np.testing.assert_array_equal(ffd(np.asfortranarray(src)), ffd(src))  # Fortran order


def test_bad_parameters_raise_sffds_message(tmp_path):
    bad = tmp_path / "bad.prm"
    bad.write_text(open(SPHERE_PRM).read().replace("n control points x: 3", "n control points x: 9"))
    with pytest.raises(sffd.InputError, match=r"bad\.prm:7: 'n control points x' is 9; 2\.\.6 are supported"):
        sffd.FFD().read_parameters(str(bad))
    ffd = sffd.FFD()
    ffd.array_mu_x = np.zeros((3, 3, 3))
    with pytest.raises(ValueError, match="array_mu_x has shape"):
        ffd(np.zeros((1, 3)))


def test_reflect_is_symmetric():
    ffd = sffd.FFD([2, 3, 2], backend="cpu")
    ffd.box_length = np.array([1.0, 2.0, 1.0])
    ffd.array_mu_x[0, 1, 1] = 0.2
    ffd.array_mu_y[1, 2, 0] = -0.1
    wide = ffd.reflect(axis=0, in_place=False)
    assert list(wide.n_control_points) == [3, 3, 2] and wide.box_length[0] == 2.0 and ffd.box_length[0] == 1.0
    assert wide.array_mu_x[2, 1, 1] == -0.2 and wide.array_mu_y[1, 2, 0] == -0.1
    rng = np.random.default_rng(2)
    p = rng.random((50, 3)) * [1.0, 2.0, 1.0]
    mirror = p * [-1, 1, 1] + [2.0, 0, 0]
    np.testing.assert_allclose(wide(mirror), wide(p) * [-1, 1, 1] + [2.0, 0, 0], rtol=0, atol=1e-12)
    ffd.array_mu_x[1, 0, 0] = 0.1
    with pytest.raises(RuntimeError):
        ffd.reflect(axis=0)
