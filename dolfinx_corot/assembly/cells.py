"""A continuum's tangent on one rank, assembled straight into the values of PETSc's AIJ matrix.

DOLFINx 0.5.2 inserts each element matrix through ``MatSetValuesLocal``, which searches its
row for every column: for trilinear hexahedra with three dofs a node (24 × 24 element
matrices) that costs as much as the FFCx kernel itself. Here a small C loop (compiled by cffi
on first use, as FFCx compiles forms, and cached on disk) calls the form's FFCx kernel cell by
cell and adds each 3 × 3 nodal block where it lies in the row: the column's place is found
once per pair of nodes, by bisection in the row's sorted columns, and serves the block's other
rows wherever their columns are laid out alike (checked; otherwise they are searched too).
Rows and columns of constrained dofs are left out and their diagonal set to 1, as DOLFINx's
``assemble_matrix`` with Dirichlet conditions and ``insert_diagonal`` do; the entries are
added in DOLFINx's order, so the matrix is the same to the last bit.

Used by :class:`~dolfinx_corot.assembly.system.System` on one rank for FFCx forms whose
integrals are all cell integrals over meshes of at least :data:`MIN_CELLS` cells.
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

MIN_CELLS = 4000  # meshes with fewer cells keep DOLFINx's insertion

_SOURCE = r"""
#include <stdint.h>
#include <string.h>

typedef void (*tabulate_t)(double*, const double*, const double*, const double*, const int*, const uint8_t*);

static int64_t find(const int32_t* indices, int64_t lo, int64_t hi, int64_t column)
{
  int64_t stop = hi;
  while (lo < hi)
  {
    int64_t mid = (lo + hi) / 2;
    if (indices[mid] < column)
      lo = mid + 1;
    else
      hi = mid;
  }
  return (lo < stop && indices[lo] == column) ? lo : -1;
}

int64_t add_cells(uintptr_t address, int64_t ncells, const int32_t* cells, int64_t nb, const int32_t* blocks,
                  int64_t ng, const int32_t* geometry, const double* x, const double* w, int64_t wstride,
                  const double* c, const int32_t* indptr, const int32_t* indices, const uint8_t* constrained,
                  int64_t bs, double* values, double* Ae, double* X, int64_t* place)
{
  tabulate_t kernel = (tabulate_t)address;
  const int64_t n = nb * bs;
  int64_t missing = 0;
  for (int64_t k = 0; k < ncells; ++k)
  {
    const int64_t cell = cells[k];
    const int32_t* nodes = blocks + cell * nb;
    for (int64_t i = 0; i < ng; ++i)
      for (int d = 0; d < 3; ++d)
        X[3 * i + d] = x[3 * (int64_t)geometry[cell * ng + i] + d];
    memset(Ae, 0, n * n * sizeof(double));
    kernel(Ae, w + k * wstride, c, X, NULL, NULL);
    int held = 0;
    for (int64_t i = 0; i < n; ++i)
      held |= constrained[nodes[i / bs] * bs + i % bs];
    for (int64_t i = 0; i < nb; ++i)
    {
      const int64_t row0 = (int64_t)nodes[i] * bs;
      const int64_t start = indptr[row0], stop = indptr[row0 + 1];
      for (int64_t j = 0; j < nb; ++j)
      {
        const int64_t col0 = (int64_t)nodes[j] * bs;
        const int64_t p = find(indices, start, stop, col0);
        const int whole = p >= 0 && p + bs <= stop && indices[p + bs - 1] == col0 + bs - 1;
        place[j] = whole ? p - start : -1;
        missing += !whole;
      }
      for (int64_t a = 0; a < bs; ++a)
      {
        const int64_t row = row0 + a;
        if (constrained[row])
          continue;
        const int64_t first = indptr[row], last = indptr[row + 1];
        double* v = values + first;
        const double* e = Ae + (i * bs + a) * n;
        for (int64_t j = 0; j < nb; ++j)
        {
          if (place[j] < 0)
            continue;
          int64_t at = place[j];
          const int64_t col0 = (int64_t)nodes[j] * bs;
          if (a > 0 && (first + at + bs > last || indices[first + at] != col0
                        || indices[first + at + bs - 1] != col0 + bs - 1))
          {
            /* this row's columns are not laid out as the node's first row's */
            const int64_t p = find(indices, first, last, col0);
            if (p < 0 || p + bs > last || indices[p + bs - 1] != col0 + bs - 1)
            {
              ++missing;
              continue;
            }
            at = p - first;
          }
          double* vj = v + at;
          const double* ej = e + j * bs;
          if (!held)
            for (int64_t b = 0; b < bs; ++b)
              vj[b] += ej[b];
          else
          {
            const uint8_t* held_j = constrained + (int64_t)nodes[j] * bs;
            for (int64_t b = 0; b < bs; ++b)
              if (!held_j[b])
                vj[b] += ej[b];
          }
        }
      }
    }
  }
  return missing;
}

