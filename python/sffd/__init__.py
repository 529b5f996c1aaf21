"""sffd: smooth free-form deformation of triangle meshes on any GPU, numpy in and numpy out.

    import sffd
    L = sffd.Lattice.fitted(vertices).preset("twist", 0.5)
    v, t, n = sffd.deform(vertices, triangles, L)              # smooth FFD, the best device here
    ffd = sffd.FFD(); ffd.read_parameters("box.prm"); moved = ffd(points)   # pygem.FFD's drop-in

The manual is docs/PYTHON.md.
"""
from ._sffd import (  # noqa: F401  (the public names)
    Cancelled,
    Deformer,
    Device,
    DeviceEntry,
    DeviceError,
    Error,
    InputError,
    InternalError,
    Lattice,
    __version__,
    deform,
    deform_points,
    device,
    devices,
    read_mesh,
    write_mesh,
)
from .ffd import FFD  # noqa: F401

__all__ = [
    "Cancelled", "Deformer", "Device", "DeviceEntry", "DeviceError", "Error", "FFD", "InputError", "InternalError",
    "Lattice", "deform", "deform_points", "device", "devices", "read_mesh", "write_mesh",
]
