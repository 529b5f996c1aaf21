"""sffd.FFD: pygem.FFD's interface (mathLab/PyGeM pygem/ffd.py) computed by sffd's classic FFD.

The parameters are PyGeM's, held the way PyGeM holds them; a call builds the lattice a .prm file with
these parameters reads as (sffd::pygemLattice: a Bernstein lattice of degree n-1 on the rotated box)
and moves the points inside the box on the device, leaving those outside where they are.
"""
import copy
import os

import numpy as np

from . import _sffd


def _rotation(angles_deg):
    """R = Rx(x) Ry(y) Rz(z), PyGeM's convention (angles in degrees)."""
    x, y, z = np.radians(np.asarray(angles_deg, dtype=float))
    rx = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
    ry = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
    rz = np.array([[np.cos(z), -np.sin(z), 0], [np.sin(z), np.cos(z), 0], [0, 0, 1]])
    return rx @ ry @ rz


class FFD:
    """PyGeM's FFD: box_origin, box_length, rot_angle (degrees; also rotation_angle), n_control_points
    and the displacements array_mu_x/y/z of shape n_control_points in box-length units along the box's
    axes. backend picks the device as in sffd.deform ("auto", "vulkan", "gl", "cpu" or an sffd.Device)."""

    reference_frame = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])

    def __init__(self, n_control_points=None, backend="auto"):
        self.conversion_unit = 1.0
        self.box_length = np.array([1.0, 1.0, 1.0])
        self.box_origin = np.array([0.0, 0.0, 0.0])
        self.rot_angle = np.array([0.0, 0.0, 0.0])
        self.backend = backend
        self.n_control_points = [2, 2, 2] if n_control_points is None else n_control_points

    @property
    def n_control_points(self):
        return self._n_control_points

    @n_control_points.setter
    def n_control_points(self, counts):
        # As in PyGeM: a new count resets the displacements.
        self._n_control_points = np.array(counts)
        self.array_mu_x = np.zeros(self._n_control_points)
        self.array_mu_y = np.zeros(self._n_control_points)
        self.array_mu_z = np.zeros(self._n_control_points)

    @property
    def rotation_angle(self):
        return self.rot_angle

    @rotation_angle.setter
    def rotation_angle(self, angles):
        self.rot_angle = np.asarray(angles, dtype=float)

    @property
    def rotation_matrix(self):
        return _rotation(self.rot_angle)

    @property
    def position_vertices(self):
        """The box's origin, then origin + each box edge (4 x 3)."""
        edges = (self.rotation_matrix @ np.diag(self.box_length)).T
        return self.box_origin + np.vstack([np.zeros((1, 3)), edges])

    def reset_weights(self):
        for mu in (self.array_mu_x, self.array_mu_y, self.array_mu_z):
            mu.fill(0.0)

    def _mu(self):
        shape = tuple(int(n) for n in self.n_control_points)
        mus = [np.asarray(m, dtype=float) for m in (self.array_mu_x, self.array_mu_y, self.array_mu_z)]
        for name, m in zip("xyz", mus):
            if m.shape != shape:
                raise _sffd.InputError(f"array_mu_{name} has shape {m.shape}; n_control_points is {shape}")
        return np.stack([m.reshape(-1) for m in mus], axis=1)

    def _values(self):
        return ([int(n) for n in self.n_control_points], self.box_length, self.box_origin, self.rot_angle, self._mu())

    def lattice(self):
        """The sffd.Lattice these parameters mean (for sffd.deform, smooth FFD included)."""
        return _sffd._pygem_lattice(*self._values())

    def control_points(self, deformed=True):
        """The lattice's control points (i slowest, k fastest), deformed or not, as PyGeM gives them."""
        counts, length, origin, angle, mu = self._values()
        return _sffd._pygem_lattice(counts, length, origin, angle, mu if deformed else 0 * mu).control_points.copy()

    def reflect(self, axis=0, in_place=True):
        """Mirrors the lattice across the box face opposite the origin along axis (0, 1, 2), as PyGeM
        does: 2n-1 points and twice the length along it, the displacements mirrored (the one along
        axis negated). The face's points must not be displaced along axis."""
        if axis not in (0, 1, 2):
            raise ValueError(f"The axis has to be 0, 1, or 2. Current value {axis}.")
        mus = [self.array_mu_x, self.array_mu_y, self.array_mu_z]
        if np.count_nonzero(np.take(mus[axis], -1, axis=axis)):
            raise RuntimeError(f"the control points on the symmetry plane are displaced along axis {axis}: cannot reflect")
        target = self if in_place else copy.deepcopy(self)
        mirrored = []
        for c, mu in enumerate(mus):
            tail = np.flip(mu, axis).take(range(1, mu.shape[axis]), axis=axis)   # the plane itself is kept once
            mirrored.append(np.concatenate([mu, -tail if c == axis else tail], axis=axis))
        target._n_control_points = np.array(target._n_control_points)
        target._n_control_points[axis] = 2 * target._n_control_points[axis] - 1
        target.box_length = np.array(target.box_length, dtype=float)
        target.box_length[axis] *= 2
        target.array_mu_x, target.array_mu_y, target.array_mu_z = mirrored
        return None if in_place else target

    def read_parameters(self, filename="parameters.prm"):
        """Reads a .prm file; as PyGeM does, a missing file is written with the current parameters."""
        if not isinstance(filename, str):
            raise TypeError("filename must be a string")
        if not os.path.isfile(filename):
            self.write_parameters(filename)
            return
        counts, length, origin, angle, mu = _sffd._read_pygem(filename)
        self.n_control_points = list(counts)
        self.box_length, self.box_origin, self.rot_angle = length, origin, angle
        self.array_mu_x, self.array_mu_y, self.array_mu_z = (mu[:, a].reshape(counts).copy() for a in range(3))

    def write_parameters(self, filename="parameters.prm"):
        """Writes a .prm file that PyGeM and sffd read back to these parameters."""
        if not isinstance(filename, str):
            raise TypeError("filename must be a string")
        _sffd._write_pygem(filename, *self._values())

    def __call__(self, src_pts):
        """The points (n, 3) deformed: inside the box moved, outside unmoved; the input's float dtype."""
        pts = np.asarray(src_pts)
        out = _sffd.deform_points(pts, self.lattice(), self.backend)
        return out.astype(pts.dtype, copy=False) if pts.dtype.kind == "f" else out

    def __str__(self):
        return (f"n_control_points = {self.n_control_points}\nbox_length = {self.box_length}\n"
                f"box_origin = {self.box_origin}\nrot_angle  = {self.rot_angle}\n"
                f"\narray_mu_x =\n{self.array_mu_x}\n\narray_mu_y =\n{self.array_mu_y}\n\narray_mu_z =\n{self.array_mu_z}\n")