int64_t set_constrained_diagonal(int64_t nrows, const int32_t* indptr, const int32_t* indices,
                                 const uint8_t* constrained, double* values)
{
  int64_t missing = 0;
  for (int64_t row = 0; row < nrows; ++row)
    if (constrained[row])
    {
      const int64_t p = find(indices, indptr[row], indptr[row + 1], row);
      if (p < 0)
        ++missing;
      else
        values[p] = 1.0;
    }
  return missing;
}
"""

_CDEF = """
int64_t add_cells(uintptr_t address, int64_t ncells, const int32_t* cells, int64_t nb, const int32_t* blocks,
                  int64_t ng, const int32_t* geometry, const double* x, const double* w, int64_t wstride,
                  const double* c, const int32_t* indptr, const int32_t* indices, const uint8_t* constrained,
                  int64_t bs, double* values, double* Ae, double* X, int64_t* place);
int64_t set_constrained_diagonal(int64_t nrows, const int32_t* indptr, const int32_t* indices,
                                 const uint8_t* constrained, double* values);
"""

_MODULE = None


def _cache_dir() -> Path:
    root = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(root) / "dolfinx_corot"


def compiled():
    """The compiled loop (cffi), built once per machine and source into the cache directory;
    a build goes to a private directory first and is moved in whole, so that processes
    building at once do not read each other's half-written files."""
    global _MODULE
    if _MODULE is not None:
        return _MODULE
    import cffi

    name = "_dc_cells_" + hashlib.sha1((_SOURCE + _CDEF + sys.version).encode()).hexdigest()[:16]
    cache = _cache_dir()
    cache.mkdir(parents=True, exist_ok=True)
    built = list(cache.glob(name + "*.so"))
    if not built:
        ffi = cffi.FFI()
        ffi.cdef(_CDEF)
        ffi.set_source(name, _SOURCE, extra_compile_args=["-O2", "-g0"])
        with tempfile.TemporaryDirectory(dir=cache) as tmp:
            library = Path(ffi.compile(tmpdir=tmp, verbose=False))
            target = cache / library.name
            os.replace(library, target)
        built = [target]
    spec = importlib.util.spec_from_file_location(name, built[0])
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    _MODULE = module
    return module


class CellAssembler:
    """The tangent of an FFCx bilinear form on one rank, added into the values of a SeqAIJ
    matrix that DOLFINx made for it (its pattern; see the module's docstring).

    integrals: ``(kernel address, cells, key)`` per cell integral; blocks: the space's dofmap
    (cells × nodes); geometry, x: the mesh's geometry dofmap and coordinates; constants(),
    coefficients(): the form's packed constants and its packed coefficients by key;
    constrained: the scalar dofs of the Dirichlet conditions; bs: dofs a node; size: scalar
    dofs (all of :func:`dolfinx_corot._dolfinx.cell_integrals`)."""

    def __init__(self, integrals, blocks, geometry, x, constants, coefficients, constrained: np.ndarray, bs: int,
                 size: int):
        self.integrals = [(address, np.ascontiguousarray(cells, dtype=np.int32), key)
                          for address, cells, key in integrals]
        self.blocks = np.ascontiguousarray(blocks, dtype=np.int32)
        self.geometry = np.ascontiguousarray(geometry, dtype=np.int32)
        self.x = np.ascontiguousarray(x, dtype=np.float64)  # (a copy if x is not contiguous)
        self.constants = constants
        self.coefficients = coefficients
        self.bs = bs
        self.constrained = np.zeros(size, dtype=np.bool_)
        self.constrained[constrained] = True

    def assemble(self, indptr, indices, values) -> None:
        """values (the matrix's CSR values, zeroed) += the form's tangent; raises RuntimeError
        if the pattern lacks an entry the form needs."""
        module = compiled()
        ffi, lib = module.ffi, module.lib

        def ptr(kind, a):
            return ffi.cast(kind + "*", a.ctypes.data)

        c = np.ascontiguousarray(self.constants(), dtype=np.float64)
        if c.size == 0:
            c = np.zeros(1)
        packed = self.coefficients()
        n = self.blocks.shape[1] * self.bs
        Ae = np.empty(n * n)
        X = np.empty(3 * self.geometry.shape[1])
        place = np.empty(self.blocks.shape[1], dtype=np.int64)
        held = self.constrained.view(np.uint8)
        missing = 0
        for address, cells, key in self.integrals:
            w = np.ascontiguousarray(packed[key], dtype=np.float64)
            if w.size == 0:
                w = np.zeros((len(cells), 1))
            missing += lib.add_cells(address, len(cells), ptr("int32_t", cells), self.blocks.shape[1],
                                     ptr("int32_t", self.blocks), self.geometry.shape[1],
                                     ptr("int32_t", self.geometry), ptr("double", self.x), ptr("double", w),
                                     w.shape[1] if w.size else 0, ptr("double", c), ptr("int32_t", indptr),
                                     ptr("int32_t", indices), ptr("uint8_t", held), self.bs, ptr("double", values),
                                     ptr("double", Ae), ptr("double", X), ptr("int64_t", place))
        missing += lib.set_constrained_diagonal(len(indptr) - 1, ptr("int32_t", indptr), ptr("int32_t", indices),
                                                ptr("uint8_t", held), ptr("double", values))
        if missing:
            raise RuntimeError(f"the matrix's pattern lacks {missing} entries of the form")
