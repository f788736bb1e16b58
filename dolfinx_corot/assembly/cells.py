"""A continuum's tangent assembled straight into the values of PETSc's AIJ matrix.

DOLFINx 0.5.2 inserts each element matrix through ``MatSetValuesLocal``, which searches its
row for every column: for trilinear hexahedra with three dofs a node (24 × 24 element
matrices) that costs as much as the FFCx kernel itself. Here a small C loop (compiled by cffi
on first use, as FFCx compiles forms, and cached on disk) calls the form's kernel (FFCx's or
:mod:`dolfinx_corot.continuum.compiled`'s) cell by cell and adds each 3 × 3 nodal block where it
lies in the row: the column's place is found once per pair of nodes, by bisection in the row's
sorted columns, and serves the block's other rows wherever their columns are laid out alike
(checked; otherwise they are searched too). The places are kept for the next tangents (a map of
4 bytes per pair of a cell's nodes, about 8 % of the AIJ matrix for trilinear hexahedra), checked at
each use against the row's columns, and searched again where the pattern has changed (contact
couplings merged into it).
Rows and columns of constrained dofs are left out and their diagonal set to 1, as DOLFINx's
``assemble_matrix`` with Dirichlet conditions and ``insert_diagonal`` do; the entries are
added in DOLFINx's order, so the matrix is the same to the last bit.

On several ranks the loop writes the owned nodes' rows into the two blocks of PETSc's MPIAIJ
matrix (the owned columns, and the other columns through the block's sorted global column
map) and hands the element matrices of cells with ghost nodes back whole: their ghost rows go
to the owners through ``MatSetValuesBlockedLocal`` and the matrix's assembly, as DOLFINx sends
them, so that the matrix is again DOLFINx's to the last bit.

The same library copies a symmetric AIJ matrix's upper triangle into an SBAIJ matrix of its
nodal blocks (:func:`upper_blocks`; the operator of the iterative solver,
:class:`~dolfinx_corot.assembly.petsc.SymmetricBlockOperator`). The tangent can go into that
SBAIJ matrix alone (:meth:`CellAssembler.assemble_upper`: the node pairs of a cell on or above the
diagonal, 36 of a hexahedron's 64 blocks; on one rank the same sums in the same order as the
copy's; on several the owned nodes' rows, the pairs ordered by global node index, into the
diagonal block of PETSc's MPISBAIJ matrix and the blocks of higher ranks' columns, the rows of
ghost nodes handed back whole), the AIJ matrix being made from it (:func:`aij_from_upper`, the
mirror image) only where it is read: the AMG's set-up, a fallback LU, the stability checks. The library also holds the loops of the
co-rotated AMG hierarchy (:mod:`dolfinx_corot.assembly.amg`: the patches' moments
``patch_moments``, their rotations ``polar3``, the check ``unlike_rows`` and the rotation
``rotate_rows`` of a prolongator's nodal rows) and those of the dense factorization of small
systems (:mod:`dolfinx_corot.assembly.dense`).

Used by :class:`~dolfinx_corot.assembly.system.System` for FFCx forms whose integrals are all
cell integrals over meshes of at least :data:`MIN_CELLS` cells (on every rank).
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import tempfile
from pathlib import Path

import numpy as np

MIN_CELLS = 4000  # meshes with fewer cells (on some rank) keep DOLFINx's insertion

_SOURCE = r"""
#include <math.h>
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

/* The element matrix of the k-th cell of ``cells`` into Ae (n x n, row-major; X: its geometry's
   coordinates, work space); returns whether any of its dofs is constrained. */
static int element_matrix(tabulate_t kernel, int64_t k, const int32_t* cells, int64_t nb, const int32_t* blocks,
                          int64_t ng, const int32_t* geometry, const double* x, const double* w, int64_t wstride,
                          const double* c, const uint8_t* constrained, int64_t bs, double* Ae, double* X)
{
  const int64_t cell = cells[k], n = nb * bs;
  const int32_t* nodes = blocks + cell * nb;
  for (int64_t i = 0; i < ng; ++i)
    for (int d = 0; d < 3; ++d)
      X[3 * i + d] = x[3 * (int64_t)geometry[cell * ng + i] + d];
  memset(Ae, 0, n * n * sizeof(double));
  kernel(Ae, w + k * wstride, c, X, NULL, NULL);
  int held = 0;
  for (int64_t i = 0; i < n; ++i)
    held |= constrained[nodes[i / bs] * bs + i % bs];
  return held;
}

/* g = the element matrix Ae (n x n) with its constrained rows and columns zero: a cell's matrix
   whose rows of ghost nodes go to their owners. */
static void copy_for_owners(double* g, const double* Ae, const int32_t* nodes, int64_t n, const uint8_t* constrained,
                            int64_t bs)
{
  for (int64_t i = 0; i < n; ++i)
  {
    const int row_held = constrained[nodes[i / bs] * bs + i % bs];
    for (int64_t j = 0; j < n; ++j)
      g[i * n + j] = (row_held || constrained[nodes[j / bs] * bs + j % bs]) ? 0.0 : Ae[i * n + j];
  }
}

/* The element matrices of ``cells`` added into the rows of owned nodes (node < owned): columns of
   owned nodes into the CSR block (indptr, indices, values) at column node * bs, columns of ghost
   nodes into the CSR block (indptr_o, indices_o, values_o) at column ghost_column[node - owned]
   (several ranks: PETSc's off-diagonal block). The element matrix of the k-th cell goes whole
   to ghost + ghost_slot[k] * n * n as well where ghost_slot[k] >= 0 (its rows of ghost nodes are
   sent to their owners by the caller). Rows and columns of constrained dofs are left out (zero in
   the copy). map (or NULL): for each cell and pair of its nodes (i, j), the place of node j's first
   column in node i's first row (from the row's start; -1: not known), kept from call to call and
   checked at each use (a new pattern is searched again). Returns the number of entries the pattern
   lacks. */
