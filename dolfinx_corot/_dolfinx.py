"""The one module that touches DOLFINx 0.5.2's private API (its C++ layer and private helpers).

* :func:`kernel_form`: a numba ``cfunc`` element kernel (ufcx ``tabulate_tensor``
  signature) as a ``dolfinx.cpp.fem.Form_float64`` on a part's function space,
  so that DOLFINx handles dofmaps, ghosts, sparsity and Dirichlet rows
  (dolfinx-0.5 notes §2).
* :func:`index_map`, :func:`sparsity_pattern`, :func:`petsc_matrix`,
  :func:`petsc_vector`: a global numbering and a matrix over several meshes
  (parts stacked by :class:`dolfinx_corot.assembly.layout.DofLayout`); only
  :mod:`dolfinx_corot.assembly.petsc` calls the two PETSc factories.
* :func:`form_sparsity`: the nodal block pattern DOLFINx lays out a form's matrix from (so that
  the matrix's pattern can be made without DOLFINx's first assembly).
* :func:`assemble_matrix_into`: a form's matrix added to an existing PETSc
  matrix through its current local-to-global map (no Dirichlet rows).
* :func:`assemble_vector_into`, :func:`assemble_matrix_with_bcs`: DOLFINx's own assembly into
  an existing vector or matrix, called as its Python layer calls it, without that layer's
  dispatch (on a model of a few elements it costs as much as the kernels).
* :func:`dirichletbc`: a Dirichlet condition on a subspace, given to DOLFINx as its C++ space
  (given the Python one, DOLFINx 0.5.2 first fails a constructor whose error message prints
  the dofs: 180 against 20 µs a condition).
* :func:`function_space`: a Lagrange or DG function space whose C++ element is made once per
  process and element (DOLFINx 0.5.2 takes 10–100 ms to build one from its ufcx element,
  which every space made the public way pays again).
"""
from __future__ import annotations

import weakref
from typing import Sequence

import numpy as np

import dolfinx
import dolfinx.cpp
import dolfinx.fem
import dolfinx.fem.petsc
import dolfinx.mesh


# forms of compiled kernels that the compiled loop of assembly.cells may assemble: their kernel
_CELL_KERNELS: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def kernel_form(V: dolfinx.fem.FunctionSpace, kernel_address: int, rank: int,
                coefficients: Sequence[dolfinx.fem.Function], constants: Sequence[dolfinx.fem.Constant],
                cells: np.ndarray | None = None, loop: bool = False):
    """A DOLFINx form whose cell integral is a compiled kernel.

    V: the argument space (test, and trial for rank 2); kernel_address: the
    address of a compiled kernel (a numba cfunc, a C function); coefficients are
    packed into ``w`` in order, constants into ``c``; cells: owned cells to
    integrate over (all if None); loop: the form's matrix may be assembled by
    :class:`dolfinx_corot.assembly.cells.CellAssembler` (:func:`cell_integrals`).
    """
    mesh = V.mesh
    if cells is None:
        integrals = {dolfinx.cpp.fem.IntegralType.cell: ([(-1, kernel_address)], None)}
    else:
        tdim = mesh.topology.dim
        cells = np.unique(np.asarray(cells, dtype=np.int32))
        tags = dolfinx.mesh.meshtags(mesh, tdim, cells, np.ones(len(cells), dtype=np.int32))
        integrals = {dolfinx.cpp.fem.IntegralType.cell: ([(1, kernel_address)], tags)}
    spaces = [V._cpp_object] * rank
    form = dolfinx.cpp.fem.Form_float64(spaces, integrals, [c._cpp_object for c in coefficients],
                                        [c._cpp_object for c in constants], False)
    if loop:
        _CELL_KERNELS[form] = kernel_address
    return form


def index_map(comm, n_owned: int, ghosts: np.ndarray, owners: np.ndarray):
    """A scalar IndexMap: ``n_owned`` owned indices, then ``ghosts`` (global) owned by ``owners``."""
    return dolfinx.cpp.common.IndexMap(comm, n_owned, ghosts.astype(np.int64), owners.astype(np.int32))


