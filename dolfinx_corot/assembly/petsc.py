"""Every PETSc object of the package is made here: vectors, matrices, the extra matrix of
declared couplings, near-nullspaces, local-to-global maps, and the linear solver.

The linear solver (:class:`LinearSolver`) is MUMPS — LDLᵀ for symmetric tangents
(its count of negative pivots is the number of negative eigenvalues of K,
Sylvester's law) or LU — or, for continua, CG preconditioned by
smoothed-aggregation AMG (PETSc's GAMG) with the rigid-body near-nullspace,
whose failed solves (an indefinite tangent) are repeated with MUMPS LU.
PETSc options with the solver's prefix (``dc_newton_``) override all of it
(e.g. ``-dc_newton_pc_type lu``).
"""
from __future__ import annotations

import logging
from typing import Sequence

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

import dolfinx.fem.petsc
import dolfinx.la

from .. import _dolfinx

logger = logging.getLogger(__name__)


# -- vectors and matrices ---------------------------------------------------------------
def form_matrix(a, mat_type: str | None = None) -> PETSc.Mat:
    """The matrix of a DOLFINx bilinear form (its sparsity), AIJ or ``mat_type``."""
    return dolfinx.fem.petsc.create_matrix(a, mat_type)


def form_vector(L) -> PETSc.Vec:
    """A ghosted vector laid out like the test space of a linear form."""
    return dolfinx.fem.petsc.create_vector(L)


def layout_matrix(comm, imap, blocks: Sequence[np.ndarray], n_owned: int) -> PETSc.Mat:
    """AIJ matrix over a :class:`~dolfinx_corot.assembly.layout.DofLayout` whose pattern couples
    the local indices of each row of every (k, n) array of ``blocks``."""
    return _dolfinx.petsc_matrix(comm, _dolfinx.sparsity_pattern(comm, imap, blocks, n_owned))


def layout_vector(imap) -> PETSc.Vec:
    return _dolfinx.petsc_vector(imap, 1)


def duplicate(v: PETSc.Vec, count: int = 1):
    """``count`` new vectors laid out like ``v`` (one vector if count is 1)."""
    out = [v.duplicate() for _ in range(count)]
    return out[0] if count == 1 else out


def copy(v: PETSc.Vec) -> PETSc.Vec:
    return v.copy()


def _petsc_library():
    """(ctypes, the PETSc library petsc4py is linked to, PetscInt*, PetscInt) with the argument
    types of the calls petsc4py 3.18 lacks: ``MatGetRowIJ``, ``MatSeqAIJGetArray[Read]``,
    ``MatSeqSBAIJGetArray``, ``MatMPIAIJGetSeqAIJ``, ``MatGetSize``, ``MatSeqAIJSetColumnIndices``,
    ``MatGetOperation``, ``MatSetOperation``, ``MatInodeGetInodeSizes`` and their Restore calls."""
    global _LIBRARY
    if _LIBRARY is None:
        import ctypes

        import petsc4py.PETSc

        lib = ctypes.CDLL(petsc4py.PETSc.__file__)  # its dependencies' symbols too (dlsym)
        int_t = ctypes.c_int32 if PETSc.IntType == np.int32 else ctypes.c_int64
        p_int = ctypes.POINTER(int_t)
        for name in ("MatGetRowIJ", "MatRestoreRowIJ"):
            f = getattr(lib, name)
            f.argtypes = [ctypes.c_void_p, int_t, ctypes.c_int, ctypes.c_int, p_int,
                          ctypes.POINTER(p_int), ctypes.POINTER(p_int), ctypes.POINTER(ctypes.c_int)]
            f.restype = ctypes.c_int
        for name in ("MatSeqAIJGetArray", "MatSeqAIJRestoreArray", "MatSeqAIJGetArrayRead",
                     "MatSeqAIJRestoreArrayRead", "MatSeqSBAIJGetArray", "MatSeqSBAIJRestoreArray"):
            f = getattr(lib, name)
            f.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.POINTER(ctypes.c_double))]
            f.restype = ctypes.c_int
        lib.MatMPIAIJGetSeqAIJ.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_void_p),
                                           ctypes.POINTER(ctypes.c_void_p), ctypes.POINTER(p_int)]
        lib.MatMPIAIJGetSeqAIJ.restype = ctypes.c_int
        lib.MatGetSize.argtypes = [ctypes.c_void_p, p_int, p_int]
        lib.MatGetSize.restype = ctypes.c_int
        lib.MatSeqAIJSetColumnIndices.argtypes = [ctypes.c_void_p, p_int]
        lib.MatSeqAIJSetColumnIndices.restype = ctypes.c_int
        lib.MatGetOperation.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.POINTER(ctypes.c_void_p)]
        lib.MatGetOperation.restype = ctypes.c_int
        lib.MatSetOperation.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_void_p]
        lib.MatSetOperation.restype = ctypes.c_int
        lib.MatInodeGetInodeSizes.argtypes = [ctypes.c_void_p, p_int, ctypes.POINTER(p_int), p_int]
        lib.MatInodeGetInodeSizes.restype = ctypes.c_int
        _LIBRARY = (ctypes, lib, p_int, int_t)
    return _LIBRARY


_LIBRARY = None
_MATOP_MULT, _MATOP_MULT_ADD, _MATOP_MULT_TRANSPOSE, _MATOP_GET_DIAGONAL = 3, 4, 5, 17  # PETSc 3.18's MatOperation
_PRODUCT_API = []
_PETSC_PRODUCTS: dict[tuple[int, int], int] = {}  # PETSc's own operation of each (kind, block size)
_PRODUCT_TOKENS = iter(range(1, 2 ** 62))


def _compiled_cells():
    from . import cells

    return cells.compiled()


def _product_api(module) -> None:
    """Hands the compiled products (cells.sbaij_mult, cells.nodal_mult_transpose,
    cells.nodal_mult_add, cells.copied_mult) the PETSc calls they make, once."""
    if _PRODUCT_API:
        return
    ctypes, lib, _, _ = _petsc_library()
    names = ("VecGetArrayRead", "VecRestoreArrayRead", "VecGetArrayWrite", "VecRestoreArrayWrite", "MatGetBlockSize",
             "PetscObjectStateGet", "VecGetArray", "VecRestoreArray")
    addresses = [module.ffi.cast("void*", ctypes.cast(getattr(lib, n), ctypes.c_void_p).value) for n in names]
    module.lib.product_api(*addresses)
    _PRODUCT_API.append(True)


class CompiledProduct:
    """A product of the sequential PETSc matrix at ``handle`` by a compiled loop of
    :mod:`dolfinx_corot.assembly.cells`, installed as its operation ``op`` (MATOP_MULT: the
    SBAIJ product ``sbaij_mult``, kind 1; MATOP_MULT_TRANSPOSE: the nodal AIJ transpose
    ``nodal_mult_transpose``, kind 2; MATOP_MULT_ADD: the nodal AIJ product added
    ``nodal_mult_add``, kind 4), with the pattern (ia, ja: kept alive by the caller) and
    values it reads. ``installed`` is False where nothing could be (an empty matrix, no slot);
    :meth:`forget` ends the registration (PETSc's own product then serves the matrix)."""

    _FUNCTIONS = {1: (_MATOP_MULT, "sbaij_mult"), 2: (_MATOP_MULT_TRANSPOSE, "nodal_mult_transpose"),
                  4: (_MATOP_MULT_ADD, "nodal_mult_add")}

    def __init__(self, handle: int, kind: int, n: int, ncols: int, bs: int, ia: np.ndarray, ja: np.ndarray):
        import weakref

        self.handle, self.kind, self.n, self.ncols, self.bs = int(handle), kind, n, ncols, bs
        self.ia, self.ja = ia, ja
        self.installed = False
        self.module = module = _compiled_cells()
        if n == 0 or len(ja) == 0:
            return
        _product_api(module)
        ctypes, lib, _, _ = _petsc_library()
        op, name = self._FUNCTIONS[kind]
        h = ctypes.c_void_p(self.handle)
        original = ctypes.c_void_p()
        if lib.MatGetOperation(h, op, ctypes.byref(original)) or not original.value:
            return
        ffi = module.ffi
        address = int(ffi.cast("uintptr_t", ffi.addressof(module.lib, name)))
        if original.value == address:  # installed already (a second owner): PETSc's is the one seen first
            if (kind, bs) not in _PETSC_PRODUCTS:
                return
            original.value = _PETSC_PRODUCTS[kind, bs]
        _PETSC_PRODUCTS.setdefault((kind, bs), original.value)
        self.original = original.value
        self.token = next(_PRODUCT_TOKENS)
        if not self.register():
            return
        if lib.MatSetOperation(h, op, ctypes.c_void_p(address)):
            self.forget()
            return
        self.installed = True
        self._finalizer = weakref.finalize(self, module.lib.product_forget, ffi.cast("void*", self.handle),
                                           self.token)

    def _values(self) -> int:
        """The address of the matrix's values (PETSc's array)."""
        ctypes, lib, _, _ = _petsc_library()
        h = ctypes.c_void_p(self.handle)
        v = ctypes.POINTER(ctypes.c_double)()
        get, restore = (("MatSeqSBAIJGetArray", "MatSeqSBAIJRestoreArray") if self.kind == 1 else
                        ("MatSeqAIJGetArrayRead", "MatSeqAIJRestoreArrayRead"))
        if getattr(lib, get)(h, ctypes.byref(v)):
            return 0
        address = ctypes.cast(v, ctypes.c_void_p).value or 0
        getattr(lib, restore)(h, ctypes.byref(v))
        return address

    def register(self) -> bool:
        """(Re-)registers the matrix with the current address of its values (fixed while its
        pattern is; checked after each assembly)."""
        address = self._values()
        if not address:
            return False
        ffi, lib = self.module.ffi, self.module.lib
        return lib.product_register(ffi.cast("void*", self.handle), self.token, self.kind, self.n, self.ncols,
                                    self.bs, ffi.cast("int32_t*", self.ia.ctypes.data),
                                    ffi.cast("int32_t*", self.ja.ctypes.data), ffi.cast("double*", address),
                                    ffi.cast("void*", self.original)) == 0

    def recheck(self) -> None:
        """After an assembly: registered anew, or PETSc's product back where that fails."""
        if self.installed and not self.register():
            self.restore()

    def restore(self) -> None:
        """PETSc's own product back."""
        if self.installed:
            ctypes, lib, _, _ = _petsc_library()
            lib.MatSetOperation(ctypes.c_void_p(self.handle), self._FUNCTIONS[self.kind][0],
                                ctypes.c_void_p(self.original))
            self.forget()

    def forget(self) -> None:
        if getattr(self, "_finalizer", None) is not None:
            self._finalizer()
        else:
            self.module.lib.product_forget(self.module.ffi.cast("void*", self.handle), getattr(self, "token", 0))
        self.installed = False