int64_t add_cells(uintptr_t address, int64_t ncells, const int32_t* cells, int64_t nb, const int32_t* blocks,
                  int64_t ng, const int32_t* geometry, const double* x, const double* w, int64_t wstride,
                  const double* c, int64_t owned, const int32_t* indptr, const int32_t* indices, double* values,
                  const int32_t* ghost_column, const int32_t* indptr_o, const int32_t* indices_o,
                  double* values_o, const uint8_t* constrained, int64_t bs, double* ghost,
                  const int64_t* ghost_slot, double* Ae, double* X, int64_t* place, int32_t* map)
{
  tabulate_t kernel = (tabulate_t)address;
  const int64_t n = nb * bs;
  int64_t missing = 0;
  for (int64_t k = 0; k < ncells; ++k)
  {
    const int32_t* nodes = blocks + (int64_t)cells[k] * nb;
    const int held = element_matrix(kernel, k, cells, nb, blocks, ng, geometry, x, w, wstride, c, constrained,
                                    bs, Ae, X);
    if (ghost_slot != NULL && ghost_slot[k] >= 0)
      copy_for_owners(ghost + ghost_slot[k] * n * n, Ae, nodes, n, constrained, bs);
    for (int64_t i = 0; i < nb; ++i)
    {
      if (nodes[i] >= owned)
        continue; /* a ghost node's rows: its owner's */
      const int64_t row0 = (int64_t)nodes[i] * bs;
      for (int64_t j = 0; j < nb; ++j)
      {
        const int off = nodes[j] >= owned;
        const int32_t* ip = off ? indptr_o : indptr;
        const int32_t* ix = off ? indices_o : indices;
        const int64_t col0 = off ? (int64_t)ghost_column[nodes[j] - owned] : (int64_t)nodes[j] * bs;
        const int64_t start = ip[row0], stop = ip[row0 + 1];
        int32_t* known = map == NULL ? NULL : map + (k * nb + i) * nb + j;
        if (known != NULL && *known >= 0 && start + *known + bs <= stop && ix[start + *known] == col0
            && ix[start + *known + bs - 1] == col0 + bs - 1)
        {
          place[j] = *known; /* where the last call found it, still there */
          continue;
        }
        const int64_t p = col0 < 0 ? -1 : find(ix, start, stop, col0);
        const int whole = p >= 0 && p + bs <= stop && ix[p + bs - 1] == col0 + bs - 1;
        place[j] = whole ? p - start : -1;
        if (known != NULL)
          *known = (int32_t)place[j];
        missing += !whole;
      }
      for (int64_t a = 0; a < bs; ++a)
      {
        const int64_t row = row0 + a;
        if (constrained[row])
          continue;
        const double* e = Ae + (i * bs + a) * n;
        for (int64_t j = 0; j < nb; ++j)
        {
          if (place[j] < 0)
            continue;
          const int off = nodes[j] >= owned;
          const int32_t* ix = off ? indices_o : indices;
          const int64_t first = (off ? indptr_o : indptr)[row], last = (off ? indptr_o : indptr)[row + 1];
          int64_t at = place[j];
          const int64_t col0 = off ? (int64_t)ghost_column[nodes[j] - owned] : (int64_t)nodes[j] * bs;
          if (a > 0 && (first + at + bs > last || ix[first + at] != col0
                        || ix[first + at + bs - 1] != col0 + bs - 1))
          {
            /* this row's columns are not laid out as the node's first row's */
            const int64_t p = find(ix, first, last, col0);
            if (p < 0 || p + bs > last || ix[p + bs - 1] != col0 + bs - 1)
            {
              ++missing;
              continue;
            }
            at = p - first;
          }
          double* vj = (off ? values_o : values) + first + at;
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

/* The element matrices of ``cells`` added into the values ``out`` of an SBAIJ matrix of the upper
   nodal block pattern (bi, bj; column-major bs x bs blocks, the diagonal block whole: its upper
   triangle and the mirror image of that), as :c:func:`upper_blocks` would copy them from the AIJ
   matrix that :c:func:`add_cells` assembles, to the last bit (the same sums in the same order):
   only the node pairs (i, j) of a cell with nodes[i] <= nodes[j]. Rows and columns of constrained
   dofs are left out. map: for each cell and pair of its nodes, the block's place in the node's
   block row (from the row's start; -1: not known), kept from call to call and checked at each use.
   Several ranks (global != NULL): the rows of the owned nodes (node < owned) alone, the pairs
   ordered by their global block indices ``global``; (bi, bj) is then the diagonal block of the
   owned columns (local indices), and the blocks of ghost nodes' columns above the diagonal go to
   the values out_o (row-major blocks) of the block CSR (oi, oj; global block columns); the element
   matrix of the k-th cell goes whole to ghost + ghost_slot[k] * n * n as well where
   ghost_slot[k] >= 0, for the rows of its ghost nodes' owners. Returns the number of blocks the
   pattern lacks. */
int64_t add_cells_upper(uintptr_t address, int64_t ncells, const int32_t* cells, int64_t nb,
                        const int32_t* blocks, int64_t ng, const int32_t* geometry, const double* x,
                        const double* w, int64_t wstride, const double* c, const uint8_t* constrained,
                        int64_t bs, const int32_t* bi, const int32_t* bj, double* out, double* Ae, double* X,
                        int32_t* map, int64_t owned, const int64_t* global, const int32_t* oi,
                        const int32_t* oj, double* out_o, double* ghost, const int64_t* ghost_slot)
{
  tabulate_t kernel = (tabulate_t)address;
  const int64_t n = nb * bs, bb = bs * bs;
  int64_t missing = 0;
  for (int64_t k = 0; k < ncells; ++k)
  {
    const int32_t* nodes = blocks + (int64_t)cells[k] * nb;
    const int held = element_matrix(kernel, k, cells, nb, blocks, ng, geometry, x, w, wstride, c, constrained,
                                    bs, Ae, X);
    if (ghost_slot != NULL && ghost_slot[k] >= 0)
      copy_for_owners(ghost + ghost_slot[k] * n * n, Ae, nodes, n, constrained, bs);
    for (int64_t i = 0; i < nb; ++i)
    {
      const int64_t I = nodes[i];
      if (global != NULL && I >= owned)
        continue; /* a ghost node's rows: its owner's */
      const int64_t gI = global == NULL ? I : global[I];
      for (int64_t j = 0; j < nb; ++j)
      {
        const int64_t J = nodes[j];
        const int off = global != NULL && J >= owned;
        const int64_t gJ = global == NULL ? J : global[J];
        if (gJ < gI)
          continue;
        const int32_t* rows = off ? oi : bi;
        const int32_t* columns = off ? oj : bj;
        const int64_t column = off ? gJ : J, k0 = rows[I], k1 = rows[I + 1];
        int32_t* known = map + (k * nb + i) * nb + j;
        int64_t at = *known >= 0 && k0 + *known < k1 && columns[k0 + *known] == column ? k0 + *known : -1;
        if (at < 0)
        {
          int64_t lo = k0, hi = k1;
          while (lo < hi)
          {
            const int64_t mid = (lo + hi) / 2;
            if (columns[mid] < column)
              lo = mid + 1;
            else
              hi = mid;
          }
          if (lo == k1 || columns[lo] != column)
          {
            ++missing;
            continue;
          }
          at = lo;
          *known = (int32_t)(lo - k0);
        }
        double* block = (off ? out_o : out) + at * bb;
        for (int64_t a = 0; a < bs; ++a)
        {
          if (held && constrained[I * bs + a])
            continue;
          const double* e = Ae + (i * bs + a) * n + j * bs;
          for (int64_t b = 0; b < bs; ++b)
          {
            if (held && constrained[J * bs + b])
              continue;
            if (off)
              block[a * bs + b] += e[b];
            else if (J != I)
              block[b * bs + a] += e[b];
            else if (b >= a)
            {
              block[b * bs + a] += e[b];
              if (b > a)
                block[a * bs + b] += e[b];
            }
          }
        }
      }
    }
  }
  return missing;
}

/* The diagonal of the constrained rows set to 1 in the SBAIJ values out (the diagonal block first
   in each block row); returns the number of block rows that lack it. */
int64_t set_constrained_upper(int64_t nblocks, int64_t bs, const int32_t* bi, const int32_t* bj,
                              const uint8_t* constrained, double* out)
{
  int64_t missing = 0;
  for (int64_t I = 0; I < nblocks; ++I)
    for (int64_t a = 0; a < bs; ++a)
      if (constrained[I * bs + a])
      {
        if (bi[I] == bi[I + 1] || bj[bi[I]] != I)
        {
          ++missing;
          continue;
        }
        out[bi[I] * bs * bs + a * bs + a] = 1.0;
      }
  return missing;
}

/* values at row's columns col0 ... col0 + len - 1 = v[0], v[stride], ..., found from cursor[row] on (the
   row's columns sorted, visited in increasing order; the cursor moves on); returns the columns
   the row lacks. */
static int64_t put_run(int64_t row, int64_t col0, int64_t len, const double* v, int64_t stride,
                       const int32_t* indptr, const int32_t* indices, double* values, int64_t* cursor)
{
  int64_t missing = 0, p = cursor[row];
  const int64_t stop = indptr[row + 1];
  for (int64_t b = 0; b < len; ++b)
  {
    const int64_t col = col0 + b;
    while (p < stop && indices[p] < col)
      ++p;
    if (p == stop || indices[p] != col)
    {
      ++missing;
      continue;
    }
    values[p] = v[b * stride];
  }
  cursor[row] = p;
  return missing;
}

/* The symmetric AIJ matrix (indptr, indices, values; every row's columns sorted) of the SBAIJ
   values S (upper block pattern bi, bj; column-major blocks): each block at its place in its rows
   and, off the diagonal, transposed in the rows of its column. Entries of the AIJ pattern outside
   the blocks are zero. cursor: nblocks * bs work entries. Returns the number of entries the AIJ
   pattern lacks. */
int64_t aij_from_upper(int64_t nblocks, int64_t bs, const int32_t* bi, const int32_t* bj, const double* S,
                       const int32_t* indptr, const int32_t* indices, double* values, int64_t* cursor)
{
  int64_t missing = 0;
  const int64_t bb = bs * bs, nrows = nblocks * bs;
  memset(values, 0, (size_t)indptr[nrows] * sizeof(double));
  for (int64_t r = 0; r < nrows; ++r)
    cursor[r] = indptr[r];
  for (int64_t I = 0; I < nblocks; ++I)
  {
    for (int64_t k = bi[I]; k < bi[I + 1]; ++k)
    {
      const int64_t J = bj[k];
      const double* block = S + k * bb;
      for (int64_t a = 0; a < bs; ++a)  /* row I*bs + a: the block's row a at columns J*bs ... */
        missing += put_run(I * bs + a, J * bs, bs, block + a, bs, indptr, indices, values, cursor);
      if (J != I)
        for (int64_t b = 0; b < bs; ++b)  /* row J*bs + b: the block's column b at columns I*bs ... */
          missing += put_run(J * bs + b, I * bs, bs, block + b * bs, 1, indptr, indices, values, cursor);
    }
  }
  return missing;
}

/* out[row] = the diagonal entry of each row (0 where the pattern lacks it), found by bisection in
   the row's sorted columns (PETSc's MatGetDiagonal scans each row from its start) */
void diagonal(int64_t nrows, const int32_t* indptr, const int32_t* indices, const double* values, double* out)
{
  for (int64_t row = 0; row < nrows; ++row)
  {
    const int64_t p = find(indices, indptr[row], indptr[row + 1], row);
    out[row] = p < 0 ? 0.0 : values[p];
  }
}

/* The scalar CSR (indptr, indices: global columns, sorted in each row) of the n block rows of a
   nodal block pattern with blocks of bs: block row r couples the local block columns
   links[offsets[r]] ... links[offsets[r + 1] - 1], whose global indices are to_global[link]; every
   row of a block row has the same columns. work: the longest block row's length. */
void expand_blocks(int64_t n, int64_t bs, const int64_t* offsets, const int32_t* links, const int64_t* to_global,
                   int32_t* indptr, int32_t* indices, int64_t* work)
{
  int64_t p = 0;
  indptr[0] = 0;
  for (int64_t r = 0; r < n; ++r)
  {
    const int64_t count = offsets[r + 1] - offsets[r];
    for (int64_t k = 0; k < count; ++k)
    {
      const int64_t g = to_global[links[offsets[r] + k]];
      int64_t i = k;
      while (i > 0 && work[i - 1] > g)
      {
        work[i] = work[i - 1];
        --i;
      }
      work[i] = g;
    }
    for (int64_t a = 0; a < bs; ++a)
    {
      for (int64_t k = 0; k < count; ++k)
        for (int64_t b = 0; b < bs; ++b)
          indices[p++] = (int32_t)(work[k] * bs + b);
      indptr[r * bs + a + 1] = (int32_t)p;
    }
  }
}

/* values' diagonal entries = diag (rows that lack one: counted) */
int64_t set_diagonal(int64_t nrows, const int32_t* indptr, const int32_t* indices, const double* diag,
                     double* values)
{
  int64_t missing = 0;
  for (int64_t row = 0; row < nrows; ++row)
  {
    const int64_t p = find(indices, indptr[row], indptr[row + 1], row);
    if (p < 0)
      ++missing;
    else
      values[p] = diag[row];
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

/* The upper triangle of a symmetric AIJ matrix with nodal blocks of bs rows into the values of
   an SBAIJ matrix of the upper block pattern (bi, bj; column-major bs x bs blocks, the diagonal
   block whole: its upper triangle and the mirror image of that). Entries
   of the SBAIJ pattern the AIJ rows lack are set to zero. Returns the number of AIJ entries
   right of the diagonal block that the SBAIJ pattern lacks. */
int64_t upper_blocks(int64_t nblocks, int64_t bs, const int32_t* indptr, const int32_t* indices,
                     const double* values, const int32_t* bi, const int32_t* bj, double* out)
{
  int64_t missing = 0;
  const int64_t bb = bs * bs;
  for (int64_t I = 0; I < nblocks; ++I)
  {
    const int64_t k0 = bi[I], k1 = bi[I + 1];
    memset(out + k0 * bb, 0, (k1 - k0) * bb * sizeof(double));
    for (int64_t a = 0; a < bs; ++a)
    {
      const int64_t row = I * bs + a;
      int64_t p = indptr[row];
      const int64_t stop = indptr[row + 1];
      const int64_t first = I * bs;
      while (p < stop && indices[p] < first)
        ++p;
      int64_t k = k0;
      for (; p < stop; ++p)
      {
        const int64_t col = indices[p], J = col / bs;
        while (k < k1 && bj[k] < J)
          ++k;
        if (k == k1 || bj[k] != J)
        {
          ++missing;
          continue;
        }
        const int64_t b = col - J * bs;
        if (J == I)
        {
          /* the diagonal block: its upper triangle, mirrored (as PETSc's insertion stores it) */
          if (b >= a)
            out[k * bb + b * bs + a] = out[k * bb + a * bs + b] = values[p];
        }
        else
          out[k * bb + b * bs + a] = values[p];
      }
    }
  }
  return missing;
}
/* H_i += sum over the cells c around node i (i < n) of sum_j (b_j - mean_c b)(a_j - mean_c a)^T, for
   positions a (before) and b (after), (nodes, d) row-major; H: (n, d, d), zeroed by the caller. */
void patch_moments(int64_t ncells, int64_t k, const int32_t* cells, int64_t d, const double* a,
                   const double* b, int64_t n, double* H)
{
  double M[9], ma[3], mb[3];
  for (int64_t c = 0; c < ncells; ++c)
  {
    const int32_t* nodes = cells + c * k;
    for (int64_t p = 0; p < d; ++p)
      ma[p] = mb[p] = 0.0;
    for (int64_t j = 0; j < k; ++j)
      for (int64_t p = 0; p < d; ++p)
      {
        ma[p] += a[(int64_t)nodes[j] * d + p];
        mb[p] += b[(int64_t)nodes[j] * d + p];
      }
    for (int64_t p = 0; p < d; ++p)
    {
      ma[p] /= (double)k;
      mb[p] /= (double)k;
    }
    for (int64_t p = 0; p < d * d; ++p)
      M[p] = 0.0;
    for (int64_t j = 0; j < k; ++j)
    {
      const double* aj = a + (int64_t)nodes[j] * d;
      const double* bj = b + (int64_t)nodes[j] * d;
      for (int64_t p = 0; p < d; ++p)
        for (int64_t q = 0; q < d; ++q)
          M[p * d + q] += (bj[p] - mb[p]) * (aj[q] - ma[q]);
    }
    for (int64_t j = 0; j < k; ++j)
      if (nodes[j] < n)
        for (int64_t p = 0; p < d * d; ++p)
          H[(int64_t)nodes[j] * d * d + p] += M[p];
  }
}

/* The orthogonal polar factor R of each of n 3 x 3 matrices H (row-major), H = R S with S
   symmetric positive definite, by Newton's iteration X <- (z X + X^{-T} / z) / 2 with Higham's
   scaling z = (|X^{-1}|_F / |X|_F)^{1/2} (Higham 1986, "Computing the polar decomposition, with
   applications"), unscaled once close. Where det H > 0 that factor is the proper rotation
   nearest H, the U V^T of H's SVD. ok[i] = 1 where it converged with det H_i > 0; 0 elsewhere
   (singular, reflecting or not converged: the caller takes the SVD there). */
void polar3(int64_t n, const double* H, double* R, uint8_t* ok)
{
  for (int64_t i = 0; i < n; ++i)
  {
    const double* h = H + 9 * i;
    double* x = R + 9 * i;
    double det = h[0] * (h[4] * h[8] - h[5] * h[7]) - h[1] * (h[3] * h[8] - h[5] * h[6])
                 + h[2] * (h[3] * h[7] - h[4] * h[6]);
    double norm = 0.0;
    for (int p = 0; p < 9; ++p)
    {
      x[p] = h[p];
      norm += h[p] * h[p];
    }
    ok[i] = 0;
    if (!(det > 1e-13 * norm * sqrt(norm)))  /* singular to round-off, reflecting, or NaN */
      continue;
    int scaled = 1, last = 0;
    for (int it = 0; it < 40; ++it)
    {
      /* c: the cofactors of X, so that X^{-T} = c / det X */
      double c[9];
      c[0] = x[4] * x[8] - x[5] * x[7];
      c[1] = x[5] * x[6] - x[3] * x[8];
      c[2] = x[3] * x[7] - x[4] * x[6];
      c[3] = x[2] * x[7] - x[1] * x[8];
      c[4] = x[0] * x[8] - x[2] * x[6];
      c[5] = x[1] * x[6] - x[0] * x[7];
      c[6] = x[1] * x[5] - x[2] * x[4];
      c[7] = x[2] * x[3] - x[0] * x[5];
      c[8] = x[0] * x[4] - x[1] * x[3];
      const double d = x[0] * c[0] + x[1] * c[1] + x[2] * c[2];
      if (!(d > 0.0))
        break;
      double nx = 0.0, nc = 0.0;
      for (int p = 0; p < 9; ++p)
      {
        c[p] /= d;
        nx += x[p] * x[p];
        nc += c[p] * c[p];
      }
      const double z = scaled ? sqrt(sqrt(nc / nx)) : 1.0;
      double change = 0.0;
      for (int p = 0; p < 9; ++p)
      {
        const double y = 0.5 * (z * x[p] + c[p] / z);
        change += (y - x[p]) * (y - x[p]);
        x[p] = y;
      }
      if (last)  /* one step past a change of 1e-10: converged to round-off (quadratically) */
      {
        ok[i] = 1;
        break;
      }
      if (change < 1e-4)
        scaled = 0;
      if (!scaled && change < 1e-20)
        last = 1;
    }
  }
}

/* The rows of each node (bs of them, node i: rows i*bs ... i*bs + bs - 1) that do not hold the
   same columns in the same order: their number. */
int64_t unlike_rows(int64_t nodes, int64_t bs, const int32_t* indptr, const int32_t* indices)
{
  int64_t unlike = 0;
  for (int64_t i = 0; i < nodes; ++i)
  {
    const int64_t r0 = i * bs, len = indptr[r0 + 1] - indptr[r0];
    for (int64_t a = 1; a < bs; ++a)
    {
      const int64_t ra = r0 + a;
      int same = indptr[ra + 1] - indptr[ra] == len;
      for (int64_t k = 0; same && k < len; ++k)
        same = indices[indptr[ra] + k] == indices[indptr[r0] + k];
      unlike += !same;
    }
  }
  return unlike;
}

/* values = diag(R_i) base on CSR rows grouped by node (rows alike: unlike_rows == 0):
   row i*bs + a = sum_b R_i[a][b] row i*bs + b, R: (nodes, bs, bs) row-major. */
void rotate_rows(int64_t nodes, int64_t bs, const int32_t* indptr, const double* base, const double* R,
                 double* values)
{
  for (int64_t i = 0; i < nodes; ++i)
  {
    const int64_t r0 = i * bs, len = indptr[r0 + 1] - indptr[r0];
    const double* Ri = R + i * bs * bs;
    for (int64_t k = 0; k < len; ++k)
      for (int64_t a = 0; a < bs; ++a)
      {
        double sum = 0.0;
        for (int64_t b = 0; b < bs; ++b)
          sum += Ri[a * bs + b] * base[indptr[r0 + b] + k];
        values[indptr[r0 + a] + k] = sum;
      }
  }
}

/* -- the dense factorization's helpers (dolfinx_corot.assembly.dense) -- */

/* s_i = 1/sqrt|a_ii| of A's CSR rows (1 where a_ii = 0) */
static void unit_diagonal_scale(int64_t n, const int32_t* indptr, const int32_t* indices, const double* values,
                                double* s)
{
  for (int64_t i = 0; i < n; ++i)
  {
    s[i] = 1.0;
    for (int64_t k = indptr[i]; k < indptr[i + 1]; ++k)
      if (indices[k] == i && values[k] != 0.0)
        s[i] = 1.0 / sqrt(fabs(values[k]));
  }
}

/* K (n, n, column-major) = S A S, s filled */
void scaled_dense(int64_t n, const int32_t* indptr, const int32_t* indices, const double* values, double* K,
                  double* s)
{
  memset(K, 0, (size_t)(n * n) * sizeof(double));
  unit_diagonal_scale(n, indptr, indices, values, s);
  for (int64_t i = 0; i < n; ++i)
    for (int64_t k = indptr[i]; k < indptr[i + 1]; ++k)
    {
      int64_t j = indices[k];
      K[i + j * n] = values[k] * s[i] * s[j];
    }
}

/* S A S in LAPACK's band storage (dgbtrf): ab (ldab, n, column-major), ab[kl + ku + i - j, j] */
void scaled_band(int64_t n, const int32_t* indptr, const int32_t* indices, const double* values, int64_t kl,
                 int64_t ku, int64_t ldab, double* ab, double* s)
{
  memset(ab, 0, (size_t)(ldab * n) * sizeof(double));
  unit_diagonal_scale(n, indptr, indices, values, s);
  for (int64_t i = 0; i < n; ++i)
    for (int64_t k = indptr[i]; k < indptr[i + 1]; ++k)
    {
      int64_t j = indices[k];
      ab[kl + ku + i - j + j * ldab] = values[k] * s[i] * s[j];
    }
}

/* out = (kl, ku): the largest i - j and j - i over the stored entries of a CSR pattern */
void bandwidths(int64_t n, const int32_t* indptr, const int32_t* indices, int64_t* out)
{
  int64_t kl = 0, ku = 0;
  for (int64_t i = 0; i < n; ++i)
    for (int64_t k = indptr[i]; k < indptr[i + 1]; ++k)
    {
      int64_t j = indices[k];
      if (i - j > kl)
        kl = i - j;
      if (j - i > ku)
        ku = j - i;
    }
  out[0] = kl;
  out[1] = ku;
}

/* out = (row swaps, pivots with |u_ii| <= null_pivot, negative pivots) of an LU's diagonal and
   (0-based) pivots */
void lu_summary(int64_t n, const double* diagonal, const int32_t* piv, double null_pivot, int64_t* out)
{
  int64_t swaps = 0, null = 0, negative = 0;
  for (int64_t i = 0; i < n; ++i)
  {
    if (piv[i] != i)
      swaps += 1;
    double u = diagonal[i];
    if (fabs(u) <= null_pivot)
      null += 1;
    if (u < 0.0)
      negative += 1;
  }
  out[0] = swaps;
  out[1] = null;
  out[2] = negative;
}

/* Products of PETSc matrices by compiled loops, installed as the matrices' operations
   (MatSetOperation) and reading PETSc's own arrays, registered with the matrix:
   - y = S x of a SeqSBAIJ matrix with 2 x 2, 3 x 3 or 6 x 6 blocks (PETSc's layout: the upper
     block triangle, each block column-major, the diagonal block first in its row and read from
     its upper half), as MATOP_MULT: the operations of PETSc 3.18's MatMult_SeqSBAIJ_2/3/6 in
     their order, so the same numbers to the last bit; the block row's own sums are kept in
     registers instead of memory, which PETSc's compiler cannot do for fear of aliasing, and the
     blocks are fetched ahead (the tangent of the 10⁶-dof block, 360 MB, streams from memory):
     3 x 3 blocks in 0.8 (116 k dofs) and 0.65 (10⁶) of PETSc's time, 6 x 6 blocks (AMG's coarse
     levels in 3D) in a tenth to a fifth;
   - y = P^T x of a SeqAIJ matrix whose rows come in groups of bs (a node's) with the same
     columns (AMG's prolongators), as MATOP_MULT_TRANSPOSE: each column's index and each entry
     of y read and written once per node instead of once per row, the rows' contributions added
     in PETSc's order (MatMultTranspose_SeqAIJ), so the same numbers to the last bit;
   - y = z + P x of the same matrices, as MATOP_MULT_ADD (the V-cycle's prolongation), in the
     order of PETSc's I-node product, which serves them;
   - the diagonal of a matrix from a kept copy, as MATOP_GET_DIAGONAL, while the matrix's object
     state is the one kept (the tangent's, for the Jacobi smoother, which reads it once a solve);
   - y = A x of a matrix by the product of a copy of it in another format (AMG's coarse
     operators, AIJ with 6 x 6 blocks, by their SBAIJ copies: a fifth of the time), as
     MATOP_MULT, while A's object state is the one copied (else by A's own product).
   The pattern is fixed, so the value arrays stay where they are. A matrix that carries one of
   the compiled operations but is not registered (its registration forgotten) goes to PETSc's
   own; a copied product's own operation is put back before its registration ends. */
typedef int (*dc_vec_read_t)(void*, const double**);
typedef int (*dc_vec_write_t)(void*, double**);
typedef int (*dc_mult_t)(void*, void*, void*);
static dc_vec_read_t dc_get_read = 0, dc_restore_read = 0;
static dc_vec_write_t dc_get_write = 0, dc_restore_write = 0;
static int (*dc_block_size)(void*, int32_t*) = 0;
static int (*dc_object_state)(void*, int64_t*) = 0;
static dc_mult_t dc_petsc_sbaij_mult[7] = {0, 0, 0, 0, 0, 0, 0};
static dc_mult_t dc_petsc_aij_mult_transpose = 0;
static int (*dc_petsc_aij_mult_add)(void*, void*, void*, void*) = 0;
static dc_vec_write_t dc_get_array = 0, dc_restore_array = 0;

#define DC_PRODUCT_SLOTS 256
typedef struct
{
  void* mat;
  int64_t token, kind, n, ncols, bs; /* kind 1: SBAIJ product (n block rows); 2: AIJ transpose (n rows,
                                        ncols); 4: AIJ product added (n rows, ncols); 5: kept diagonal (n) */
  const int32_t *ia, *ja;
  const double* v;
  void* copy; /* kind 3: the copy, its product, the matrix's own and the state copied */
  dc_mult_t copy_mult, own_mult;
  int64_t state;
} dc_product_t;
static dc_product_t dc_products[DC_PRODUCT_SLOTS];

int sbaij_mult(void* mat, void* x, void* y);
int nodal_mult_transpose(void* mat, void* x, void* y);
int nodal_mult_add(void* mat, void* x, void* z, void* y);
int copied_mult(void* mat, void* x, void* y);
int kept_diagonal(void* mat, void* d);

void product_api(void* get_read, void* restore_read, void* get_write, void* restore_write, void* block_size,
                 void* object_state, void* get_array, void* restore_array)
{
  dc_get_array = (dc_vec_write_t)get_array;
  dc_restore_array = (dc_vec_write_t)restore_array;
  dc_block_size = (int (*)(void*, int32_t*))block_size;
  dc_object_state = (int (*)(void*, int64_t*))object_state;
  dc_get_read = (dc_vec_read_t)get_read;
  dc_restore_read = (dc_vec_read_t)restore_read;
  dc_get_write = (dc_vec_write_t)get_write;
  dc_restore_write = (dc_vec_write_t)restore_write;
}

/* the slot of mat's registration, else a free one, else -1 */
static int64_t dc_slot(void* mat)
{
  for (int64_t s = 0; s < DC_PRODUCT_SLOTS; ++s)
    if (dc_products[s].mat == mat)
      return s;
  for (int64_t s = 0; s < DC_PRODUCT_SLOTS; ++s)
    if (dc_products[s].mat == 0)
      return s;
  return -1;
}

/* the block sizes of the compiled SBAIJ products */
static int dc_sbaij_size(int64_t bs)
{
  return bs == 2 || bs == 3 || bs == 6;
}

/* 0, or -1 where all slots are taken; petsc_op: PETSc's own operation (the fallback) */
int64_t product_register(void* mat, int64_t token, int64_t kind, int64_t n, int64_t ncols, int64_t bs,
                         const int32_t* ia, const int32_t* ja, const double* v, void* petsc_op)
{
  const int64_t slot = dc_slot(mat);
  if (slot < 0)
    return -1;
  dc_product_t e = {mat, token, kind, n, ncols, bs, ia, ja, v, 0, 0, 0, 0};
  dc_products[slot] = e;
  /* (never one of these loops, which would send a matrix to itself: the caller passes the
     operation PETSc had, and the comparison below only guards the direct addresses, as
     cffi's address of a function is its wrapper's) */
  const int ours = petsc_op == (void*)sbaij_mult || petsc_op == (void*)nodal_mult_transpose
                   || petsc_op == (void*)nodal_mult_add;
  if (kind == 1 && dc_sbaij_size(bs) && !ours)
    dc_petsc_sbaij_mult[bs] = (dc_mult_t)petsc_op;
  if (kind == 2 && !ours)
    dc_petsc_aij_mult_transpose = (dc_mult_t)petsc_op;
  if (kind == 4 && !ours)
    dc_petsc_aij_mult_add = (int (*)(void*, void*, void*, void*))petsc_op;
  return 0;
}

/* kind 3: the product of mat by copy_mult(copy, x, y) while mat's object state is `state`, else
   by own_mult (mat's own operation); 0, or -1 where all slots are taken */
int64_t product_register_copy(void* mat, int64_t token, void* copy, void* copy_mult, void* own_mult, int64_t state)
{
  if (own_mult == (void*)copied_mult || copy_mult == (void*)copied_mult)
    return -1;
  const int64_t slot = dc_slot(mat);
  if (slot < 0)
    return -1;
  dc_product_t e = {mat, token, 3, 0, 0, 0, 0, 0, 0, copy, (dc_mult_t)copy_mult, (dc_mult_t)own_mult, state};
  dc_products[slot] = e;
  return 0;
}

/* kind 5: the diagonal of mat from a kept copy (n values at v) while mat's object state is
   `state`, else by own (mat's own operation, never kept_diagonal: the caller checks, as cffi's
   address of a function is its wrapper's); 0, or -1 where all slots are taken */
int64_t product_register_diagonal(void* mat, int64_t token, int64_t n, const double* v, void* own, int64_t state)
{
  const int64_t slot = dc_slot(mat);
  if (slot < 0)
    return -1;
  dc_product_t e = {mat, token, 5, n, 0, 0, 0, 0, v, 0, 0, (dc_mult_t)own, state};
  dc_products[slot] = e;
  return 0;
}

/* forgets the registration of mat made with token (not a later one of a matrix at that address) */
void product_forget(void* mat, int64_t token)
{
  for (int64_t s = 0; s < DC_PRODUCT_SLOTS; ++s)
    if (dc_products[s].mat == mat && dc_products[s].token == token)
      dc_products[s].mat = 0;
}

static const dc_product_t* dc_product(void* mat, int64_t kind)
{
  for (int64_t s = 0; s < DC_PRODUCT_SLOTS; ++s)
    if (dc_products[s].mat == mat && dc_products[s].kind == kind)
      return &dc_products[s];
  return 0;
}

/* How far ahead the products fetch the values they stream (a tangent or a prolongator larger
   than the caches), measured on the 10⁶-dof block: 3 x 3 blocks ahead (the best of 8-128),
   6 x 6 blocks ahead (about the same bytes; 12-15 % quicker than none on its coarse levels),
   entries of a nodal row ahead (the best of 16-512) */
#define DC_AHEAD3 32
#define DC_AHEAD6 4
#define DC_AHEAD_ROW 256

static void dc_sbaij3(int64_t nb, const int32_t* restrict bi, const int32_t* restrict bj,
                      const double* restrict v, const double* restrict x, double* restrict z)
{
  memset(z, 0, sizeof(double) * 3 * nb);
  for (int64_t i = 0; i < nb; ++i)
  {
    const double x1 = x[3 * i], x2 = x[3 * i + 1], x3 = x[3 * i + 2];
    int64_t k = bi[i];
    const int64_t end = bi[i + 1];
    const double* b = v + 9 * k;
    double s1 = z[3 * i], s2 = z[3 * i + 1], s3 = z[3 * i + 2];
    if (k < end && bj[k] == i) /* the diagonal block's upper half */
    {
      s1 += b[0] * x1 + b[3] * x2 + b[6] * x3;
      s2 += b[3] * x1 + b[4] * x2 + b[7] * x3;
      s3 += b[6] * x1 + b[7] * x2 + b[8] * x3;
      b += 9;
      ++k;
    }
    for (; k < end; ++k, b += 9)
    {
      __builtin_prefetch(b + 9 * DC_AHEAD3, 0, 3);
      const int64_t c = 3 * (int64_t)bj[k];
      z[c] += b[0] * x1 + b[1] * x2 + b[2] * x3; /* the block's transpose into block row j */
      z[c + 1] += b[3] * x1 + b[4] * x2 + b[5] * x3;
      z[c + 2] += b[6] * x1 + b[7] * x2 + b[8] * x3;
      s1 += b[0] * x[c] + b[3] * x[c + 1] + b[6] * x[c + 2]; /* the block into block row i */
      s2 += b[1] * x[c] + b[4] * x[c + 1] + b[7] * x[c + 2];
      s3 += b[2] * x[c] + b[5] * x[c + 1] + b[8] * x[c + 2];
    }
    z[3 * i] = s1;
    z[3 * i + 1] = s2;
    z[3 * i + 2] = s3;
  }
}

/* PETSc 3.18's MatMult_SeqSBAIJ_6 (its operations in their order), block row i's sums in
   registers: AMG's coarse operators in 3D (the six rigid-body modes a node of the level) */
#define DC_ROW6(b, p1, p2, p3, p4, p5, p6) \
  (b[p1] * x1 + b[p2] * x2 + b[p3] * x3 + b[p4] * x4 + b[p5] * x5 + b[p6] * x6)
static void dc_sbaij6(int64_t nb, const int32_t* restrict bi, const int32_t* restrict bj,
                      const double* restrict v, const double* restrict x, double* restrict z)
{
  memset(z, 0, sizeof(double) * 6 * nb);
  for (int64_t i = 0; i < nb; ++i)
  {
    const double* xi = x + 6 * i;
    const double x1 = xi[0], x2 = xi[1], x3 = xi[2], x4 = xi[3], x5 = xi[4], x6 = xi[5];
    int64_t k = bi[i];
    const int64_t end = bi[i + 1];
    const double* b = v + 36 * k;
    double* zi = z + 6 * i;
    double s1 = zi[0], s2 = zi[1], s3 = zi[2], s4 = zi[3], s5 = zi[4], s6 = zi[5];
    if (k < end && bj[k] == i) /* the diagonal block's upper half (columns stored) */
    {
      s1 += DC_ROW6(b, 0, 6, 12, 18, 24, 30);
      s2 += DC_ROW6(b, 6, 7, 13, 19, 25, 31);
      s3 += DC_ROW6(b, 12, 13, 14, 20, 26, 32);
      s4 += DC_ROW6(b, 18, 19, 20, 21, 27, 33);
      s5 += DC_ROW6(b, 24, 25, 26, 27, 28, 34);
      s6 += DC_ROW6(b, 30, 31, 32, 33, 34, 35);
      b += 36;
      ++k;
    }
    for (; k < end; ++k, b += 36)
    {
      for (int q = 0; q < 36; q += 8)
        __builtin_prefetch(b + 36 * DC_AHEAD6 + q, 0, 3);
      const int64_t c = 6 * (int64_t)bj[k];
      const double* xc = x + c;
      double* zc = z + c;
      /* the block's transpose into block row j */
      zc[0] += DC_ROW6(b, 0, 1, 2, 3, 4, 5);
      zc[1] += DC_ROW6(b, 6, 7, 8, 9, 10, 11);
      zc[2] += DC_ROW6(b, 12, 13, 14, 15, 16, 17);
      zc[3] += DC_ROW6(b, 18, 19, 20, 21, 22, 23);
      zc[4] += DC_ROW6(b, 24, 25, 26, 27, 28, 29);
      zc[5] += DC_ROW6(b, 30, 31, 32, 33, 34, 35);
      /* the block into block row i */
      const double y1 = xc[0], y2 = xc[1], y3 = xc[2], y4 = xc[3], y5 = xc[4], y6 = xc[5];
      s1 += b[0] * y1 + b[6] * y2 + b[12] * y3 + b[18] * y4 + b[24] * y5 + b[30] * y6;
      s2 += b[1] * y1 + b[7] * y2 + b[13] * y3 + b[19] * y4 + b[25] * y5 + b[31] * y6;
      s3 += b[2] * y1 + b[8] * y2 + b[14] * y3 + b[20] * y4 + b[26] * y5 + b[32] * y6;
      s4 += b[3] * y1 + b[9] * y2 + b[15] * y3 + b[21] * y4 + b[27] * y5 + b[33] * y6;
      s5 += b[4] * y1 + b[10] * y2 + b[16] * y3 + b[22] * y4 + b[28] * y5 + b[34] * y6;
      s6 += b[5] * y1 + b[11] * y2 + b[17] * y3 + b[23] * y4 + b[29] * y5 + b[35] * y6;
    }
    zi[0] = s1;
    zi[1] = s2;
    zi[2] = s3;
    zi[3] = s4;
    zi[4] = s5;
    zi[5] = s6;
  }
}
#undef DC_ROW6

static void dc_sbaij2(int64_t nb, const int32_t* restrict bi, const int32_t* restrict bj,
                      const double* restrict v, const double* restrict x, double* restrict z)
{
  memset(z, 0, sizeof(double) * 2 * nb);
  for (int64_t i = 0; i < nb; ++i)
  {
    const double x1 = x[2 * i], x2 = x[2 * i + 1];
    int64_t k = bi[i];
    const int64_t end = bi[i + 1];
    const double* b = v + 4 * k;
    double s1 = z[2 * i], s2 = z[2 * i + 1];
    if (k < end && bj[k] == i)
    {
      s1 += b[0] * x1 + b[2] * x2;
      s2 += b[2] * x1 + b[3] * x2;
      b += 4;
      ++k;
    }
    for (; k < end; ++k, b += 4)
    {
      const int64_t c = 2 * (int64_t)bj[k];
      z[c] += b[0] * x1 + b[1] * x2;
      z[c + 1] += b[2] * x1 + b[3] * x2;
      s1 += b[0] * x[c] + b[2] * x[c + 1];
      s2 += b[1] * x[c] + b[3] * x[c + 1];
    }
    z[2 * i] = s1;
    z[2 * i + 1] = s2;
  }
}

/* z (ncols, zeroed first) = P^T x, P's rows in nodes of bs rows with the same columns */
static void dc_nodal_transpose(int64_t nrows, int64_t bs, int64_t ncols, const int32_t* restrict ia,
                               const int32_t* restrict ja, const double* restrict v, const double* restrict x,
                               double* restrict z)
{
  memset(z, 0, sizeof(double) * ncols);
  for (int64_t r = 0; r < nrows; r += bs)
  {
    const int64_t start = ia[r], len = ia[r + 1] - ia[r];
    const int32_t* col = ja + start;
    if (bs == 3)
    {
      const double *v0 = v + start, *v1 = v + ia[r + 1], *v2 = v + ia[r + 2];
      const double a0 = x[r], a1 = x[r + 1], a2 = x[r + 2];
      for (int64_t k = 0; k < len; ++k)
      {
        double t = z[col[k]];
        t += a0 * v0[k];
        t += a1 * v1[k];
        t += a2 * v2[k];
        z[col[k]] = t;
      }
    }
    else
    {
      for (int64_t k = 0; k < len; ++k)
      {
        double t = z[col[k]];
        for (int64_t b = 0; b < bs; ++b)
          t += x[r + b] * v[ia[r + b] + k];
        z[col[k]] = t;
      }
    }
  }
}

/* y = z + P x (z and y may be one array), P's rows in nodes of bs rows with the same columns:
   PETSc 3.18's I-node product (MatMultAdd_SeqAIJ_Inode), its operations in their order (each
   row's sum from z, the products two columns at a time), the columns read once a node and the
   values fetched ahead (the prolongator of the 10⁶-dof block streams 290 MB a product) */
static void dc_nodal_mult_add(int64_t nrows, int64_t bs, const int32_t* restrict ia, const int32_t* restrict ja,
                              const double* restrict v, const double* restrict x, const double* z, double* y)
{
  for (int64_t r = 0; r < nrows; r += bs)
  {
    const int64_t start = ia[r], len = ia[r + 1] - ia[r];
    const int32_t* col = ja + start;
    if (bs == 3)
    {
      const double *v0 = v + start, *v1 = v + ia[r + 1], *v2 = v + ia[r + 2];
      double s0 = z[r], s1 = z[r + 1], s2 = z[r + 2];
      int64_t k = 0;
      for (; k + 1 < len; k += 2)
      {
        __builtin_prefetch(v0 + k + DC_AHEAD_ROW, 0, 3);
        __builtin_prefetch(v1 + k + DC_AHEAD_ROW, 0, 3);
        __builtin_prefetch(v2 + k + DC_AHEAD_ROW, 0, 3);
        __builtin_prefetch(col + k + DC_AHEAD_ROW, 0, 3);
        const double t0 = x[col[k]], t1 = x[col[k + 1]];
        s0 += v0[k] * t0 + v0[k + 1] * t1;
        s1 += v1[k] * t0 + v1[k + 1] * t1;
        s2 += v2[k] * t0 + v2[k + 1] * t1;
      }
      if (k < len)
      {
        const double t0 = x[col[k]];
        s0 += v0[k] * t0;
        s1 += v1[k] * t0;
        s2 += v2[k] * t0;
      }
      y[r] = s0;
      y[r + 1] = s1;
      y[r + 2] = s2;
    }
    else
    {
      for (int64_t b = 0; b < bs; ++b)
      {
        const double* vb = v + ia[r + b];
        double s = z[r + b];
        int64_t k = 0;
        for (; k + 1 < len; k += 2)
          s += vb[k] * x[col[k]] + vb[k + 1] * x[col[k + 1]];
        if (k < len)
          s += vb[k] * x[col[k]];
        y[r + b] = s;
      }
    }
  }
}

static int dc_arrays(void* x, const double** px, void* y, double** py)
{
  int ierr = dc_get_read(x, px);
  if (ierr)
    return ierr;
  if ((ierr = dc_get_write(y, py)))
    dc_restore_read(x, px);
  return ierr;
}

static int dc_restore(void* x, const double** px, void* y, double** py)
{
  int ierr = dc_restore_write(y, py);
  int ierr2 = dc_restore_read(x, px);
  return ierr ? ierr : ierr2;
}

/* MATOP_MULT of a registered SeqSBAIJ matrix (PETSc's calling convention: Mat, Vec x, Vec y) */
int sbaij_mult(void* mat, void* x, void* y)
{
  const dc_product_t* e = dc_product(mat, 1);
  if (!e)
  {
    int32_t bs = 0;
    int ierr = dc_block_size(mat, &bs);
    if (ierr)
      return ierr;
    if (dc_sbaij_size(bs) && dc_petsc_sbaij_mult[bs])
      return dc_petsc_sbaij_mult[bs](mat, x, y);
    return 73; /* PETSC_ERR_ARG_WRONGSTATE */
  }
  const double* px;
  double* py;
  int ierr = dc_arrays(x, &px, y, &py);
  if (ierr)
    return ierr;
  if (e->bs == 6)
    dc_sbaij6(e->n, e->ia, e->ja, e->v, px, py);
  else if (e->bs == 3)
    dc_sbaij3(e->n, e->ia, e->ja, e->v, px, py);
  else
    dc_sbaij2(e->n, e->ia, e->ja, e->v, px, py);
  return dc_restore(x, &px, y, &py);
}

/* mat's registration of `kind` (3, 5) and whether mat's object state is the one registered
   (*current); 0 with *ierr set where there is none or the state cannot be read */
static const dc_product_t* dc_stated(void* mat, int64_t kind, int* ierr, int* current)
{
  const dc_product_t* e = dc_product(mat, kind);
  *ierr = 73; /* (never: the matrix's own operation is back before its registration ends) */
  if (!e)
    return 0;
  int64_t state = -1;
  if ((*ierr = dc_object_state(mat, &state)))
    return 0;
  *current = state == e->state;
  return e;
}

/* MATOP_MULT of a matrix registered with a copy (kind 3) */
int copied_mult(void* mat, void* x, void* y)
{
  int ierr, current;
  const dc_product_t* e = dc_stated(mat, 3, &ierr, &current);
  if (!e)
    return ierr;
  return current ? e->copy_mult(e->copy, x, y) : e->own_mult(mat, x, y);
}

/* MATOP_GET_DIAGONAL of a matrix registered with a kept diagonal (kind 5) */
int kept_diagonal(void* mat, void* d)
{
  int ierr, current;
  const dc_product_t* e = dc_stated(mat, 5, &ierr, &current);
  if (!e)
    return ierr;
  if (!current)
    return ((int (*)(void*, void*))e->own_mult)(mat, d);
  double* pd;
  if ((ierr = dc_get_write(d, &pd)))
    return ierr;
  memcpy(pd, e->v, sizeof(double) * e->n);
  return dc_restore_write(d, &pd);
}

/* MATOP_MULT_TRANSPOSE of a registered SeqAIJ matrix of nodal rows (y: its columns) */
int nodal_mult_transpose(void* mat, void* x, void* y)
{
  const dc_product_t* e = dc_product(mat, 2);
  if (!e)
    return dc_petsc_aij_mult_transpose ? dc_petsc_aij_mult_transpose(mat, x, y) : 73;
  const double* px;
  double* py;
  int ierr = dc_arrays(x, &px, y, &py);
  if (ierr)
    return ierr;
  dc_nodal_transpose(e->n, e->bs, e->ncols, e->ia, e->ja, e->v, px, py);
  return dc_restore(x, &px, y, &py);
}

/* MATOP_MULT_ADD of a registered SeqAIJ matrix of nodal rows (PETSc's calling convention:
   Mat, Vec x, Vec z, Vec y; y = z + A x) */
int nodal_mult_add(void* mat, void* x, void* z, void* y)
{
  const dc_product_t* e = dc_product(mat, 4);
  if (!e)
    return dc_petsc_aij_mult_add ? dc_petsc_aij_mult_add(mat, x, z, y) : 73;
  const double *px, *pz;
  double* py;
  int ierr = dc_get_read(x, &px);
  if (ierr)
    return ierr;
  if (z == y)
  {
    if ((ierr = dc_get_array(y, &py)))
    {
      dc_restore_read(x, &px);
      return ierr;
    }
    dc_nodal_mult_add(e->n, e->bs, e->ia, e->ja, e->v, px, py, py);
    ierr = dc_restore_array(y, &py);
  }
  else
  {
    if ((ierr = dc_arrays(z, &pz, y, &py)))
    {
      dc_restore_read(x, &px);
      return ierr;
    }
    dc_nodal_mult_add(e->n, e->bs, e->ia, e->ja, e->v, px, pz, py);
    ierr = dc_restore(z, &pz, y, &py);
  }
  int ierr2 = dc_restore_read(x, &px);
  return ierr ? ierr : ierr2;
}
"""

_CDEF = """
int64_t add_cells(uintptr_t address, int64_t ncells, const int32_t* cells, int64_t nb, const int32_t* blocks,
                  int64_t ng, const int32_t* geometry, const double* x, const double* w, int64_t wstride,
                  const double* c, int64_t owned, const int32_t* indptr, const int32_t* indices, double* values,
                  const int32_t* ghost_column, const int32_t* indptr_o, const int32_t* indices_o,
                  double* values_o, const uint8_t* constrained, int64_t bs, double* ghost,
                  const int64_t* ghost_slot, double* Ae, double* X, int64_t* place, int32_t* map);
int64_t add_cells_upper(uintptr_t address, int64_t ncells, const int32_t* cells, int64_t nb,
                        const int32_t* blocks, int64_t ng, const int32_t* geometry, const double* x,
                        const double* w, int64_t wstride, const double* c, const uint8_t* constrained,
                        int64_t bs, const int32_t* bi, const int32_t* bj, double* out, double* Ae, double* X,
                        int32_t* map, int64_t owned, const int64_t* global, const int32_t* oi,
                        const int32_t* oj, double* out_o, double* ghost, const int64_t* ghost_slot);
int64_t set_constrained_upper(int64_t nblocks, int64_t bs, const int32_t* bi, const int32_t* bj,
                              const uint8_t* constrained, double* out);
int64_t aij_from_upper(int64_t nblocks, int64_t bs, const int32_t* bi, const int32_t* bj, const double* S,
                       const int32_t* indptr, const int32_t* indices, double* values, int64_t* cursor);
int64_t set_constrained_diagonal(int64_t nrows, const int32_t* indptr, const int32_t* indices,
                                 const uint8_t* constrained, double* values);
int64_t set_diagonal(int64_t nrows, const int32_t* indptr, const int32_t* indices, const double* diag,
                     double* values);
void expand_blocks(int64_t n, int64_t bs, const int64_t* offsets, const int32_t* links, const int64_t* to_global,
                   int32_t* indptr, int32_t* indices, int64_t* work);
void diagonal(int64_t nrows, const int32_t* indptr, const int32_t* indices, const double* values, double* out);
int64_t upper_blocks(int64_t nblocks, int64_t bs, const int32_t* indptr, const int32_t* indices,
                     const double* values, const int32_t* bi, const int32_t* bj, double* out);
void patch_moments(int64_t ncells, int64_t k, const int32_t* cells, int64_t d, const double* a,
                   const double* b, int64_t n, double* H);
void polar3(int64_t n, const double* H, double* R, uint8_t* ok);
int64_t unlike_rows(int64_t nodes, int64_t bs, const int32_t* indptr, const int32_t* indices);
void rotate_rows(int64_t nodes, int64_t bs, const int32_t* indptr, const double* base, const double* R,
                 double* values);
void scaled_dense(int64_t n, const int32_t* indptr, const int32_t* indices, const double* values, double* K,
                  double* s);
void scaled_band(int64_t n, const int32_t* indptr, const int32_t* indices, const double* values, int64_t kl,
                 int64_t ku, int64_t ldab, double* ab, double* s);
void bandwidths(int64_t n, const int32_t* indptr, const int32_t* indices, int64_t* out);
void lu_summary(int64_t n, const double* diagonal, const int32_t* piv, double null_pivot, int64_t* out);
void product_api(void* get_read, void* restore_read, void* get_write, void* restore_write, void* block_size,
                 void* object_state, void* get_array, void* restore_array);
int64_t product_register_copy(void* mat, int64_t token, void* copy, void* copy_mult, void* own_mult, int64_t state);
int copied_mult(void* mat, void* x, void* y);
int64_t product_register_diagonal(void* mat, int64_t token, int64_t n, const double* v, void* own, int64_t state);
int kept_diagonal(void* mat, void* d);
int64_t product_register(void* mat, int64_t token, int64_t kind, int64_t n, int64_t ncols, int64_t bs,
                         const int32_t* ia, const int32_t* ja, const double* v, void* petsc_op);
void product_forget(void* mat, int64_t token);
int sbaij_mult(void* mat, void* x, void* y);
int nodal_mult_transpose(void* mat, void* x, void* y);
int nodal_mult_add(void* mat, void* x, void* z, void* y);
"""

_MODULE = None


def _cache_dir() -> Path:
    root = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(root) / "dolfinx_corot"


def compiled():
    """The compiled loop (cffi) of this module, built once per machine and source (:func:`build`)."""
    global _MODULE
    if _MODULE is None:
        _MODULE = build("_dc_cells_", _SOURCE, _CDEF)
    return _MODULE


def _processor() -> str:
    """The processor's model and instruction sets (Linux's /proc/cpuinfo; else the platform's name)."""
    import platform

    try:
        with open("/proc/cpuinfo") as f:
            lines = [line for line in f if line.startswith(("model name", "flags", "Features"))]
        return "".join(sorted(set(lines)))
    except OSError:
        return platform.processor() + platform.machine()


def build(prefix: str, source: str, cdef: str, flags: tuple[str, ...] = ("-O2", "-g0")):
    """The cffi module of C ``source`` (declarations ``cdef``), compiled with ``flags`` once per
    machine, source and flags into the cache directory and named ``prefix`` + a hash of them; a
    build goes to a private directory first and is moved in whole, so that processes building at
    once do not read each other's half-written files. Code for this processor (``-march=native``)
    is named after the processor's instruction sets as well, so that a cache directory shared by
    different machines does not hand one another's code to the other."""
    import cffi

    salt = _processor() if "-march=native" in flags else ""
    digest = hashlib.sha1((source + cdef + " ".join(flags) + sys.version + salt).encode()).hexdigest()[:16]
    name = prefix + digest
    cache = _cache_dir()
    cache.mkdir(parents=True, exist_ok=True)
    built = list(cache.glob(name + "*.so"))
    if not built:
        ffi = cffi.FFI()
        ffi.cdef(cdef)
        ffi.set_source(name, source, extra_compile_args=list(flags))
        with tempfile.TemporaryDirectory(dir=cache) as tmp:
            library = Path(ffi.compile(tmpdir=tmp, verbose=False))
            target = cache / library.name
            os.replace(library, target)
        built = [target]
    spec = importlib.util.spec_from_file_location(name, built[0])
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


class CellAssembler:
    """The tangent of an FFCx bilinear form, added into the values of the AIJ matrix that DOLFINx
    made for it (its pattern; see the module's docstring): on one rank into the SeqAIJ matrix, on
    several into the owned rows' diagonal and off-diagonal blocks of the MPIAIJ matrix, the rows
    of ghost nodes handed back to be sent to their owners.

    integrals: ``(kernel address, cells, key)`` per cell integral; blocks: the space's dofmap
    (cells × nodes); geometry, x: the mesh's geometry dofmap and coordinates; constants(),
    coefficients(): the form's packed constants and its packed coefficients by key;
    constrained: the local scalar dofs of the Dirichlet conditions; bs: dofs a node; size: local
    scalar dofs, ghosts included (all of :func:`dolfinx_corot._dolfinx.cell_integrals`);
    owned: the owned nodes (None: all); ghosts: the global index of each ghost node's first dof."""

    def __init__(self, integrals, blocks, geometry, x, constants, coefficients, constrained: np.ndarray, bs: int,
                 size: int, owned: int | None = None, ghosts: np.ndarray | None = None):
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
        self.owned = size // bs if owned is None else int(owned)
        self.ghosts = np.zeros(0, dtype=np.int64) if ghosts is None else np.asarray(ghosts, dtype=np.int64)
        # the cells with a ghost node: their element matrices also go to the ghost rows' owners
        self.slots = []
        self.ghost_cells = []
        count = 0
        for _, cells, _ in self.integrals:
            touches = (self.blocks[cells] >= self.owned).any(axis=1)
            slot = np.full(len(cells), -1, dtype=np.int64)
            slot[touches] = np.arange(count, count + int(touches.sum()))
            count += int(touches.sum())
            self.slots.append(slot)
            self.ghost_cells.append(cells[touches])
        self.ghost_cells = np.concatenate(self.ghost_cells) if self.ghost_cells else np.zeros(0, dtype=np.int32)
        # their rows and columns for MatSetValuesBlockedLocal: the rows of owned nodes left out (−1)
        self._ghost_columns = self.blocks[self.ghost_cells]
        self._ghost_rows = np.where(self._ghost_columns < self.owned, -1, self._ghost_columns).astype(np.int32)
        self._calls = 0  # calls of assemble
        self._node_index = None  # several ranks: each local node's global index (assemble_upper)
        self.maps = None  # per integral: where each pair of a cell's nodes has its block in the rows
        self.upper_maps = None  # the same in the block rows of the upper triangle (assemble_upper)

    def ghost_columns(self, colmap: np.ndarray) -> np.ndarray:
        """Each ghost node's first column in the off-diagonal block whose columns are the global
        ``colmap`` (sorted), or −1 where its dofs are not all there."""
        at = np.searchsorted(colmap, self.ghosts)
        ok = np.ones(len(self.ghosts), dtype=bool)
        for b in range(self.bs):
            pos = at + b
            inside = pos < len(colmap)
            ok &= inside
            ok[inside] &= colmap[pos[inside]] == self.ghosts[inside] + b
        return np.where(ok, at, -1).astype(np.int32)

    def assemble(self, indptr, indices, values, off=None):
        """values (the matrix's CSR values of the owned rows and owned columns, zeroed) += the
        form's tangent; off: ``(indptr, indices, values, colmap)`` of the off-diagonal block
        (several ranks). Returns the rows of ghost nodes as ``(rows, columns, values)`` for
        ``MatSetValuesBlockedLocal`` (local node indices, −1 for the owned nodes' rows; values
        row-major, constrained rows and columns zero), or None on one rank. Raises RuntimeError
        if the pattern lacks an entry the form needs."""
        module = compiled()
        ffi, lib = module.ffi, module.lib

        def ptr(kind, a):
            return ffi.cast(kind + "*", a.ctypes.data)

        null = ffi.NULL
        c = np.ascontiguousarray(self.constants(), dtype=np.float64)
        if c.size == 0:
            c = np.zeros(1)
        packed = self.coefficients()
        nb = self.blocks.shape[1]
        n = nb * self.bs
        Ae = np.empty(n * n)
        X = np.empty(3 * self.geometry.shape[1])
        place = np.empty(nb, dtype=np.int64)
        held = self.constrained.view(np.uint8)
        ghost = np.zeros((len(self.ghost_cells), n * n))
        if off is not None:
            indptr_o, indices_o, values_o, colmap = off
            column = self.ghost_columns(colmap)
            off_args = (ptr("int32_t", column), ptr("int32_t", indptr_o), ptr("int32_t", indices_o),
                        ptr("double", values_o))
        else:
            off_args = (null, null, null, null)
        missing = 0
        # the places of the nodal blocks in their rows, kept from the second call on (where the
        # upper triangle alone is assembled after a first tangent into A, they would take 4 bytes
        # a node pair beside the upper triangle's own)
        self._calls += 1
        if self.maps is None and self._calls > 1:
            self.maps = [np.full((len(cells), nb * nb), -1, dtype=np.int32) for _, cells, _ in self.integrals]
        maps = self.maps if self.maps is not None else [None] * len(self.integrals)
        for (address, cells, key), slot, known in zip(self.integrals, self.slots, maps):
            w = np.ascontiguousarray(packed[key], dtype=np.float64)
            if w.size == 0:
                w = np.zeros((len(cells), 1))
            missing += lib.add_cells(address, len(cells), ptr("int32_t", cells), nb, ptr("int32_t", self.blocks),
                                     self.geometry.shape[1], ptr("int32_t", self.geometry), ptr("double", self.x),
                                     ptr("double", w), w.shape[1] if w.size else 0, ptr("double", c), self.owned,
                                     ptr("int32_t", indptr), ptr("int32_t", indices), ptr("double", values), *off_args,
                                     ptr("uint8_t", held), self.bs, ptr("double", ghost) if ghost.size else null,
                                     ptr("int64_t", slot) if len(self.ghost_cells) else null,
                                     ptr("double", Ae), ptr("double", X), ptr("int64_t", place),
                                     null if known is None else ptr("int32_t", known))
        missing += lib.set_constrained_diagonal(len(indptr) - 1, ptr("int32_t", indptr), ptr("int32_t", indices),
                                                ptr("uint8_t", held), ptr("double", values))
        if missing:
            raise RuntimeError(f"the matrix's pattern lacks {missing} entries of the form")
        if off is None:
            return None
        return self._ghost_rows, self._ghost_columns, ghost


    def assemble_upper(self, bi, bj, out, off=None):
        """out (the values of an SBAIJ matrix of the nodal upper block pattern ``bi``, ``bj``,
        column-major blocks) = the form's tangent, one rank: the upper triangle of the matrix that
        :meth:`assemble` adds into the AIJ matrix, to the last bit, without the AIJ matrix (the node
        pairs of a cell on or above the diagonal: 36 of the 64 blocks of a hexahedron). Several
        ranks: ``off = (oi, oj, out_o, first)``, (bi, bj) the pattern of the owned block columns
        (local indices) and (oi, oj) that of the higher ranks' columns (global block indices; out_o
        its values, row-major blocks), ``first`` the first owned node's global index; the order of
        a pair is that of its nodes' global indices, and the rows of ghost nodes are handed back
        as :meth:`assemble` hands them back. Raises RuntimeError if the pattern lacks a block the
        form needs."""
        module = compiled()
        ffi, lib = module.ffi, module.lib

        def ptr(kind, a):
            return ffi.cast(kind + "*", a.ctypes.data)

        c = np.ascontiguousarray(self.constants(), dtype=np.float64)
        if c.size == 0:
            c = np.zeros(1)
        packed = self.coefficients()
        nb = self.blocks.shape[1]
        n = nb * self.bs
        Ae = np.empty(n * n)
        X = np.empty(3 * self.geometry.shape[1])
        held = self.constrained.view(np.uint8)
        if self.upper_maps is None:
            self.upper_maps = [np.full((len(cells), nb * nb), -1, dtype=np.int32) for _, cells, _ in self.integrals]
        out[:] = 0.0
        null = ffi.NULL
        ghost = np.zeros((len(self.ghost_cells), n * n)) if off is not None else np.zeros((0, 0))
        if off is not None:
            oi, oj, out_o, first = off
            out_o[:] = 0.0
            if self._node_index is None or self._node_index[0] != first:  # each local node's global index
                self._node_index = np.concatenate([np.arange(first, first + self.owned, dtype=np.int64),
                                                   self.ghosts // self.bs])
            split = (self.owned, ptr("int64_t", self._node_index), ptr("int32_t", oi),
                     ptr("int32_t", oj) if len(oj) else null, ptr("double", out_o) if out_o.size else null,
                     ptr("double", ghost) if ghost.size else null)
        else:
            split = (len(bi) - 1, null, null, null, null, null)
        missing = 0
        for (address, cells, key), known, slot in zip(self.integrals, self.upper_maps, self.slots):
            w = np.ascontiguousarray(packed[key], dtype=np.float64)
            if w.size == 0:
                w = np.zeros((len(cells), 1))
            missing += lib.add_cells_upper(address, len(cells), ptr("int32_t", cells), nb, ptr("int32_t", self.blocks),
                                           self.geometry.shape[1], ptr("int32_t", self.geometry), ptr("double", self.x),
                                           ptr("double", w), w.shape[1] if w.size else 0, ptr("double", c),
                                           ptr("uint8_t", held), self.bs, ptr("int32_t", bi), ptr("int32_t", bj),
                                           ptr("double", out), ptr("double", Ae), ptr("double", X),
                                           ptr("int32_t", known), *split,
                                           ptr("int64_t", slot) if ghost.size else null)
        missing += lib.set_constrained_upper(len(bi) - 1, self.bs, ptr("int32_t", bi), ptr("int32_t", bj),
                                             ptr("uint8_t", held), ptr("double", out))
        if missing:
            raise RuntimeError(f"the SBAIJ pattern lacks {missing} blocks of the form")
        if off is None:
            return None
        return self._ghost_rows, self._ghost_columns, ghost


def aij_from_upper(bi, bj, S, bs: int, indptr, indices, values) -> None:
    """values (a symmetric AIJ matrix's CSR values; sorted columns) = the matrix whose upper block
    triangle is the SBAIJ values ``S`` (pattern ``bi``, ``bj``, column-major blocks of ``bs``),
    the lower triangle its mirror image; raises RuntimeError where the AIJ pattern lacks entries."""
    module = compiled()
    ffi, lib = module.ffi, module.lib

    def ptr(kind, a):
        return ffi.cast(kind + "*", a.ctypes.data)

    cursor = np.empty(len(indptr) - 1, dtype=np.int64)
    missing = lib.aij_from_upper(len(bi) - 1, bs, ptr("int32_t", bi), ptr("int32_t", bj), ptr("double", S),
                                 ptr("int32_t", indptr), ptr("int32_t", indices), ptr("double", values),
                                 ptr("int64_t", cursor))
    if missing:
        raise RuntimeError(f"the AIJ pattern lacks {missing} entries of the SBAIJ matrix")


def diagonal(indptr, indices, values) -> np.ndarray:
    """The diagonal entries of the CSR rows (indptr, indices, values) (0 where a row lacks one):
    those of an AIJ matrix, or of the owned block of an MPIAIJ one (local columns)."""
    module = compiled()
    ffi, lib = module.ffi, module.lib
    out = np.empty(len(indptr) - 1)
    if len(out):
        lib.diagonal(len(out), ffi.cast("int32_t*", indptr.ctypes.data), ffi.cast("int32_t*", indices.ctypes.data),
                     ffi.cast("double*", values.ctypes.data), ffi.cast("double*", out.ctypes.data))
    return out


def expand_blocks(offsets, links, to_global, bs: int):
    """(indptr, indices) int32: the scalar CSR of the owned rows of a nodal block pattern (block
    row r couples the local block columns links[offsets[r]:offsets[r + 1]], their global indices
    to_global), global columns sorted in each row (:c:func:`expand_blocks`)."""
    module = compiled()
    ffi, lib = module.ffi, module.lib
    offsets = np.ascontiguousarray(offsets, dtype=np.int64)
    links = np.ascontiguousarray(links, dtype=np.int32)
    to_global = np.ascontiguousarray(to_global, dtype=np.int64)
    n = len(offsets) - 1
    count = np.diff(offsets)
    indptr = np.empty(n * bs + 1, dtype=np.int32)
    indices = np.empty(int(offsets[-1]) * bs * bs, dtype=np.int32)
    work = np.empty(max(int(count.max(initial=0)), 1), dtype=np.int64)
    lib.expand_blocks(n, bs, ffi.cast("int64_t*", offsets.ctypes.data), ffi.cast("int32_t*", links.ctypes.data),
                      ffi.cast("int64_t*", to_global.ctypes.data), ffi.cast("int32_t*", indptr.ctypes.data),
                      ffi.cast("int32_t*", indices.ctypes.data if indices.size else work.ctypes.data),
                      ffi.cast("int64_t*", work.ctypes.data))
    return indptr, indices


def set_diagonal(indptr, indices, values, diag) -> None:
    """The diagonal entries of the CSR rows (indptr, indices, values) set to ``diag``; raises
    RuntimeError where a row lacks one."""
    module = compiled()
    ffi, lib = module.ffi, module.lib
    diag = np.ascontiguousarray(diag, dtype=np.float64)
    missing = lib.set_diagonal(len(indptr) - 1, ffi.cast("int32_t*", indptr.ctypes.data),
                               ffi.cast("int32_t*", indices.ctypes.data), ffi.cast("double*", diag.ctypes.data),
                               ffi.cast("double*", values.ctypes.data))
    if missing:
        raise RuntimeError(f"{missing} rows lack their diagonal entry")


def upper_blocks(indptr, indices, values, bs: int, bi, bj, out) -> None:
    """out (the values of an SBAIJ matrix of the upper block pattern ``bi``, ``bj``) = the upper
    triangle of the symmetric AIJ matrix (indptr, indices, values) with nodal blocks of ``bs``;
    raises RuntimeError where the AIJ matrix has entries right of its diagonal block that the
    SBAIJ pattern lacks."""
    module = compiled()
    ffi, lib = module.ffi, module.lib

    def ptr(kind, a):
        return ffi.cast(kind + "*", a.ctypes.data)

    missing = lib.upper_blocks(len(bi) - 1, bs, ptr("int32_t", indptr), ptr("int32_t", indices), ptr("double", values),
                               ptr("int32_t", bi), ptr("int32_t", bj), ptr("double", out))
    if missing:
        raise RuntimeError(f"the SBAIJ pattern lacks {missing} entries of the AIJ matrix")