def sparsity_pattern(comm, imap, blocks: Sequence[np.ndarray], n_owned: int):
    """The assembled pattern over ``imap`` of the dense couplings of each row of every array in
    ``blocks`` ((k, n) local indices), with the owned diagonal."""
    sp = dolfinx.cpp.la.SparsityPattern(comm, [imap, imap], [1, 1])
    for dofs in blocks:
        for row in dofs:
            sp.insert(row, row)
    sp.insert_diagonal(np.arange(n_owned, dtype=np.int32))
    sp.assemble()
    return sp


def form_sparsity(form):
    """The nodal block pattern of the owned rows of the matrix DOLFINx makes for the bilinear
    ``form`` (``dolfinx.fem.petsc.create_matrix`` lays it out from the same): (offsets, local block
    columns, their global indices) of its block rows."""
    spaces = form.function_spaces
    sp = dolfinx.cpp.fem.create_sparsity_pattern(form.mesh.topology, [spaces[0].dofmap, spaces[1].dofmap],
                                                 form.integral_types)
    sp.assemble()
    n = sp.index_map(0).size_local
    columns = sp.column_index_map()
    offsets = np.asarray(sp.graph.offsets, dtype=np.int64)[: n + 1]
    links = np.asarray(sp.graph.array[: offsets[-1]], dtype=np.int32)
    to_global = np.asarray(columns.local_to_global(np.arange(columns.size_local + columns.num_ghosts, dtype=np.int32)),
                           dtype=np.int64)
    return offsets, links, to_global


def petsc_matrix(comm, pattern):
    """A PETSc AIJ matrix of an assembled sparsity pattern (local-to-global map set)."""
    return dolfinx.cpp.la.petsc.create_matrix(comm, pattern)


def petsc_vector(imap, block_size: int = 1):
    """A ghosted PETSc vector over an IndexMap."""
    return dolfinx.cpp.la.petsc.create_vector(imap, block_size)


def assemble_vector_into(array: np.ndarray, form) -> None:
    """array += the vector of ``form`` (local entries, owned and ghost), as
    ``dolfinx.fem.petsc.assemble_vector`` does it."""
    dolfinx.cpp.fem.assemble_vector(array, form, dolfinx.cpp.fem.pack_constants(form),
                                    dolfinx.cpp.fem.pack_coefficients(form))


def assemble_matrix_with_bcs(A, form, bcs: list, space) -> None:
    """A += the matrix of ``form`` with the rows and columns of ``bcs`` zero and 1 on their
    diagonal (``space``: the form's test space), as ``dolfinx.fem.petsc.assemble_matrix`` does
    it; A is left to be assembled."""
    dolfinx.cpp.fem.petsc.assemble_matrix(A, form, dolfinx.cpp.fem.pack_constants(form),
                                          dolfinx.cpp.fem.pack_coefficients(form), bcs)
    A.assemblyBegin(A.AssemblyType.FLUSH)
    A.assemblyEnd(A.AssemblyType.FLUSH)
    dolfinx.cpp.fem.petsc.insert_diagonal(A, space, bcs, 1.0)


def dirichletbc(value, dofs, V: dolfinx.fem.FunctionSpace, comp: int):
    """A Dirichlet condition on component ``comp`` of V (``dolfinx.fem.dirichletbc(value, dofs,
    V.sub(comp))``, the subspace given as its C++ object)."""
    return dolfinx.fem.dirichletbc(value, dofs, V.sub(comp)._cpp_object)


def assemble_matrix_into(A, form) -> None:
    """A += the matrix of ``form`` (ADD_VALUES through A's local-to-global map; no Dirichlet rows)."""
    dolfinx.cpp.fem.petsc.assemble_matrix(A, form, dolfinx.fem.petsc._pack_constants(form),
                                          dolfinx.fem.petsc._pack_coefficients(form), [], True)


# (ufl element repr) → (C++ element, address of its ufcx dofmap, the cffi module that holds both)
_ELEMENTS: dict = {}


