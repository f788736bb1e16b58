"""The ufcx ``tabulate_tensor`` kernels handed to DOLFINx, made by one factory.

``void(double* A, const double* w, const double* c, const double* coordinate_dofs,
const int* entity_local_index, const uint8_t* quadrature_permutation)``: A the
element tensor (row-major), w the packed coefficients, c the constants,
coordinate_dofs the cell's node coordinates (always 3 per node).

Every element module defines one jitted element function with the signature

    ``tabulate(w (ncoef,), c (nconst,), X (nnode, 3), f (ndof,), K (ndof, ndof), tangent)``

that fills f and, if ``tangent``, K (with ``tangent`` False it may use K as
scratch or leave it alone), and gets its two cfuncs from
:func:`tabulate_tensor_kernels`: the vector kernel writes f into A, the
matrix kernel K. The cfuncs' ``.address`` is what
:func:`dolfinx_corot.assembly.kernel_form` passes to DOLFINx.
"""
from __future__ import annotations

import hashlib
import sys
from pathlib import Path
from types import FunctionType

import numba
import numpy as np
from numba import types

signature = types.void(types.CPointer(types.double), types.CPointer(types.double),
                       types.CPointer(types.double), types.CPointer(types.double),
                       types.CPointer(types.int32), types.CPointer(types.uint8))

# The two cfunc bodies. NDOF, NCOEF, NCONST, NNODE and ``tabulate`` are globals that
# tabulate_tensor_kernels binds per element module (numba freezes them as constants).
# The cached cfuncs are named after this file's content, so that an edit here recompiles them.
_VERSION = hashlib.sha1(Path(__file__).read_bytes()).hexdigest()[:12]


def _vector_kernel(b_, w_, c_, coords_, entity_local_index, permutation):
    K = np.empty((NDOF, NDOF))  # noqa: F821
    tabulate(numba.carray(w_, (NCOEF,)), numba.carray(c_, (NCONST,)),  # noqa: F821
             numba.carray(coords_, (NNODE, 3)), numba.carray(b_, (NDOF,)), K, False)  # noqa: F821


def _matrix_kernel(A_, w_, c_, coords_, entity_local_index, permutation):
    f = np.empty(NDOF)  # noqa: F821
    tabulate(numba.carray(w_, (NCOEF,)), numba.carray(c_, (NCONST,)),  # noqa: F821
             numba.carray(coords_, (NNODE, 3)), f, numba.carray(A_, (NDOF, NDOF)), True)  # noqa: F821


def tabulate_tensor_kernels(tabulate, ndof: int, ncoef: int, nnode: int, nconst: int = 1):
    """(vector_kernel, matrix_kernel): the ufcx cfuncs of the element function ``tabulate``.

    tabulate: a ``numba.njit`` function ``(w, c, X, f, K, tangent)`` (see the module
    docstring); ndof: size of the element vector; ncoef, nconst: lengths of w and c;
    nnode: number of nodes of the cell geometry.

    The cfuncs are compiled and cached by numba as if they were written in the
    module that defines ``tabulate`` (their code object is re-labelled with that
    module's file, their qualified name carries a hash of this file): the
    on-disk cache is then invalidated when either file changes, and two element
    functions (of one module or two) never share an entry (the name of ``tabulate`` is in it). A closure over ``tabulate`` would not do:
    numba keys the cache of a closure on the pickle of its cells, and a jitted
    function pickles with a fresh id in every process, so such a cache never
    hits (and grows at every import).
    """
    module = tabulate.py_func.__module__
    module_file = sys.modules[module].__file__
    # __name__: numba rebuilds a cached function's environment from that module
    env = {"__name__": module, "np": np, "numba": numba, "tabulate": tabulate,
           "NDOF": ndof, "NCOEF": ncoef, "NCONST": nconst, "NNODE": nnode}
    made = []
    for body, what in ((_vector_kernel, f"element vector ({ndof},)"),
                       (_matrix_kernel, f"element matrix ({ndof}, {ndof})")):
        name = body.__name__[1:]
        code = body.__code__.replace(co_filename=module_file, co_name=name,
                                     co_qualname=f"{name}{tabulate.__name__}_{_VERSION}")
        fn = FunctionType(code, env, name)
        fn.__doc__ = f"ufcx tabulate_tensor of the {what} of {module}."
        made.append(numba.cfunc(signature, nopython=True, cache=True)(fn))
    return tuple(made)


def lazy_kernels(tabulate, ndof: int, ncoef: int, nnode: int):
    """A function returning :func:`tabulate_tensor_kernels` of ``tabulate``, compiled on its first
    call (kernels that only some analyses need, e.g. those of staged elements)."""
    made = []

    def kernels():
        if not made:
            made.extend(tabulate_tensor_kernels(tabulate, ndof, ncoef, nnode))
        return tuple(made)

    return kernels
