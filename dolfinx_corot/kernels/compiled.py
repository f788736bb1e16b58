"""The beams' kernels (in space and in the plane) and the nodal rotation updates in C
(``beam3d.c``, ``line2d.c``), compiled by cffi.

A scene of beams then runs without numba: its import and its first load of cached
functions (numba's target context and LLVM, about 0.45 s of a small model's whole process) are
not paid. The C source is the same arithmetic, in the same order, as the numba kernels of
:mod:`.beam3d` (the co-rotational element of Battini & Pacoste 2002 with its closed-form
tangent, and the geometrically linear one), of :mod:`.line2d` (Crisfield's planar element)
and as :func:`dolfinx_corot.rotations.quat_update` and
:func:`~dolfinx_corot.rotations.rotvec_from_quat`; compiled without fused multiply-adds
(``-ffp-contract=off``), it gives their numbers to rounding, which the tests check. The numba
versions remain the reference: they also run in complex arithmetic, for the complex-step
derivatives that check the closed-form tangent, and they serve what C does not cover (staged
elements, follower loads). The element results (the 3D beams' section forces, the planar
elements' end forces) are C as well.

Compiled once per machine and source into the cache directory, as the assembly's loops are
(:func:`dolfinx_corot.assembly.cells.build`).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from ..elements.line_properties import NPROPS_2D, NPROPS_3D
from . import NSTATE as NSTATE_3D  # a node's state in space: u (3), quaternion (4)

_CDEF = """
void beam3d_vector(double* A, const double* w, const double* c, const double* coordinate_dofs,
                   const int* entity_local_index, const uint8_t* quadrature_permutation);
void beam3d_matrix(double* A, const double* w, const double* c, const double* coordinate_dofs,
                   const int* entity_local_index, const uint8_t* quadrature_permutation);
void line2d_vector(double* A, const double* w, const double* c, const double* coordinate_dofs,
                   const int* entity_local_index, const uint8_t* quadrature_permutation);
void line2d_matrix(double* A, const double* w, const double* c, const double* coordinate_dofs,
                   const int* entity_local_index, const uint8_t* quadrature_permutation);
void beam3d_section_forces_all(int64_t n, const double* X, const double* S, const double* props,
                               int64_t large_rotations, double* out, double* axes);
void line2d_evaluate_all(int64_t n, const double* X, const double* D, const double* props, int64_t large_rotations,
                         double* F, double* K);
void update_quaternions(int64_t n, double* state, const double* dx);
void rotvecs_from_quats(int64_t n, const double* Q, double* out);
"""
FLAGS = ("-O2", "-ffp-contract=off", "-g0")
SOURCES = ("beam3d.c", "line2d.c")  # one library (line2d.c uses beam3d.c's includes)

_MODULE = None


def library():
    """The cffi module of ``beam3d.c`` and ``line2d.c`` (built on first use, then loaded from the cache)."""
    global _MODULE
    if _MODULE is None:
        from ..assembly.cells import build

        here = Path(__file__).parent
        source = "\n".join((here / name).read_text() for name in SOURCES)
        _MODULE = build("_dc_beam3d_", source, _CDEF, FLAGS)
    return _MODULE


class Kernel:
    """A ufcx ``tabulate_tensor`` function of the library, as DOLFINx takes it (``.address``)."""

    def __init__(self, name: str):
        module = library()
        self.name = name
        self.address = int(module.ffi.cast("uintptr_t", module.ffi.addressof(module.lib, name)))


def beam3d_kernels() -> tuple[Kernel, Kernel]:
    """(vector kernel, matrix kernel) of the 3D beams: the coefficients, constants and geometry of
    :data:`dolfinx_corot.kernels.beam3d.vector_kernel`'s."""
    return Kernel("beam3d_vector"), Kernel("beam3d_matrix")


def line2d_kernels() -> tuple[Kernel, Kernel]:
    """(vector kernel, matrix kernel) of the planar beams and bars: the coefficients, constants and
    geometry of :data:`dolfinx_corot.kernels.line2d.vector_kernel`'s."""
    return Kernel("line2d_vector"), Kernel("line2d_matrix")


def _double(ffi, a: np.ndarray, name: str):
    if a.dtype != np.float64 or not a.flags.c_contiguous:
        raise TypeError(f"{name}: a C-contiguous float64 array is needed, not {a.dtype} {a.flags.c_contiguous=}")
    return ffi.cast("double*", a.ctypes.data)


def _arrays(ffi, name: str, **arrays):
    """The pointers of float64 arrays of the given shapes ({name: (array, shape)})."""
    out = []
    for key, (a, shape) in arrays.items():
        if a.shape != shape:
            raise ValueError(f"{name}: {key} of shape {shape}, not {a.shape}")
        out.append(_double(ffi, a, key))
    return out