def function_space(mesh: dolfinx.mesh.Mesh, family: str, degree: int, dim: int | None = None,
                   scalar: bool = False) -> dolfinx.fem.FunctionSpace:
    """``dolfinx.fem.VectorFunctionSpace(mesh, (family, degree), dim=dim)`` (``scalar``:
    ``FunctionSpace(mesh, (family, degree))``), its C++ element shared by every space of the same
    element and cell in this process: only the dofmap is made per mesh (dolfinx-0.5 notes: a
    space from an existing C++ space is the public ``FunctionSpace(mesh, element, cppV)``). Collective."""
    import ufl
    from dolfinx import jit

    cell = mesh.ufl_cell()
    element = ufl.FiniteElement(family, cell, degree) if scalar else \
        ufl.VectorElement(family, cell, degree, dim=dim)
    key = repr(element)
    made = _ELEMENTS.get(key)
    if made is None:
        (ufcx_element, ufcx_dofmap), module, _ = jit.ffcx_jit(mesh.comm, element)
        ffi = module.ffi
        cpp_element = dolfinx.cpp.fem.FiniteElement(ffi.cast("uintptr_t", ffi.addressof(ufcx_element)))
        made = _ELEMENTS[key] = (cpp_element, ffi.cast("uintptr_t", ffi.addressof(ufcx_dofmap)), module)
    cpp_element, dofmap_address, _ = made
    dofmap = dolfinx.cpp.fem.create_dofmap(mesh.comm, dofmap_address, mesh.topology, cpp_element)
    try:
        cpp_space = dolfinx.cpp.fem.FunctionSpace(mesh, cpp_element, dofmap)
    except TypeError:  # the Python Mesh wraps the C++ one
        cpp_space = dolfinx.cpp.fem.FunctionSpace(mesh._mesh, cpp_element, dofmap)
    return dolfinx.fem.FunctionSpace(mesh, element, cpp_space)


def cell_integrals(form, bcs: list):
    """What :class:`dolfinx_corot.assembly.cells.CellAssembler` needs to assemble an FFCx
    bilinear form, or one of :func:`kernel_form` with ``loop``, without DOLFINx: ``(integrals,
    blocks, geometry, x, constants, coefficients, constrained, bs)``, or None for a form it does not cover (integrals other
    than cell integrals, two different spaces, elements with dof transformations, conditions
    on another space). integrals: ``(kernel address, cells, key of the packed coefficients)``;
    constants(), coefficients(): the form's packed constants and coefficients (a dict by key)."""
    import cffi

    ufcx = getattr(form, "ufcx_form", None)
    kernel = _CELL_KERNELS.get(form) if ufcx is None else None
    cell = dolfinx.cpp.fem.IntegralType.cell
    if (ufcx is None and kernel is None) or form.rank != 2 or set(form.integral_types) != {cell}:
        return None
    V0, V1 = form.function_spaces
    if V0 is not V1 and not (V0.contains(V1) and V1.contains(V0)):
        return None
    if V0.element.needs_dof_transformations:
        return None
    if not all(V0.contains(bc.function_space) for bc in bcs):
        return None
    integrals = []
    if ufcx is None:
        for i in form.integral_ids(cell):
            integrals.append((kernel, np.asarray(form.domains(cell, i), dtype=np.int32), (cell, i)))
    else:
        ffi = cffi.FFI()
        count = ufcx.num_integrals(0)
        ids = ffi.unpack(ufcx.integral_ids(0), count)
        for k, i in enumerate(ids):
            address = ufcx.integrals(0)[k].tabulate_tensor_float64
            cells = np.asarray(form.domains(cell, i), dtype=np.int32)
            integrals.append((int(ffi.cast("uintptr_t", address)), cells, (cell, i)))
    mesh = V0.mesh
    geometry = mesh.geometry.dofmap.array.reshape(-1, mesh.geometry.cmap.create_dof_layout().num_dofs)
    bs = V0.dofmap.index_map_bs
    blocks = V0.dofmap.list().array.reshape(-1, V0.dofmap.dof_layout.num_dofs)
    constrained = np.concatenate([bc.dof_indices()[0] for bc in bcs]) if bcs else np.zeros(0, dtype=np.int32)
    return (integrals, blocks, geometry, mesh.geometry.x, lambda: dolfinx.cpp.fem.pack_constants(form),
            lambda: dolfinx.cpp.fem.pack_coefficients(form), constrained, bs)