class CopiedProduct:
    """The product of ``A`` by that of a copy of it in the nodal-block format ``fmt`` ('sbaij':
    its upper block triangle, where A is flagged symmetric, else 'baij'), installed as A's
    MATOP_MULT (the compiled ``copied_mult`` of :mod:`dolfinx_corot.assembly.cells`): it serves
    while A's object state is the one copied, A's own product after any change of A. For AMG's coarse operators,
    which PETSc keeps as AIJ with 6 × 6 blocks (the rigid-body modes) whose I-nodes hold five
    rows: on the 116 k-dof block's third level (3876 rows, 672 k entries) 1.08 ms a product
    against 0.20 ms by SBAIJ and 0.33 ms by BAIJ. The numbers differ from A's by round-off (the
    sums' order). ``installed`` is False where nothing was (a block size of 1, a failed
    conversion, no slot); :meth:`restore` puts A's own product back (also when the object is
    collected)."""

    def __init__(self, A: PETSc.Mat, fmt: str):
        """(collective on A's communicator)"""
        import weakref

        self.A = A
        self.installed = False
        self.state = A.stateGet()
        if A.getBlockSize() < 2:
            return
        self.module = module = _compiled_cells()
        _product_api(module)
        ctypes, lib, _, _ = _petsc_library()
        if fmt == "sbaij" and A.isSymmetricKnown() != (True, True):  # (PETSc converts only these)
            fmt = "baij"
        self.format = fmt
        self.copy = A.convert(fmt, PETSc.Mat())  # (petsc4py's convert without a target converts A itself)
        self.state = A.stateGet()  # (after the conversion, which raises it)
        self.compiled = self._compiled_product() if fmt == "sbaij" else None
        own, mult = ctypes.c_void_p(), ctypes.c_void_p()
        if lib.MatGetOperation(ctypes.c_void_p(A.handle), _MATOP_MULT, ctypes.byref(own)) or not own.value \
                or lib.MatGetOperation(ctypes.c_void_p(self.copy.handle), _MATOP_MULT, ctypes.byref(mult)) \
                or not mult.value:
            return
        ffi = module.ffi
        address = int(ffi.cast("uintptr_t", ffi.addressof(module.lib, "copied_mult")))
        if own.value == address:  # (another copy serves A: A's own would be this one)
            return
        self.own = own.value
        self.token = next(_PRODUCT_TOKENS)
        cast = ffi.cast
        if module.lib.product_register_copy(cast("void*", A.handle), self.token, cast("void*", self.copy.handle),
                                            cast("void*", mult.value), cast("void*", own.value), self.state):
            return
        if lib.MatSetOperation(ctypes.c_void_p(A.handle), _MATOP_MULT, ctypes.c_void_p(address)):
            module.lib.product_forget(cast("void*", A.handle), self.token)
            return
        self.installed = True
        self._finalizer = weakref.finalize(self, _restore_copied, module, A, self.copy, self.own, self.token,
                                           self.compiled)

    def _compiled_product(self) -> CompiledProduct | None:
        """The SBAIJ copy's product by the compiled loop (``cells.sbaij_mult``, block sizes 2,
        3 and 6: PETSc's numbers to the last bit), on one rank the copy's, on several its diagonal
        block's (which PETSc's MPISBAIJ product calls); None where it is not
        (``-dc_sbaij_product false``, 64-bit indices, another block size). PETSc's loop for the
        6 × 6 blocks of the 3D coarse levels keeps each block row's six sums in memory: on the
        10⁶-dof block's third and fourth levels (5 784 rows, 5.0 M entries; 33 096 rows, 7.6 M
        entries) 8.1 and 8.2 ms a product against 0.8–0.9 and 1.3–1.5 ms by the compiled loop,
        on the 116 k-dof block's third (3 876 rows, 672 k entries) 0.20 against 0.10 ms."""
        bs = self.copy.getBlockSize()
        if (bs not in (2, 3, 6) or np.dtype(PETSc.IntType) != np.int32
                or not PETSc.Options().getBool("dc_sbaij_product", True)):
            return None
        target = self.copy if self.copy.getType() == "seqsbaij" else self.copy.getDiagonalBlock()
        if target.getType() != "seqsbaij":
            return None
        ia, ja = target.getRowIJ(symmetric=False, compressed=True)
        product = CompiledProduct(target.handle, 1, len(ia) - 1, len(ia) - 1, bs, ia, ja)
        if not product.installed:
            return None
        product.target = target  # (the diagonal block lives as long as the copy)
        return product

    def current(self, A: PETSc.Mat) -> bool:
        """Whether this copy serves ``A`` as it is now."""
        return self.installed and A.handle == self.A.handle and A.stateGet() == self.state

    def restore(self) -> None:
        """A's own product back, the copy released."""
        if self.installed:
            self._finalizer()
            self.installed = False


class KeptDiagonal:
    """A's diagonal (its MATOP_GET_DIAGONAL, the compiled ``kept_diagonal`` of
    :mod:`dolfinx_corot.assembly.cells`) from a copy kept by :meth:`keep` while A's object state is
    the one kept, by A's own operation otherwise (before the first :meth:`keep`, after any change
    of A). For the tangent, whose diagonal the assembly makes anyway and which the Jacobi
    smoother of AMG's finest level reads once a solve: PETSc's loop reads A's values at the
    diagonal's places, about 10 ms on the 116 k-dof block (2 % of the run). ``installed`` is False
    where nothing was (no slot); :meth:`restore` puts A's own operation back (also when the object
    is collected)."""

    def __init__(self, A: PETSc.Mat):
        import weakref

        self.A = A
        self.installed = False
        self.values = None
        self.module = module = _compiled_cells()
        _product_api(module)
        ctypes, lib, _, _ = _petsc_library()
        ffi = module.ffi
        address = int(ffi.cast("uintptr_t", ffi.addressof(module.lib, "kept_diagonal")))
        own = ctypes.c_void_p()
        if lib.MatGetOperation(ctypes.c_void_p(A.handle), _MATOP_GET_DIAGONAL, ctypes.byref(own)) or not own.value \
                or own.value == address:  # (another one serves A: A's own would be this one)
            return
        self.own = own.value
        self.token = next(_PRODUCT_TOKENS)
        if not self._register(None, -1):  # (nothing kept yet: A's own operation serves)
            return
        if lib.MatSetOperation(ctypes.c_void_p(A.handle), _MATOP_GET_DIAGONAL, ctypes.c_void_p(address)):
            module.lib.product_forget(ffi.cast("void*", A.handle), self.token)
            return
        self.installed = True
        self._finalizer = weakref.finalize(self, _restore_diagonal, module, A, self.own, self.token)

    def _register(self, values: np.ndarray | None, state: int) -> bool:
        ffi, lib = self.module.ffi, self.module.lib
        n, address = (0, ffi.NULL) if values is None else (len(values), ffi.cast("double*", values.ctypes.data))
        return lib.product_register_diagonal(ffi.cast("void*", self.A.handle), self.token, n, address,
                                             ffi.cast("void*", self.own), state) == 0

    def keep(self, diagonal: np.ndarray) -> None:
        """A's diagonal is now ``diagonal`` (its owned rows), until A changes."""
        if not self.installed:
            return
        values = np.ascontiguousarray(diagonal, dtype=np.float64)
        if len(values) != self.A.getLocalSize()[0]:
            self._register(None, -1)
            return
        self.values = values  # (alive while registered)
        self._register(values, self.A.stateGet())

    def restore(self) -> None:
        """A's own operation back."""
        if self.installed:
            self._finalizer()
            self.installed = False


def _restore_diagonal(module, A: PETSc.Mat, own: int, token: int) -> None:
    if not PETSc.Sys.isFinalized():
        ctypes, lib, _, _ = _petsc_library()
        lib.MatSetOperation(ctypes.c_void_p(A.handle), _MATOP_GET_DIAGONAL, ctypes.c_void_p(own))
    module.lib.product_forget(module.ffi.cast("void*", A.handle), token)


def _restore_copied(module, A: PETSc.Mat, copy: PETSc.Mat, own: int, token: int,
                    compiled: CompiledProduct | None) -> None:
    if not PETSc.Sys.isFinalized():
        ctypes, lib, _, _ = _petsc_library()
        lib.MatSetOperation(ctypes.c_void_p(A.handle), _MATOP_MULT, ctypes.c_void_p(own))
    module.lib.product_forget(module.ffi.cast("void*", A.handle), token)
    if compiled is not None:
        compiled.forget()
    if not PETSc.Sys.isFinalized():
        copy.destroy()