def section_forces_all(X, S, props, large_rotations: bool, out, axes) -> None:
    """:func:`dolfinx_corot.kernels.beam3d.section_forces_all` in C: X (n, 2, 3), S (n, 2, 7),
    props (n, 10) → out (n, 2, 6) the section forces (N, Vy, Vz, T, My, Mz) at both ends in the
    elements' axes, axes (n, 3, 3) their rows e1, e2, e3."""
    n = len(X)
    module = library()
    pointers = _arrays(module.ffi, "section_forces_all", X=(X, (n, 2, 3)), S=(S, (n, 2, NSTATE_3D)),
                       props=(props, (n, NPROPS_3D)), out=(out, (n, 2, 6)), axes=(axes, (n, 3, 3)))
    module.lib.beam3d_section_forces_all(n, *pointers[:3], int(bool(large_rotations)), *pointers[3:])


def evaluate_all_2d(X, D, props, large_rotations: bool, F, K) -> None:
    """:func:`dolfinx_corot.kernels.line2d.evaluate_all` in C: X (n, 2, 2), D (n, 6), props (n, 4)
    → F (n, 6), K (n, 6, 6)."""
    n = len(X)
    module = library()
    pointers = _arrays(module.ffi, "evaluate_all_2d", X=(X, (n, 2, 2)), D=(D, (n, 6)), props=(props, (n, NPROPS_2D)),
                       F=(F, (n, 6)), K=(K, (n, 6, 6)))
    module.lib.line2d_evaluate_all(n, *pointers[:3], int(bool(large_rotations)), *pointers[3:])


def update_quaternions(state: np.ndarray, dx: np.ndarray, n: int) -> None:
    """state (·, 7) ← (u + du, exp(dw)∘q), renormalized, for the first n nodes; dx (≥ n, 6)."""
    if n > len(state) or n > len(dx) or state.shape[1:] != (NSTATE_3D,) or dx.shape[1:] != (6,):
        raise ValueError(f"update_quaternions: states {state.shape} and corrections {dx.shape} for {n} nodes")
    module = library()
    module.lib.update_quaternions(n, _double(module.ffi, state, "state"), _double(module.ffi, dx, "dx"))


def rotvecs_from_quats(Q: np.ndarray) -> np.ndarray:
    """Rotation vectors (n, 3) of the unit quaternions Q (n, 4), each with norm in [0, π]."""
    Q = np.ascontiguousarray(Q, dtype=np.float64)
    if Q.ndim != 2 or Q.shape[1] != 4:
        raise ValueError(f"rotvecs_from_quats: quaternions of shape (n, 4), not {Q.shape}")
    out = np.empty((len(Q), 3))
    module = library()
    module.lib.rotvecs_from_quats(len(Q), _double(module.ffi, Q, "Q"), _double(module.ffi, out, "out"))
    return out


def _element(kind: str, ndof: int, ncoef: int, X, w, mode: float) -> tuple[np.ndarray, np.ndarray]:
    module = library()
    ffi, lib = module.ffi, module.lib
    X = np.ascontiguousarray(X, dtype=np.float64).reshape(2, 3)
    w = np.ascontiguousarray(w, dtype=np.float64)
    if w.shape != (ncoef,):
        raise ValueError(f"{kind}_element: {ncoef} coefficients, not {w.shape}")
    c = np.array([float(mode)])
    f, K = np.empty(ndof), np.empty((ndof, ndof))
    args = (_double(ffi, w, "w"), _double(ffi, c, "c"), _double(ffi, X, "X"), ffi.NULL, ffi.NULL)
    getattr(lib, kind + "_vector")(_double(ffi, f, "f"), *args)
    getattr(lib, kind + "_matrix")(_double(ffi, K, "K"), *args)
    return f, K


def beam3d_element(X: np.ndarray, w: np.ndarray, mode: float) -> tuple[np.ndarray, np.ndarray]:
    """(f (12,), K (12, 12)) of one element through the two C kernels: X (2, 3) the nodes, w the
    coefficients (the two nodal states (7,) and props (10,)), ``mode`` the constant c[0] (0
    geometrically linear, 1 co-rotational, 2 with ½(K + Kᵀ))."""
    return _element("beam3d", 12, 2 * NSTATE_3D + NPROPS_3D, X, w, mode)


def line2d_element(X: np.ndarray, w: np.ndarray, mode: float) -> tuple[np.ndarray, np.ndarray]:
    """(f (6,), K (6, 6)) of one planar element through the two C kernels: X (2, 3) the nodes
    (z = 0), w the coefficients ((u, v, θ) of both nodes, props (EA, EI, GAs, N0)), ``mode`` the
    constant c[0] (0 geometrically linear, 1 co-rotational)."""
    return _element("line2d", 6, 6 + NPROPS_2D, X, w, mode)