def coarse_copies(pc: PETSc.PC, symmetric: bool, kept: dict[int, CopiedProduct]) -> dict[int, CopiedProduct]:
    """The products of a GAMG hierarchy's operators between its finest and coarsest levels by
    nodal-block copies (:class:`CopiedProduct`, SBAIJ where the operator is symmetric): those of
    ``kept`` that still serve their level, new ones for the others; PETSc's products are put
    back where a level's operator changed. Nothing where ``-dc_amg_coarse_blocks false``."""
    if pc.getType() != "gamg" or not PETSc.Options().getBool("dc_amg_coarse_blocks", True):
        for product in kept.values():
            product.restore()
        return {}
    levels = pc.getMGLevels()
    copies = {}
    comm = pc.getComm().tompi4py()
    for level in range(1, levels - 1):
        A = pc.getMGSmoother(level).getOperators()[0]
        product = kept.pop(level, None)
        current = product is not None and product.current(A)
        if comm.size > 1:  # (the conversion is collective)
            current = comm.allreduce(current, op=MPI.LAND)
        if current:
            copies[level] = product
            continue
        if product is not None:
            product.restore()
        if A.getType() in ("seqaij", "mpiaij"):
            if symmetric:  # (a Galerkin product P^T A P of the symmetric tangent: its upper triangle)
                A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
            product = CopiedProduct(A, "sbaij" if symmetric else "baij")
            if product.installed:
                copies[level] = product
    for product in kept.values():
        product.restore()
    return copies


def nodal_products(P: PETSc.Mat, bs: int) -> list[CompiledProduct]:
    """The V-cycle's transfers through AMG's prolongator P on one rank (SeqAIJ), whose rows come
    in nodes of ``bs`` with the same columns, by compiled nodal loops (:class:`CompiledProduct`):
    the restriction Pᵀr (kind 2, ``-dc_nodal_transpose false``: PETSc's) and the prolongation
    x + Pe (kind 4, where PETSc's I-node product serves P; ``-dc_nodal_prolongation false``:
    PETSc's), PETSc's numbers to the last bit, each column read once a node instead of once a
    row. Nothing where PetscInt is not 32-bit."""
    if np.dtype(PETSc.IntType) != np.int32 or P.getType() != "seqaij":  # (several ranks: PETSc's MPIAIJ products)
        return []
    options = PETSc.Options()
    ctypes, lib, p_int, int_t = _petsc_library()
    handle = ctypes.c_void_p(P.handle)
    with SeqAIJArrays(P.handle, write=False) as (indptr, indices, _):
        rows = len(indptr) - 1
    m, n = int_t(0), int_t(0)
    lib.MatGetSize(handle, ctypes.byref(m), ctypes.byref(n))
    if rows % bs:
        return []
    kinds = []
    if options.getBool("dc_nodal_transpose", True):
        kinds.append(2)
    count, sizes, limit = int_t(0), p_int(), int_t(0)
    if (options.getBool("dc_nodal_prolongation", True)
            and not lib.MatInodeGetInodeSizes(handle, ctypes.byref(count), ctypes.byref(sizes), ctypes.byref(limit))
            and sizes):  # (PETSc's I-node product, whose order the compiled loop keeps)
        kinds.append(4)
    products = []
    for kind in kinds:
        # (PETSc's own structure: the arrays live as long as the matrix)
        product = CompiledProduct(P.handle, kind, rows, n.value, bs, indptr, indices)
        if product.installed:
            products.append(product)
    return products


class SeqAIJArrays:
    """The CSR arrays of an assembled SeqAIJ matrix, written in place: ``with
    SeqAIJArrays(A) as (indptr, indices, values): ...``. The structure is PETSc's own (no copy,
    ``MatGetRowIJ``); the values come from ``MatSeqAIJGetArray`` and go back with
    ``MatSeqAIJRestoreArray``, which tells PETSc (and the preconditioners built on A) that A
    has changed; ``write=False`` reads them (``MatSeqAIJGetArrayRead``: A's state is kept).
    A: a SeqAIJ matrix, or the address of one (a block of an MPIAIJ matrix). petsc4py 3.18 has
    none of these calls; they are taken from the PETSc library petsc4py is linked to."""

    def __init__(self, A, write: bool = True):
        if isinstance(A, PETSc.Mat):
            if A.getType() != "seqaij":
                raise TypeError(f"SeqAIJArrays needs a SeqAIJ matrix, not {A.getType()}")
            A = A.handle
        self._address = int(A)
        self._get, self._restore = (("MatSeqAIJGetArray", "MatSeqAIJRestoreArray") if write else
                                    ("MatSeqAIJGetArrayRead", "MatSeqAIJRestoreArrayRead"))

    def __enter__(self):
        ctypes, lib, p_int, int_t = _petsc_library()
        self._handle = ctypes.c_void_p(self._address)
        n, done = int_t(0), ctypes.c_int(0)
        self._ia, self._ja = p_int(), p_int()
        if lib.MatGetRowIJ(self._handle, 0, 0, 0, ctypes.byref(n), ctypes.byref(self._ia), ctypes.byref(self._ja),
                           ctypes.byref(done)) or not done.value:
            raise RuntimeError("MatGetRowIJ failed")
        self._n = n
        self._v = ctypes.POINTER(ctypes.c_double)()
        if getattr(lib, self._get)(self._handle, ctypes.byref(self._v)):
            raise RuntimeError(f"{self._get} failed")
        indptr = np.ctypeslib.as_array(self._ia, shape=(n.value + 1,))
        nnz = int(indptr[-1])
        if nnz == 0:  # (ctypes cannot view an empty array)
            return indptr, np.zeros(0, dtype=PETSc.IntType), np.zeros(0)
        return indptr, np.ctypeslib.as_array(self._ja, shape=(nnz,)), np.ctypeslib.as_array(self._v, shape=(nnz,))

    def __exit__(self, *exc):
        ctypes, lib, p_int, int_t = _petsc_library()
        getattr(lib, self._restore)(self._handle, ctypes.byref(self._v))
        done = ctypes.c_int(0)
        lib.MatRestoreRowIJ(self._handle, 0, 0, 0, ctypes.byref(self._n), ctypes.byref(self._ia),
                            ctypes.byref(self._ja), ctypes.byref(done))
        return False


class MPIAIJArrays:
    """The CSR arrays of the owned rows of an assembled MPIAIJ matrix, written in place: ``with
    MPIAIJArrays(A) as (diagonal, off, colmap): ...``, where diagonal and off are ``(indptr,
    indices, values)`` of the block of the owned columns (numbered from the first owned one) and
    of the block of the other columns (numbered 0, 1, …: ``colmap`` gives their global indices,
    sorted), both PETSc's own (``MatMPIAIJGetSeqAIJ``). A's state changes at its next assembly,
    which the caller does."""

    def __init__(self, A: PETSc.Mat, write: bool = True):
        if A.getType() != "mpiaij":
            raise TypeError(f"MPIAIJArrays needs an MPIAIJ matrix, not {A.getType()}")
        self.A = A
        self.write = write

    def __enter__(self):
        ctypes, lib, p_int, int_t = _petsc_library()
        diagonal, off, colmap = ctypes.c_void_p(), ctypes.c_void_p(), p_int()
        if lib.MatMPIAIJGetSeqAIJ(ctypes.c_void_p(self.A.handle), ctypes.byref(diagonal), ctypes.byref(off),
                                  ctypes.byref(colmap)):
            raise RuntimeError("MatMPIAIJGetSeqAIJ failed")
        m, n = int_t(0), int_t(0)
        lib.MatGetSize(off, ctypes.byref(m), ctypes.byref(n))
        columns = (np.ctypeslib.as_array(colmap, shape=(n.value,)).copy() if n.value
                   else np.zeros(0, dtype=PETSc.IntType))
        self._blocks = [SeqAIJArrays(diagonal.value, self.write), SeqAIJArrays(off.value, self.write)]
        return self._blocks[0].__enter__(), self._blocks[1].__enter__(), columns

    def __exit__(self, *exc):
        for block in self._blocks:
            block.__exit__(*exc)
        return False


class SymmetricBlockOperator:
    """The upper triangle of a symmetric AIJ matrix A with nodal blocks (block size > 1) as an
    SBAIJ matrix, the operator of CG and of the AMG's smoothers while AMG builds its hierarchy
    from A: PETSc's SBAIJ product with 3 × 3 blocks reads each block's values once and one
    index per block, the AIJ product one index per value and both triangles (on the 116 k-dof
    hexahedral block: 2.8 against 11 ms a product, the same CG iterations). The pattern is A's
    nodal pattern, made once; :meth:`refresh` copies A's values whenever A has changed since
    (PETSc's object state): on one rank by a compiled loop from A's CSR arrays into S's
    (:func:`dolfinx_corot.assembly.cells.upper_blocks`; 8.6 M values in about 10 ms), where no
    compiler is at hand by ``MatSetValues`` row by row (lower triangle ignored, 45 ms); on
    several ranks the diagonal block by the same loop and the interface's blocks by
    ``MatSetValuesBlocked`` (:meth:`_refresh_split`), without a compiler by ``MatConvert`` into
    the same matrix (47 ms on two ranks)."""

    def __init__(self, A: PETSc.Mat):
        self.A = A
        self.bs = bs = A.getBlockSize()
        start, stop = A.getOwnershipRange()
        self.serial = A.comm.size == 1 and A.getType() == "seqaij"
        if self.serial:
            with SeqAIJArrays(A, write=False) as (indptr, indices, _):
                self.bi, self.bj = self._upper_blocks([(indptr, indices, None)], bs, start // bs)
        else:
            with MPIAIJArrays(A, write=False) as ((indptr, indices, _), (ip, ix, _o), colmap):
                self.bi, self.bj = self._upper_blocks([(indptr, indices, start), (ip, ix, colmap)], bs, start // bs)
        S = PETSc.Mat().createSBAIJ(A.getSizes(), bs, csr=(self.bi, self.bj), comm=A.comm)
        S.setOption(PETSc.Mat.Option.IGNORE_LOWER_TRIANGULAR, True)
        S.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
        S.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        S.setOption(PETSc.Mat.Option.SYMMETRY_ETERNAL, True)
        S.assemble()
        self.S = S
        self._state = None
        self._compiled = None
        self._split = None  # several ranks: S's diagonal block and the blocks of other ranks' columns
        # the tangent assembled straight into S (:meth:`assemble_upper`): A's values are made from
        # S only when something reads A (:meth:`sync`: the AMG's set-up, a fallback LU)
        self.upper_newer = False
        self.assembled = False  # whether a tangent was ever assembled into S alone
        self._diagonal = None
        from . import cells

        try:
            cells.compiled()
            compiled = True
        except Exception:  # no compiler: PETSc's insertion, PETSc's conversion
            compiled = False
        if A.comm.size > 1:  # the same choice on every rank (their calls are collective)
            compiled = bool(A.comm.tompi4py().allreduce(int(compiled), op=MPI.MIN))
        if compiled and self.serial:
            self._compiled = cells.upper_blocks
        elif compiled and A.getType() == "mpiaij":
            self._split = self._split_pattern(start // bs, stop // bs)
            S.setLGMap(*A.getLGMap())  # the rows of ghost nodes go to their owners by local index
            self._off_values = np.zeros((len(self._split[2]), bs * bs))
            self._diagonal_vec = S.createVecLeft()
        # S's product by the compiled loop (cells.sbaij_mult): PETSc's numbers, 0.65-0.8 of its time
        self._product = None
        if (compiled and bs in (2, 3) and np.dtype(PETSc.IntType) == np.int32
                and (self.serial or self._split is not None)
                and PETSc.Options().getBool("dc_sbaij_product", True)):
            self._product = self._install_product()
        # A's diagonal from the one kept by the assembly (KeptDiagonal; ``-dc_kept_diagonal false``:
        # PETSc's)
        self._kept = None
        if compiled and (self.serial or self._split is not None) and PETSc.Options().getBool("dc_kept_diagonal", True):
            self._kept = KeptDiagonal(A)

    def _keep_diagonal(self) -> None:
        """A's diagonal is the tangent's (``self._diagonal``) at its present state."""
        if self._kept is not None:
            self._kept.keep(self._diagonal)

    def _product_target(self):
        """(the SeqSBAIJ matrix whose product is compiled: S or its diagonal block, its block CSR)."""
        if self._split is not None:
            bi_d, bj_d = self._split[0], self._split[1]
            return self.S.getDiagonalBlock().handle, bi_d, bj_d
        return self.S.handle, self.bi, self.bj

    def _install_product(self) -> CompiledProduct | None:
        """The compiled product as the MATOP_MULT of S (one rank) or of its diagonal block
        (several: PETSc's MPISBAIJ product calls the diagonal block's); None where nothing was
        installed."""
        handle, bi, bj = self._product_target()
        product = CompiledProduct(handle, 1, len(bi) - 1, len(bi) - 1, self.bs, bi, bj)
        return product if product.installed else None

    def _recheck_product(self) -> None:
        """After an assembly of S: its values' address registered anew (should PETSc have moved them)."""
        if self._product is not None:
            self._product.recheck()

    @staticmethod
    def _upper_blocks(parts, bs: int, first_block: int, chunk: int = 4096):
        """Block CSR (local block rows, global block columns ≥ the row's) of the nodal pattern
        read off each block's first row, from the CSR ``parts`` of A's owned rows: (indptr,
        indices, g) with g the offset of their global columns (an int) or the global column of
        each index (an array), or None for global indices; ``chunk`` block rows at a time, so
        that the work arrays stay small beside A."""
        nb = (len(parts[0][0]) - 1) // bs
        counts, columns = np.zeros(nb, dtype=np.int64), []
        for lo in range(0, nb, chunk):
            hi = min(lo + chunk, nb)
            first = np.arange(lo, hi, dtype=np.int64) * bs
            rows, cols = [], []
            for indptr, indices, g in parts:
                starts = indptr[first].astype(np.int64)
                lengths = indptr[first + 1].astype(np.int64) - starts
                at = np.repeat(starts - np.cumsum(lengths) + lengths, lengths) + np.arange(int(lengths.sum()))
                c = indices[at].astype(np.int64)
                cols.append(c if g is None else (c + g if np.isscalar(g) else np.asarray(g, np.int64)[c]))
                rows.append(np.repeat(np.arange(lo, hi, dtype=np.int64), lengths))
            row, col = np.concatenate(rows), np.concatenate(cols)
            if len(parts) > 1:
                order = np.lexsort((col, row))
                row, col = row[order], col[order]
            block = col // bs
            keep = block >= row + first_block
            keep[1:] &= (block[1:] != block[:-1]) | (row[1:] != row[:-1])
            counts[lo:hi] = np.bincount(row[keep] - lo, minlength=hi - lo)
            columns.append(block[keep].astype(PETSc.IntType))
        bi = np.zeros(nb + 1, dtype=PETSc.IntType)
        np.cumsum(counts, out=bi[1:])
        return bi, np.concatenate(columns) if columns else np.zeros(0, dtype=PETSc.IntType)

    def _split_pattern(self, first_block: int, stop_block: int):
        """Several ranks: S is PETSc's MPISBAIJ, its owned block rows split into the diagonal
        block (a SeqSBAIJ matrix of the owned block columns, numbered from the first) and the
        blocks of the columns of higher ranks. Returns the diagonal block's pattern (bi_d, bj_d,
        local block columns), the global block rows and columns of the others ((k, 1) each) and,
        for each of their bs² entries (row-major), its place in the values of A's off-diagonal
        CSR block (-1: an entry A lacks, zero)."""
        bs = self.bs
        rows = np.repeat(np.arange(len(self.bi) - 1, dtype=np.int64), np.diff(self.bi))
        cols = self.bj.astype(np.int64)
        inside = cols < stop_block
        bi_d = np.zeros(len(self.bi), dtype=PETSc.IntType)
        np.cumsum(np.bincount(rows[inside], minlength=len(self.bi) - 1), out=bi_d[1:])
        bj_d = (cols[inside] - first_block).astype(PETSc.IntType)
        r_o, c_o = rows[~inside], cols[~inside]
        with MPIAIJArrays(self.A, write=False) as (_, (ip, ix, _v), colmap):
            colmap = np.asarray(colmap, dtype=np.int64)
            i = np.arange(bs)
            shape = (len(r_o), bs, bs)  # entry (a, b) of each block: row r·bs + a, column c·bs + b
            row = np.broadcast_to(r_o[:, None, None] * bs + i[None, :, None], shape)
            gcol = np.broadcast_to(c_o[:, None, None] * bs + i[None, None, :], shape)
            local = np.searchsorted(colmap, gcol) if len(colmap) else np.zeros_like(gcol)
            local = np.minimum(local, max(len(colmap) - 1, 0))
            present = (colmap[local] == gcol) if len(colmap) else np.zeros(gcol.shape, dtype=bool)
            # the off-diagonal CSR's entries as sorted keys row × n + local column
            n = max(len(colmap), 1)
            entry_rows = np.repeat(np.arange(len(ip) - 1, dtype=np.int64), np.diff(ip))
            keys = entry_rows * n + ix.astype(np.int64)
            order = np.argsort(keys, kind="stable")
            want = row * n + local
            at = np.minimum(np.searchsorted(keys[order], want), max(len(keys) - 1, 0))
            found = present & (keys[order][at] == want) if len(keys) else np.zeros(want.shape, dtype=bool)
            pos = np.where(found, order[at] if len(keys) else 0, -1).reshape(len(r_o), bs * bs)
        R = (r_o + first_block).astype(PETSc.IntType).reshape(-1, 1)
        C = c_o.astype(PETSc.IntType).reshape(-1, 1)
        oi = np.zeros(len(self.bi), dtype=PETSc.IntType)
        np.cumsum(np.bincount(r_o, minlength=len(self.bi) - 1), out=oi[1:])
        return bi_d, bj_d, R, C, pos, oi, first_block

    def _upper_values(self, action, handle=None, nblocks=None) -> None:
        """action(values of S, (blocks × bs², column-major blocks)) on one rank (or of the SeqSBAIJ
        matrix at ``handle`` with ``nblocks`` blocks); its state changes."""
        ctypes, lib, _, _ = _petsc_library()
        handle = ctypes.c_void_p(self.S.handle if handle is None else handle)
        v = ctypes.POINTER(ctypes.c_double)()
        if lib.MatSeqSBAIJGetArray(handle, ctypes.byref(v)):
            raise RuntimeError("MatSeqSBAIJGetArray failed")
        try:
            n = int(self.bi[-1]) if nblocks is None else nblocks
            action(np.ctypeslib.as_array(v, shape=(n * self.bs ** 2,)) if n else np.zeros(0))
        finally:
            lib.MatSeqSBAIJRestoreArray(handle, ctypes.byref(v))

    @property
    def direct(self) -> bool:
        """Whether a tangent can be assembled into S itself (the compiled loops)."""
        return self._compiled is not None or self._split is not None

    def assemble_upper(self, assemble) -> None:
        """S = ``assemble(bi, bj, values, off)`` (the tangent's upper block triangle, written in
        place: :meth:`dolfinx_corot.assembly.cells.CellAssembler.assemble_upper`); A's values are
        now out of date until :meth:`sync`. The diagonal is kept (:meth:`diagonal`). Several
        ranks: the owned block columns into S's diagonal block, the higher ranks' columns and the
        rows of ghost nodes (handed back by ``assemble``) by ``MatSetValuesBlocked``."""
        bs = self.bs
        if self._split is not None:
            self._assemble_split(assemble)
            return

        def action(values):
            assemble(self.bi, self.bj, values, None)
            self._diagonal = values.reshape(-1, bs * bs)[self.bi[:-1], :: bs + 1].ravel()

        self._upper_values(action)
        self._recheck_product()
        self.upper_newer = True
        self.assembled = True
        # A's diagonal follows (its state changes): the Jacobi smoothers of a kept hierarchy,
        # which read A's diagonal, take each new tangent's as they did when A was assembled
        from . import cells

        with SeqAIJArrays(self.A, write=True) as (indptr, indices, a):
            cells.set_diagonal(indptr, indices, a, self._diagonal)
        self._state = self.A.stateGet()
        self._keep_diagonal()

    def _assemble_split(self, assemble) -> None:
        from . import cells

        bi_d, bj_d, R, C, _pos, oi, first = self._split
        S, out_o, ghosts = self.S, self._off_values, []
        S.zeroEntries()
        self._upper_values(lambda values: ghosts.append(assemble(bi_d, bj_d, values, (oi, C.ravel(), out_o, first))),
                           handle=S.getDiagonalBlock().handle, nblocks=int(bi_d[-1]))
        if len(R):
            S.setValuesBlockedRCV(R, C, out_o, addv=PETSc.InsertMode.ADD_VALUES)
        rows, columns, ghost = ghosts[0]
        if len(rows):  # lower blocks among them are dropped (IGNORE_LOWER_TRIANGULAR)
            S.setValuesBlockedLocalRCV(rows, columns, ghost, addv=PETSc.InsertMode.ADD_VALUES)
        S.assemble()
        self._recheck_product()
        S.getDiagonal(self._diagonal_vec)
        self._diagonal = self._diagonal_vec.array_r.copy()
        self.upper_newer = True
        self.assembled = True
        with MPIAIJArrays(self.A, write=True) as ((indptr, indices, a), _off, _colmap):
            cells.set_diagonal(indptr, indices, a, self._diagonal)
        self.A.assemble()  # (its state changes: the smoothers read its diagonal)
        self._state = self.A.stateGet()
        self._keep_diagonal()

    def sync(self) -> None:
        """A = S and its mirror image (A's pattern, lower triangle included), where S was assembled
        after A; A's state changes, so that preconditioners set up from it anew. Several ranks:
        PETSc's conversion of a copy of S into a new AIJ matrix added into A (the AMG's set-up:
        rare)."""
        if not self.upper_newer:
            return
        if self._split is not None:
            # (of a copy: PETSc 3.18's conversion leaves the MPISBAIJ matrix it reads broken)
            copy = self.S.duplicate(copy=True)
            full = copy.convert("aij")
            self.A.zeroEntries()
            self.A.axpy(1.0, full, structure=PETSc.Mat.Structure.SUBSET_NONZERO_PATTERN)
            destroy(full, copy)
            self.upper_newer = False
            self._state = self.A.stateGet()
            self._keep_diagonal()  # (A = S: its diagonal is S's)
            return
        from . import cells

        def mirror(values):
            with SeqAIJArrays(self.A, write=True) as (indptr, indices, a):
                cells.aij_from_upper(self.bi, self.bj, values, self.bs, indptr, indices, a)

        self._upper_values(mirror)
        self.upper_newer = False
        self._state = self.A.stateGet()
        self._keep_diagonal()  # (A = S: its diagonal is S's)

    def diagonal(self) -> np.ndarray:
        """The diagonal of the tangent last assembled by :meth:`assemble_upper`: its diagonal
        blocks' diagonals (the diagonal block is the first of its block row)."""
        return self._diagonal

    def refresh(self) -> None:
        """S = A's upper triangle, if A changed since the last refresh (nothing to do when S was
        assembled after A: :meth:`assemble_upper`)."""
        if self.upper_newer:
            return
        state = self.A.stateGet()
        if state == self._state:
            return
        S = self.S
        if self._compiled is not None:
            ctypes, lib, p_int, int_t = _petsc_library()
            handle, v = ctypes.c_void_p(S.handle), ctypes.POINTER(ctypes.c_double)()
            if lib.MatSeqSBAIJGetArray(handle, ctypes.byref(v)):
                raise RuntimeError("MatSeqSBAIJGetArray failed")
            try:
                out = np.ctypeslib.as_array(v, shape=(int(self.bi[-1]) * self.bs ** 2,))
                with SeqAIJArrays(self.A, write=False) as (indptr, indices, values):
                    self._compiled(indptr, indices, values, self.bs, self.bi, self.bj, out)
            finally:
                lib.MatSeqSBAIJRestoreArray(handle, ctypes.byref(v))  # S's state changes
        elif self.serial:
            S.zeroEntries()
            with SeqAIJArrays(self.A, write=False) as (indptr, indices, values):
                S.setValuesCSR(indptr, indices, values)
            S.assemble()
        elif self._split is not None:
            self._refresh_split()
        else:
            self.A.setOption(PETSc.Mat.Option.SYMMETRIC, True)
            self.A.convert("sbaij", S)
        self._recheck_product()
        self._state = self.A.stateGet()

    def _refresh_split(self) -> None:
        """Several ranks: S's diagonal block copied from A's by the compiled loop, the few blocks
        of higher ranks' columns (the interface's) inserted from A's off-diagonal block; no
        communication (on the 116 k-dof block, 2 ranks: PETSc's MatConvert took 47 ms a copy)."""
        from . import cells

        bi_d, bj_d, R, C, pos, _oi, _first = self._split
        Sd = self.S.getDiagonalBlock()
        with MPIAIJArrays(self.A, write=False) as ((indptr, indices, values), (_ip, _ix, v), _colmap):
            self._upper_values(lambda out: cells.upper_blocks(indptr, indices, values, self.bs, bi_d, bj_d, out),
                               handle=Sd.handle, nblocks=int(bi_d[-1]))
            V = np.where(pos >= 0, v[np.maximum(pos, 0)] if len(v) else 0.0, 0.0)
        if len(R):
            self.S.setValuesBlockedRCV(R, C, V, addv=PETSc.InsertMode.INSERT_VALUES)
        self.S.assemble()

    def destroy(self) -> None:
        if self._product is not None:
            self._product.forget()  # (before S is gone)
            self._product = None
        if self._kept is not None:
            self._kept.restore()
            self._kept = None
        self.S.destroy()
        if self._split is not None:
            self._diagonal_vec.destroy()


def lay_out(A: PETSc.Mat, indptr: np.ndarray, indices: np.ndarray) -> None:
    """A (made and preallocated, not yet assembled) gets the pattern (indptr, global columns) of its
    owned rows, its values zero, and is assembled; a new entry is an error afterwards. One rank,
    where A's preallocation is the pattern's to the entry: its column indices written in place
    (``MatSeqAIJSetColumnIndices``), else PETSc's insertion row by row."""
    if (A.getType() == "seqaij" and np.dtype(PETSc.IntType) == np.int32
            and int(A.getInfo()["nz_allocated"]) == int(indptr[-1])):
        ctypes, lib, p_int, _ = _petsc_library()
        indices = np.ascontiguousarray(indices, dtype=np.int32)
        if lib.MatSeqAIJSetColumnIndices(ctypes.c_void_p(A.handle), indices.ctypes.data_as(p_int)):
            raise RuntimeError("MatSeqAIJSetColumnIndices failed")
        A.assemble()
        A.zeroEntries()
    else:
        A.setPreallocationCSR((indptr.astype(PETSc.IntType), indices.astype(PETSc.IntType)))
    A.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)


def coupling_matrix(comm, sizes, ownership: tuple[int, int], entries: np.ndarray) -> PETSc.Mat:
    """AIJ matrix of the given (global row, global column) entries ((k, 2), gathered on every rank),
    laid out like a matrix of ``sizes``; inserting outside the pattern is an error."""
    start, stop = ownership
    mine = entries[(entries[:, 0] >= start) & (entries[:, 0] < stop)]
    indptr = np.searchsorted(mine[:, 0], np.arange(start, stop + 1)).astype(PETSc.IntType)
    C = PETSc.Mat().create(comm=comm)
    C.setSizes(sizes)
    C.setType("aij")
    C.setPreallocationCSR((indptr, mine[:, 1].astype(PETSc.IntType)))
    C.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
    return C


def lgmap(comm, indices: np.ndarray) -> PETSc.LGMap:
    return PETSc.LGMap().create(np.asarray(indices).astype(PETSc.IntType), comm=comm)


def near_nullspace(comm, imap, block_size: int, modes: Sequence[np.ndarray]) -> PETSc.NullSpace:
    """Orthonormalized near-nullspace from owned nodal arrays ``modes`` ((n_owned, block_size) each)."""
    vecs = []
    for m in modes:
        vec = dolfinx.la.create_petsc_vector(imap, block_size)
        vec.array[:] = np.asarray(m).ravel()
        vecs.append(vec)
    dolfinx.la.orthonormalize(vecs)
    return PETSc.NullSpace().create(vectors=vecs, comm=comm)


def form_diagonal(a) -> np.ndarray:
    """The owned diagonal entries of the matrix of bilinear form ``a`` (no boundary conditions),
    unrolled by blocks: a stiffness scale per dof."""
    A = dolfinx.fem.petsc.assemble_matrix(a)
    A.assemble()
    diagonal = A.getDiagonal()
    values = diagonal.array.copy()
    destroy(diagonal, A)
    return values


def _orthonormalize(vectors: list) -> None:
    """Modified Gram–Schmidt in place."""
    for i, v in enumerate(vectors):
        for w in vectors[:i]:
            v.axpy(-v.dot(w), w)
        n = v.norm()
        if n > 0.0:
            v.scale(1.0 / n)


def destroy(*objects) -> None:
    for obj in objects:
        if obj is not None:
            obj.destroy()


# -- the linear solver ------------------------------------------------------------------
DENSE_LIMIT = 120  # serial LU systems up to this many dofs are factorized densely (LAPACK)
NULL_PIVOT = 1e-13  # a pivot of K scaled to a unit diagonal below this is null
#: MUMPS's errors of a workspace too small (INFOG(1): −8, −9 the factors' integer and real
#: arrays, −11, −12, −14, −15 those of the solution and its refinement, −17, −20 the
#: communication buffers), all cured by a larger ICNTL(14) (MUMPS 5 users' guide, §8)
MUMPS_WORKSPACE_ERRORS = (-8, -9, -11, -12, -14, -15, -17, -20)


_LAPACK = []


def _lapack():
    """SciPy's LAPACK wrappers (the module ``scipy.linalg._flapack``, whose functions
    ``scipy.linalg.lapack`` hands out), loaded from its file without importing the package
    ``scipy.linalg`` and all its submodules (40–70 ms of a small model's whole process); through
    ``scipy.linalg.lapack`` where SciPy keeps the module elsewhere. Python keeps one instance of an
    extension module per file, so a later ``import scipy.linalg`` shares it."""
    if _LAPACK:
        return _LAPACK[0]
    import glob
    import importlib.machinery
    import importlib.util
    import os

    spec = importlib.util.find_spec("scipy")
    found = glob.glob(os.path.join(os.path.dirname(spec.origin), "linalg", "_flapack.*so")) if spec else []
    if found:
        name = "scipy.linalg._flapack"
        loader = importlib.machinery.ExtensionFileLoader(name, found[0])
        module = importlib.util.module_from_spec(importlib.util.spec_from_file_location(name, found[0], loader=loader))
        loader.exec_module(module)
    else:
        from scipy.linalg import lapack as module
    _LAPACK.append(module)
    return module


class DenseFactor:
    """LU (LAPACK: dgetrf, or dgbtrf for a narrow band) of a small serial PETSc matrix, with LDLᵀ (Bunch–Kaufman, dsytrf)
    for the inertia of a symmetric one.

    negative: negative eigenvalues (Sylvester: the negative eigenvalues of the 1 × 1 and
    2 × 2 blocks of D); sign: the determinant's sign (LU); null_pivots: pivots at most
    ``NULL_PIVOT`` of the matrix scaled to a unit diagonal (a singular tangent, as MUMPS's
    null-pivot detection reports it)."""

    def __init__(self, A: PETSc.Mat):
        self.A = A
        self._lapack = _lapack()
        self.n = A.getSize()[0]
        self._state = None
        self.negative = 0
        self.sign = 1
        self.null_pivots = 0
        self._band: tuple | None = None  # (kl, ku) of a band factorization
        self.band = True  # narrow bands by the band LU

    def _dense(self) -> np.ndarray:
        """The matrix scaled to a unit diagonal, S K S (as MUMPS scales: pivots compare with 1;
        congruence keeps the inertia and the determinant's sign), in LAPACK's (column) order; sets S."""
        from . import dense
        indptr, indices, values = self.A.getValuesCSR()
        K = np.empty((self.n, self.n), order="F")
        self._s = np.empty(self.n)
        dense.scaled_dense(values, indptr, indices, K, self._s)
        return K

    def _ldlt_inertia(self, K: np.ndarray) -> tuple[int, int]:
        """(negative eigenvalues, null pivots) of symmetric K from Bunch–Kaufman's D."""
        f, piv, info = self._lapack.dsytrf(K, lower=1)
        if info < 0:
            raise np.linalg.LinAlgError(f"LAPACK dsytrf failed (info {info})")
        d = f.diagonal()
        if piv.min() > 0:  # 1 × 1 blocks alone: D's diagonal
            return int(np.count_nonzero(d < 0.0)), int(np.count_nonzero(np.abs(d) <= NULL_PIVOT))
        off = np.append(np.diag(f, -1), 0.0)
        # 2 × 2 blocks of D: negative ipiv entries, in pairs (k, k + 1) from the start of each
        # run of them (LAPACK; consecutive blocks may share the value)
        neg = piv < 0
        idx = np.arange(self.n)
        start = np.maximum.accumulate(np.where(neg & ~np.insert(neg[:-1], 0, False), idx, 0))
        k = np.flatnonzero(neg & ((idx - start) % 2 == 0))
        one = np.ones(self.n, dtype=bool)
        one[k] = one[k + 1] = False
        a, c, b = d[k], d[k + 1], off[k]
        mid, rad = 0.5 * (a + c), np.sqrt(0.25 * (a - c) ** 2 + b**2)
        eig = np.concatenate([d[one], mid - rad, mid + rad])
        return int(np.sum(eig < 0.0)), int(np.sum(np.abs(eig) <= NULL_PIVOT))

    def factorize(self, ldlt: bool) -> None:
        state = (self.A.stateGet(), ldlt)
        if state == self._state:
            return
        self._state = state
        self.ldlt = ldlt
        from . import dense
        indptr, indices, values = self.A.getValuesCSR()
        kl, ku = dense.bandwidths(indptr, indices)
        self._s = np.empty(self.n)
        if not ldlt and self.band and 3 * kl * (kl + ku) < self.n * self.n:
            # a band (a chain of elements numbered along it: the 45° bend's 54 dofs, kl = ku = 11):
            # LAPACK's band LU, the same partial pivoting (the column below a pivot holds no entry
            # outside the band) for a fraction of the dense work
            ab = np.empty((2 * kl + ku + 1, self.n), order="F")
            dense.scaled_band(values, indptr, indices, kl, ku, ab, self._s)
            self._f, self._piv, info = self._lapack.dgbtrf(ab, kl, ku, overwrite_ab=1)
            self._band = (kl, ku)
            pivots = self._f[kl + ku]
        else:
            # solves by LU (this SciPy has no dsytrs); the inertia from Bunch–Kaufman's D
            K = np.empty((self.n, self.n), order="F")  # (LAPACK's order: factorized in place)
            dense.scaled_dense(values, indptr, indices, K, self._s)
            self._f, self._piv, info = self._lapack.dgetrf(K, overwrite_a=not ldlt)
            self._band = None
            pivots = self._f.diagonal()
            if ldlt and info >= 0:
                self.negative, self.null_pivots = self._ldlt_inertia(K)
        if info < 0:
            raise np.linalg.LinAlgError(f"LAPACK LU failed (info {info})")
        if not ldlt:
            swaps, self.null_pivots, negative = dense.lu_summary(pivots, self._piv, NULL_PIVOT)
            self.sign = (-1) ** (swaps + negative)

    def symmetric_inertia(self) -> int:
        """Negative eigenvalues of ½(K + Kᵀ) of the current matrix (−1: singular); the factors
        of K are kept."""
        K = self._dense()
        negative, null = self._ldlt_inertia(0.5 * (K + K.T))
        return -1 if null else negative

    def solve(self, rhs: PETSc.Vec, out: PETSc.Vec) -> None:
        if self._band is not None:
            x, info = self._lapack.dgbtrs(self._f, *self._band, self._s * rhs.array_r, self._piv)
        else:
            x, info = self._lapack.dgetrs(self._f, self._piv, self._s * rhs.array_r)
        out.array[:] = self._s * x


class LinearSolver:
    """K x = b with the last tangent: MUMPS (``iterative=False``) or CG/GMRES + AMG.

    symmetric: LDLᵀ (MUMPS) and CG; nullspace: the rigid-body modes for AMG;
    fixed_rtol: a linear problem (no adaptive forcing); prolongator: the class that takes the
    finest prolongator of a new GAMG hierarchy to co-rotate it, ``(pc, block size)``
    (:class:`dolfinx_corot.assembly.amg.CorotatedProlongator`; None: hierarchies built anew)."""

    def __init__(self, comm, A: PETSc.Mat, iterative: bool, symmetric: bool, options_prefix: str = "dc_newton_",
                 nullspace: PETSc.NullSpace | None = None, fixed_rtol: bool = False, prolongator=None):
        self.comm = comm
        self.A = A
        self.iterative = iterative
        self.ksp = PETSc.KSP().create(comm)
        self.ksp.setOptionsPrefix(options_prefix)
        pc = self.ksp.getPC()
        self._fallback: PETSc.KSP | None = None
        self.fallback_solves = 0
        self.krylov_iterations = 0  # summed over iterative solves
        self._nullspace = nullspace
        if iterative:
            # CG + PETSc's smoothed-aggregation AMG (GAMG) with the rigid-body near-nullspace
            # (of the current configuration: System.reuse_preconditioner), one Chebyshev–Jacobi
            # sweep before and after the coarse correction, couplings weaker than 2 % dropped
            # from the aggregation graph, the hierarchy kept from step to step with its finest
            # prolongator co-rotated (System._refresh_amg, assembly/amg.py) or rebuilt. On
            # the 116 k-dof SVK block against ML (Trilinos) on a BAIJ copy: half the peak memory
            # (384 against 750 MB; ML's hierarchy alone took 318 MB, GAMG's 55 MB); AMG reads
            # the AIJ matrix the tangent is assembled into, CG and the smoothers its upper
            # triangle in nodal blocks (SymmetricBlockOperator), the coarse levels' products
            # SBAIJ copies of their operators (coarse_copies). One sweep instead of PETSc's
            # two: 1.3 times the CG iterations at 0.6 of the V-cycle's cost
            self.ksp.setType("cg" if symmetric else "gmres")
            pc.setType("gamg")
            defaults = {"pc_gamg_threshold": "0.02", "pc_gamg_reuse_interpolation": "false",
                        "mg_levels_ksp_type": "chebyshev", "mg_levels_ksp_max_it": "1",
                        "mg_levels_pc_type": "jacobi"}
            options = PETSc.Options()
            for key, value in defaults.items():
                if not options.hasName(options_prefix + key):
                    options[options_prefix + key] = value
            self.ksp.setTolerances(rtol=1e-10, atol=1e-50, max_it=500)
            A.setNearNullSpace(nullspace)
            # a tolerance given as a PETSc option is kept
            self._fixed_rtol = PETSc.Options().hasName(options_prefix + "ksp_rtol") or fixed_rtol
            # CG measures the true residual under a forcing term (set_forcing)
            self._forcing_norm = (symmetric and not options.hasName(options_prefix + "ksp_norm_type")
                                  and options.getBool(options_prefix + "forcing_true_residual", True))
        else:
            self.ksp.setType("preonly")
            pc.setType("cholesky" if symmetric else "lu")
            pc.setFactorSolverType("mumps")
            self._fixed_rtol = True
            self._forcing_norm = False
        self.ksp.setFromOptions()
        self.ksp.setOperators(A)
        # CG reads the tangent's upper triangle in nodal blocks; AMG is built from A itself
        # (:class:`SymmetricBlockOperator`; ``-<prefix>block_operator false``: A alone)
        self.operator: SymmetricBlockOperator | None = None
        self._block_operator = (iterative and symmetric and A.getBlockSize() > 1
                                and PETSc.Options().getBool(options_prefix + "block_operator", True))
        # the AMG hierarchy kept from step to step, its finest prolongator co-rotated
        # (:mod:`dolfinx_corot.assembly.amg`; ``-<prefix>amg_corotate false``: built anew each time)
        self.prolongator = None
        self._prolongator_type = prolongator
        self.corotation = (iterative and prolongator is not None
                           and PETSc.Options().getBool(options_prefix + "amg_corotate", True))
        self._take_prolongator = self.corotation
        # the coarse levels' products by nodal-block copies of their operators (coarse_copies)
        self._symmetric = symmetric
        self._coarse: dict[int, CopiedProduct] = {}
        self.solves = 0  # iterative solves
        self._reusing = False  # the preconditioner is kept for the next solve (not set up from A)
        self.mumps = self.ksp.getType() == "preonly" and pc.getType() in ("lu", "cholesky") \
            and pc.getFactorSolverType() == "mumps"
        self.ldlt = self.mumps and pc.getType() == "cholesky"
        # a small tangent on one rank that is factorized by LU (3D frames and shells: their
        # tangent is not symmetric) goes to LAPACK, and so does the LDLᵀ of its symmetric part
        # that counts its inertia: the same determinant's sign and inertia, null pivots reported
        # alike, without MUMPS's set-up (the 45° bend, 54 dofs: 134 → 89 ms for 100 iterations).
        # LDLᵀ stays with MUMPS, which factorizes a banded 54-dof matrix in 0.11 ms against
        # LAPACK's 0.19 ms (dense LU and LDLᵀ)
        self.dense: DenseFactor | None = None
        if self.mumps and comm.size == 1 and A.getSize()[0] <= DENSE_LIMIT:
            self.dense = DenseFactor(A)
        if self.mumps:
            self._mumps_controls()
        # per factorization since the last :meth:`take_inertia`: negative eigenvalues (LDLᵀ) or
        # the sign of the determinant (LU: +1 even, −1 odd)
        self._inertia: list[int] = []
        self._signs: list[int] = []

    def _mumps_controls(self) -> None:
        """Null-pivot detection (ICNTL 24): a singular tangent is reported, not solved; LU also
        computes the determinant (ICNTL 33), whose sign is the parity of the number of negative
        real eigenvalues."""
        pc = self.ksp.getPC()
        pc.setFactorSetUpSolverType()
        pc.getFactorMatrix().setMumpsIcntl(24, 1)
        if not self.ldlt:
            pc.getFactorMatrix().setMumpsIcntl(33, 1)

    def set_symmetric(self, symmetric: bool) -> None:
        """A direct solver factorizes the next tangents by LDLᵀ (``symmetric``) or LU; no change
        for iterative solvers or when it already does."""
        if not self.mumps or bool(symmetric) == self.ldlt:
            return
        pc = self.ksp.getPC()
        pc.setType("cholesky" if symmetric else "lu")
        pc.setFactorSolverType("mumps")
        self.ldlt = bool(symmetric)
        self._mumps_controls()

    def solve(self, rhs: PETSc.Vec, out: PETSc.Vec) -> None:
        """out = K⁻¹ rhs; raises numpy.linalg.LinAlgError for a failed solve or a singular K."""
        if self._dense_lu():
            self._dense_factorize()
            self.dense.solve(rhs, out)
            return
        operator = self.block_operator()
        setup = not self._reusing
        if operator is not None:
            operator.refresh()
            if setup:  # the preconditioner is set up from A: A's values from S
                operator.sync()
        if self.iterative and self.ksp.getPC().getType() == "gamg":
            self.ksp.setUp()  # the hierarchy, (re)built where it must be
            self._coarse = coarse_copies(self.ksp.getPC(), self._symmetric, self._coarse)
        self.ksp.solve(rhs, out)
        reason = self.ksp.getConvergedReason()
        if self.iterative:
            self.krylov_iterations += self.ksp.getIterationNumber()
            self.solves += 1
            if self._take_prolongator and reason >= 0:
                self._keep_prolongator()
        if reason < 0 and self.iterative:
            # CG + GAMG fails on an indefinite tangent (past a bifurcation or a limit point):
            # this solve is repeated with a sparse LU (MUMPS); the next ones try CG again
            logger.warning("CG + GAMG failed (PETSc reason %d after %d iterations): solving with MUMPS LU",
                           reason, self.ksp.getIterationNumber())
            reason = self._direct_solve(rhs, out)
            self.prolongator = None  # the next hierarchy is built anew
        if reason < 0 and self.mumps:
            reason = self._mumps_retry(rhs, out)
        if reason < 0:
            raise np.linalg.LinAlgError(f"linear solve failed (PETSc reason {reason}{self._mumps_error()}); "
                                        "the tangent may be singular (a missing support?)")
        if self.mumps:
            F = self.ksp.getPC().getFactorMatrix()
            null_pivots = F.getMumpsInfog(28)
            if self.ldlt:
                self._inertia.append(int(F.getMumpsInfog(12)))
            elif null_pivots == 0:
                self._signs.append(1 if F.getMumpsRinfog(12) >= 0.0 else -1)
            if null_pivots > 0:
                raise np.linalg.LinAlgError(
                    f"the tangent stiffness is singular ({null_pivots} zero pivot(s)): a missing support "
                    "(rigid-body motion), a mechanism, or a limit point under load control")

    def block_operator(self) -> SymmetricBlockOperator | None:
        """The upper block triangle CG and the smoothers apply (made on first use from A's
        pattern), or None where CG reads A itself."""
        if self._block_operator and self.operator is None:
            self.operator = SymmetricBlockOperator(self.A)
            self.ksp.setOperators(self.operator.S, self.A)
        return self.operator

    def sync_aij(self) -> None:
        """A's values from the block operator, where the tangent was assembled into it alone."""
        if self.operator is not None:
            self.operator.sync()

    def _mumps_retry(self, rhs: PETSc.Vec, out: PETSc.Vec) -> int:
        """A factorization that MUMPS stopped for want of workspace is done again with twice the
        extra space (ICNTL 14, the percentage added to the analysis's estimate; kept for the later
        factorizations), up to four times. The estimate can fall short where numerical pivoting
        delays pivots (an unsymmetric contact tangent by LU), and on several ranks by a margin that
        varies from run to run with MUMPS's dynamic scheduling. PETSc's reason of the last
        attempt."""
        reason = self.ksp.getConvergedReason()
        F = self.ksp.getPC().getFactorMatrix()
        for _ in range(4):
            if F.getMumpsInfog(1) not in MUMPS_WORKSPACE_ERRORS:
                break
            extra = max(2 * int(F.getMumpsIcntl(14)), 50)
            logger.warning("MUMPS ran out of workspace (INFOG(1) = %d): factorizing again with ICNTL(14) = %d",
                           F.getMumpsInfog(1), extra)
            F.setMumpsIcntl(14, extra)
            self.A.assemble()  # (its state changes: the factorization is made again)
            self.ksp.solve(rhs, out)
            reason = self.ksp.getConvergedReason()
            if reason >= 0:
                break
        return reason

    def _mumps_error(self) -> str:
        """MUMPS's error code after a failed solve (INFOG(1), 0 if none), for the message."""
        if not self.mumps:
            return ""
        return f", MUMPS INFOG(1) = {int(self.ksp.getPC().getFactorMatrix().getMumpsInfog(1))}"

    def _direct_solve(self, rhs: PETSc.Vec, out: PETSc.Vec) -> int:
        self.sync_aij()
        if self._fallback is None:
            self._fallback = PETSc.KSP().create(self.comm)
            self._fallback.setType("preonly")
            pc = self._fallback.getPC()
            pc.setType("lu")
            pc.setFactorSolverType("mumps")
        self._fallback.setOperators(self.A)
        self._fallback.solve(rhs, out)
        self.fallback_solves += 1
        return self._fallback.getConvergedReason()

    def set_forcing(self, eta: float | None) -> None:
        """Relative tolerance of the next iterative solves (inexact Newton; None: back to 1e-10);
        ignored by direct solvers and when ``-<prefix>ksp_rtol`` was given.

        Under a forcing term CG measures the true residual ‖b − Kx‖ (the unpreconditioned
        norm), the one the forcing term bounds (Eisenstat & Walker 1996: ‖F + J s‖ ≤ η‖F‖).
        With PETSc's default, the preconditioned norm ‖M⁻¹(b − Kx)‖, what η bought depended on
        the preconditioner: Newton's residual on the 116 k-dof block fell by about 3·10⁻³ an
        iteration whatever η asked, and by less on two ranks, whose AMG differs (25 Newton
        iterations serially, 27 on two ranks; with the true residual and NewtonOptions' looser
        tolerances it allows, 21 on both, docs/performance.md).
        Without a forcing term (a linear solve to 1e-10) the preconditioned norm is kept: the
        true residual of an ill-conditioned tangent stalls near round-off. ``-<prefix>forcing_true_residual
        false``: the preconditioned norm throughout; a ``-<prefix>ksp_norm_type`` given is kept."""
        if self.iterative and not self._fixed_rtol:
            self.ksp.setTolerances(rtol=1e-10 if eta is None else eta)
            if self._forcing_norm and self.ksp.getType() == "cg":
                self.ksp.setNormType(PETSc.KSP.NormType.PRECONDITIONED if eta is None
                                     else PETSc.KSP.NormType.UNPRECONDITIONED)

    def set_near_nullspace(self, nullspace: PETSc.NullSpace) -> None:
        """AMG's near-nullspace from the next preconditioner on. GAMG keeps the modes of its
        first set-up for all later ones, so the preconditioner is made anew (its hierarchy is
        rebuilt at the next solve in any case) from the same options."""
        if not self.iterative:
            return
        self.A.setNearNullSpace(nullspace)
        if self._nullspace is not None:
            self._nullspace.destroy()
        self._nullspace = nullspace
        pc = self.ksp.getPC()
        if pc.getType() == "gamg":
            pc.setType("none")
            pc.setType("gamg")
            pc.setFromOptions()
        self.prolongator = None
        self._take_prolongator = self.corotation
        self._reusing = False  # a new preconditioner is set up at the next solve

    def _keep_prolongator(self) -> None:
        """After the first solve with a new GAMG hierarchy: its finest prolongator, to be
        co-rotated (:meth:`corotate`); none where it cannot be."""
        self._take_prolongator = False
        pc = self.ksp.getPC()
        if pc.getType() != "gamg":
            return
        try:
            self.prolongator = self._prolongator_type(pc, self.A.getBlockSize())
        except ValueError as err:
            logger.debug("the AMG hierarchy is built anew at each step: %s", err)
            self.prolongator = None

    def corotate(self, rotations: np.ndarray) -> bool:
        """Keep the AMG hierarchy for the next tangents, its finest prolongator turned by the
        nodal rotations since it was built (``rotations``: (owned nodes, bs, bs)), its coarse
        operators as they are: for a tangent that is the built one turned, K = Q K⁰ Qᵀ, the
        Galerkin product (QP⁰)ᵀ K (QP⁰) = P⁰ᵀ K⁰ P⁰ is the one built (docs/theory.md). The
        preconditioner is reused until it is made anew. False (nothing done) where there is no
        such hierarchy: none yet, built anew by PETSc since (a new pattern), or not of nodal rows."""
        pc = self.ksp.getPC()
        if self.prolongator is None or not self.prolongator.current(pc):
            self.prolongator = None
            return False
        self.prolongator.rotate(rotations)
        # should PETSc set the hierarchy up again (a new pattern of the same operator), it keeps
        # the turned prolongators and makes the Galerkin products only
        ctypes, lib, _, _ = _petsc_library()
        if lib.PCGAMGSetReuseInterpolation(ctypes.c_void_p(pc.handle), ctypes.c_int(1)):
            raise RuntimeError("PCGAMGSetReuseInterpolation failed")
        pc.setReusePreconditioner(True)
        self._reusing = True
        return True

    def reuse_preconditioner(self, reuse: bool) -> None:
        """Keep the preconditioner of an earlier tangent for the next iterative solves."""
        if self.iterative:
            self.ksp.getPC().setReusePreconditioner(bool(reuse))
            self._reusing = bool(reuse)

    def negative_eigenvalues(self) -> int | None:
        """Number of negative eigenvalues of the last factorized tangent (LDLᵀ only; else None)."""
        if not self.ldlt:
            return None
        return int(self.ksp.getPC().getFactorMatrix().getMumpsInfog(12))

    def factorize(self) -> None:
        """Factorize the current tangent now (direct solvers; the next solve reuses it) and note
        its inertia as a solve does."""
        if not self.mumps:
            return
        if self._dense_lu():
            try:
                self._dense_factorize()
            except np.linalg.LinAlgError:
                pass  # a singular tangent: reported by the next solve, as MUMPS does
            return
        self.ksp.setUp()
        self.ksp.getPC().setUp()  # refactors when the matrix changed since the last set-up
        F = self.ksp.getPC().getFactorMatrix()
        if F.getMumpsInfog(28) > 0:
            return
        if self.ldlt:
            self._inertia.append(int(F.getMumpsInfog(12)))
        else:
            self._signs.append(1 if F.getMumpsRinfog(12) >= 0.0 else -1)

    def _dense_lu(self) -> bool:
        """Whether the next factorization is LAPACK's (a small serial LU)."""
        return self.dense is not None and not self.ldlt

    def _dense_factorize(self) -> None:
        """LU of the dense tangent when it changed since the last factorization, its determinant's
        sign noted as MUMPS's is at every solve; raises LinAlgError for null pivots."""
        d = self.dense
        d.factorize(False)
        if d.null_pivots:
            raise np.linalg.LinAlgError(
                f"the tangent stiffness is singular ({d.null_pivots} zero pivot(s)): a missing support "
                "(rigid-body motion), a mechanism, or a limit point under load control")
        self._signs.append(d.sign)

    def take_inertia(self) -> tuple[list[int], list[int]]:
        """(negative-eigenvalue counts, determinant signs) of the factorizations since the last call."""
        out = (self._inertia, self._signs)
        self._inertia, self._signs = [], []
        return out

    def _symmetric_copy(self, scale_constrained: np.ndarray | None = None) -> PETSc.Mat:
        """½(A + Aᵀ) as AIJ; the rows and columns ``scale_constrained`` (global) get the diagonal
        max|diag A| instead of 1, so that supports do not pose as soft modes."""
        self.sync_aij()
        A = self.A
        S = A.copy()
        T = A.transpose(PETSc.Mat())
        S.axpy(1.0, T, PETSc.Mat.Structure.DIFFERENT)
        T.destroy()
        S.scale(0.5)
        if scale_constrained is not None:
            d = S.getDiagonal()
            big = max(d.norm(PETSc.NormType.INFINITY), 1e-300)
            d.destroy()
            start, stop = S.getOwnershipRange()
            rows = scale_constrained[(scale_constrained >= start) & (scale_constrained < stop)]
            S.zeroRowsColumns(rows.astype(PETSc.IntType), big)
        return S

    def inertia(self) -> int:
        """Number of negative eigenvalues of the symmetric part of the last assembled tangent, by an
        LDLᵀ factorization of its own (for LU and iterative solvers, which do not count them);
        −1 if that matrix is singular."""
        if self.dense is not None:
            return self.dense.symmetric_inertia()
        S = self._symmetric_copy()
        S.setOption(PETSc.Mat.Option.SYMMETRIC, True)
        ksp = PETSc.KSP().create(self.comm)
        ksp.setType("preonly")
        ksp.getPC().setType("cholesky")
        ksp.getPC().setFactorSolverType("mumps")
        ksp.setOperators(S)
        ksp.getPC().setFactorSetUpSolverType()
        F = ksp.getPC().getFactorMatrix()
        F.setMumpsIcntl(24, 1)
        ksp.setUp()
        F = ksp.getPC().getFactorMatrix()
        count = -1 if F.getMumpsInfog(28) > 0 else int(F.getMumpsInfog(12))
        destroy(F, ksp, S)  # (the factor's handle holds a reference of its own)
        return count

    def smallest_eigenvalue(self, constrained: np.ndarray) -> float:
        """The eigenvalue closest to zero of the symmetric part of the last assembled tangent with
        the constrained dofs taken out (SLEPc, shift-and-invert about 0)."""
        from slepc4py import SLEPc

        S = self._symmetric_copy(constrained)
        eps = SLEPc.EPS().create(self.comm)
        eps.setOperators(S)
        eps.setProblemType(SLEPc.EPS.ProblemType.HEP)
        eps.setDimensions(1)
        eps.setTarget(0.0)
        eps.setWhichEigenpairs(SLEPc.EPS.Which.TARGET_MAGNITUDE)
        st = eps.getST()
        st.setType("sinvert")
        ksp = st.getKSP()
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        eps.setTolerances(1e-10, 200)
        eps.solve()
        value = eps.getEigenvalue(0).real if eps.getConverged() > 0 else float("nan")
        eps.destroy()
        S.destroy()
        return float(value)

    def null_space(self, constrained: np.ndarray, vectors: list, iterations: int = 4) -> list[float]:
        """The softest motions of the last assembled tangent (its null space when it is singular)
        by subspace inverse iteration on K + σ·max|diag K| (σ = 1e-9), the constrained dofs taken
        out: ``vectors`` (orthonormal on return, softest first); returns their Rayleigh
        quotients ‖K v‖/max|diag K|."""
        S = self._symmetric_copy(constrained)
        d = S.getDiagonal()
        big = max(d.norm(PETSc.NormType.INFINITY), 1e-300)
        d.destroy()
        K = S.copy()
        S.shift(1e-9 * big)
        ksp = PETSc.KSP().create(self.comm)
        ksp.setType("preonly")
        ksp.getPC().setType("lu")
        ksp.getPC().setFactorSolverType("mumps")
        ksp.setOperators(S)
        start, stop = S.getOwnershipRange()
        idx = np.arange(start, stop)
        work = vectors[0].duplicate()
        for k, v in enumerate(vectors):  # start vectors that every partition builds alike
            v.array[:] = np.sin(idx * (0.37 + 0.61 * k) + k)
        for _ in range(iterations):
            for v in vectors:
                v.copy(work)
                ksp.solve(work, v)
            _orthonormalize(vectors)
        quotients = []
        for v in vectors:
            K.mult(v, work)
            quotients.append(work.norm() / big)
        order = np.argsort(quotients)
        copies = [vectors[i].copy() for i in order]
        for v, c in zip(vectors, copies):
            c.copy(v)
        destroy(ksp, S, K, work, *copies)
        return [float(quotients[i]) for i in order]

    def destroy(self) -> None:
        for product in self._coarse.values():
            product.restore()
        self._coarse = {}
        destroy(self._fallback, self.ksp, self.operator)


def solve_constrained(comm, A: PETSc.Mat, rows: np.ndarray, values: np.ndarray) -> np.ndarray | None:
    """x with x = ``values`` (owned entries) on the global ``rows`` and A x = 0 on the others
    (MatZeroRowsColumns with the lifting of the imposed values, MUMPS LU); None when the
    reduced matrix is singular. Destroys A."""
    x, b = A.createVecs()
    x.array[:] = values
    b.set(0.0)
    A.zeroRowsColumns(np.asarray(rows, dtype=PETSc.IntType), 1.0, x, b)
    ksp = PETSc.KSP().create(comm)
    ksp.setType("preonly")
    ksp.getPC().setType("lu")
    ksp.getPC().setFactorSolverType("mumps")
    ksp.setOperators(A)
    ksp.getPC().setFactorSetUpSolverType()
    ksp.getPC().getFactorMatrix().setMumpsIcntl(24, 1)  # null pivots are reported
    ksp.setUp()
    out = None
    if ksp.getPC().getFactorMatrix().getMumpsInfog(28) == 0:
        ksp.solve(b, x)
        out = x.array.copy()
    destroy(ksp, A, x, b)
    return out

