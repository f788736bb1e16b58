r"""Hyperelastic element kernels in C: the residual and the tangent of a total-Lagrangian continuum.

FFCx compiles the UFL forms of :mod:`dolfinx_corot.parts.solid` into kernels that treat the
tangent's integrand as a general fourth-order tensor of the two gradients: for trilinear
hexahedra 24 × 24 entries, each a sum of 9 products at each of the 8 Gauss points. The two
laws of this package are isotropic, and their tangent has a structure that makes it much
cheaper. With g_a = ∇_X N_a the reference gradients of the shape functions (a, b the nodes;
i, j the components of the test and trial displacements), the nodal block of the tangent of
∫ P(F) : ∇v dX is, at a point,

.. math::

   K_{ab,ij} = \tilde\lambda\, f_{a,i} f_{b,j} + \tilde\mu\,\bigl(f_{b,i} f_{a,j}
              + s_{ab} M_{ij}\bigr) + (g_a\cdot S g_b)\,\delta_{ij},

* St Venant–Kirchhoff (S = λ tr(E) I + 2μE, the material tangent λ I⊗I + 2μ 𝕀): f_a = F g_a,
  s_ab = g_a · g_b, M = F Fᵀ, λ̃ = λ, μ̃ = μ;
* neo-Hookean (S = μ(I − C⁻¹) + λ ln J C⁻¹, the material tangent λ C⁻¹⊗C⁻¹ + 2(μ − λ ln J)
  𝕀_{C⁻¹}): f_a = F⁻ᵀ g_a (the current gradients), s_ab = f_a · f_b, M = I, λ̃ = λ,
  μ̃ = μ − λ ln J;

the last term being the geometric stiffness. The strains are formed from H = ∇u,
E = (H + Hᵀ + HᵀH)/2 and J − 1 from the invariants of H (ln J = log1p(J − 1)), not as FᵀF − I
and det F − 1: those differences of numbers near 1 keep about 7 of the 16 digits of a strain of
1e-9 (FFCx's kernels of the UFL forms are off by 8e-8 there; these by 2e-15). The block is
symmetric in (a, i) ↔ (b, j): only the blocks b ≥ a are computed, at four points at once (the
points are the inner index, held in vectors of four doubles; the rule is padded with points of
weight 0), and mirrored. The residual is ∫ F S g_a dX. Both are the
UFL forms' integrals with the same quadrature (FFCx's default rule of the same degree) and
the same tabulated shape functions (basix), to rounding; in 2D (plane strain) F, S, E are
2 × 2 as in :mod:`.laws`.

The kernels have the ufcx ``tabulate_tensor`` signature: w holds the cell's displacement dofs
(nodes × components), then E and ν (DG0); the geometry is 3 coordinates a node. A kernel is
generated for each law, cell, degree, geometry degree and quadrature degree, its tables baked
in, and compiled by cffi once per machine (:func:`dolfinx_corot.assembly.cells.build`).
"""
from __future__ import annotations

import numpy as np

from ..assembly import cells as _cells
from ..materials import Elastic, NeoHookean

_TEMPLATE = r"""
#include <math.h>
#include <stdint.h>

#define D @D@
#define NN @NN@
#define NG @NG@
#define NC @NC@ /* chunks of 4 points (the rule padded with points of weight 0) */
#define NEO @NEO@
#define N (NN * D)

typedef double vd __attribute__((vector_size(32)));
#define SPLAT(s) ((vd){(s), (s), (s), (s)})

static const vd W[NC] = @W@;
/* reference derivatives of the displacement's (DN) and of the geometry's (DG) shape functions,
   [direction][node][chunk of points] */
static const vd DN[D][NN][NC] = @DN@;
static const vd DG[D][NG][NC] = @DG@;

#define HSUM(v) (((v)[0] + (v)[2]) + ((v)[1] + (v)[3]))

/* det A (the cofactor expansion) */
static inline vd determinant(vd A[D][D])
{
#if D == 3
  return A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) - A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0])
       + A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
#else
  return A[0][0] * A[1][1] - A[0][1] * A[1][0];
#endif
}

/* Ai = A^-1 by cofactors, given det A */
static inline void inverse(vd A[D][D], vd det, vd Ai[D][D])
{
#if D == 3
  Ai[0][0] = (A[1][1] * A[2][2] - A[1][2] * A[2][1]) / det;
  Ai[0][1] = (A[0][2] * A[2][1] - A[0][1] * A[2][2]) / det;
  Ai[0][2] = (A[0][1] * A[1][2] - A[0][2] * A[1][1]) / det;
  Ai[1][0] = (A[1][2] * A[2][0] - A[1][0] * A[2][2]) / det;
  Ai[1][1] = (A[0][0] * A[2][2] - A[0][2] * A[2][0]) / det;
  Ai[1][2] = (A[0][2] * A[1][0] - A[0][0] * A[1][2]) / det;
  Ai[2][0] = (A[1][0] * A[2][1] - A[1][1] * A[2][0]) / det;
  Ai[2][1] = (A[0][1] * A[2][0] - A[0][0] * A[2][1]) / det;
  Ai[2][2] = (A[0][0] * A[1][1] - A[0][1] * A[1][0]) / det;
#else
  Ai[0][0] = A[1][1] / det;
  Ai[0][1] = -A[0][1] / det;
  Ai[1][0] = -A[1][0] / det;
  Ai[1][1] = A[0][0] / det;
#endif
}

/* At every point: the weight times |det J| (wq), the reference gradients g[a][k], F, the
   law's 2nd Piola–Kirchhoff stress S, f[a][i], M[i][j] and mu~ (see the module's docstring).
   Returns 0, or 1 where J <= 0 (neo-Hookean: no stress there). */
static int points(const double* w, const double* X, vd wq[NC], vd g[NN][D][NC], vd F[D][D][NC],
                  vd S[D][D][NC], vd f[NN][D][NC], vd M[D][D][NC], vd mut[NC], double* lmbda_out)
{
  const double E = w[N], nu = w[N + 1];
  const double lmbda = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), mu = E / (2.0 * (1.0 + nu));
  *lmbda_out = lmbda;
  int bad = 0;
  for (int q = 0; q < NC; ++q)
  {
    vd J[D][D], K[D][D];
    for (int i = 0; i < D; ++i)
      for (int k = 0; k < D; ++k)
      {
        vd s = SPLAT(0.0);
        for (int n = 0; n < NG; ++n)
          s += SPLAT(X[3 * n + i]) * DG[k][n][q];
        J[i][k] = s;
      }
    const vd det = determinant(J);
    inverse(J, det, K);
    for (int l = 0; l < 4; ++l)
      wq[q][l] = W[q][l] * fabs(det[l]);
    /* g_a = J^-T dN_a; H = grad u = sum_a u_a g_a^T, F = I + H. The strains are formed from H
       (E = (H + H^T + H^T H) / 2, J - 1 from the invariants of H), not as F^T F - I and det F - 1,
       whose differences of numbers near 1 lose the digits of small strains (a stiff region
       strained by 1e-8 would keep half of its stress's digits). */
    vd H[D][D];
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
        H[i][j] = SPLAT(0.0);
    for (int a = 0; a < NN; ++a)
      for (int k = 0; k < D; ++k)
      {
        vd s = SPLAT(0.0);
        for (int l = 0; l < D; ++l)
          s += DN[l][a][q] * K[l][k];
        g[a][k][q] = s;
        for (int i = 0; i < D; ++i)
          H[i][k] += SPLAT(w[a * D + i]) * s;
      }
    vd Fq[D][D], Eg[D][D];
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
      {
        Fq[i][j] = H[i][j] + SPLAT(i == j ? 1.0 : 0.0);
        F[i][j][q] = Fq[i][j];
        vd s = H[i][j] + H[j][i];
        for (int k = 0; k < D; ++k)
          s += H[k][i] * H[k][j];
        Eg[i][j] = SPLAT(0.5) * s;
      }
#if NEO
    /* S = mu (I - C^-1) + lambda ln J C^-1 = C^-1 (2 mu E + lambda ln J I); f_a = F^-T g_a; M = I;
       mu~ = mu - lambda ln J */
    vd Fi[D][D], Ci[D][D], lnJ;
#if D == 3
    const vd Jm1 = H[0][0] + H[1][1] + H[2][2]
                 + (H[0][0] * H[1][1] - H[0][1] * H[1][0]) + (H[0][0] * H[2][2] - H[0][2] * H[2][0])
                 + (H[1][1] * H[2][2] - H[1][2] * H[2][1]) + determinant(H);
#else
    const vd Jm1 = H[0][0] + H[1][1] + determinant(H);
#endif
    const vd Jd = SPLAT(1.0) + Jm1;
    inverse(Fq, Jd, Fi);
    for (int l = 0; l < 4; ++l)
    {
      bad |= !(Jd[l] > 0.0);
      lnJ[l] = log1p(Jm1[l]);
    }
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
      {
        vd s = SPLAT(0.0);
        for (int k = 0; k < D; ++k)
          s += Fi[i][k] * Fi[j][k];
        Ci[i][j] = s;
      }
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
      {
        vd s = SPLAT(lmbda) * lnJ * Ci[i][j];
        for (int k = 0; k < D; ++k)
          s += Ci[i][k] * SPLAT(2.0 * mu) * Eg[k][j];
        S[i][j][q] = s;
        M[i][j][q] = SPLAT(i == j ? 1.0 : 0.0);
      }
    mut[q] = SPLAT(mu) - SPLAT(lmbda) * lnJ;
    vd T[D][D]; /* f_a = T g_a */
    for (int i = 0; i < D; ++i)
      for (int k = 0; k < D; ++k)
        T[i][k] = Fi[k][i];
#else
    /* S = lambda tr(E) I + 2 mu E; f_a = F g_a; M = F F^T; mu~ = mu */
    vd trE = SPLAT(0.0);
    for (int i = 0; i < D; ++i)
      trE += Eg[i][i];
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
      {
        S[i][j][q] = (i == j ? SPLAT(lmbda) * trE : SPLAT(0.0)) + SPLAT(2.0 * mu) * Eg[i][j];
        vd s = SPLAT(0.0);
        for (int k = 0; k < D; ++k)
          s += Fq[i][k] * Fq[j][k];
        M[i][j][q] = s;
      }
    mut[q] = SPLAT(mu);
    vd T[D][D]; /* f_a = T g_a */
    for (int i = 0; i < D; ++i)
      for (int k = 0; k < D; ++k)
        T[i][k] = Fq[i][k];
#endif
    for (int a = 0; a < NN; ++a)
      for (int i = 0; i < D; ++i)
      {
        vd s = SPLAT(0.0);
        for (int k = 0; k < D; ++k)
          s += T[i][k] * g[a][k][q];
        f[a][i][q] = s;
      }
  }
  return bad;
}

/* b += the cell's residual: the sum over the points of wq F S g_a */
void residual(double* b, const double* w, const double* c, const double* X, const int* entity,
              const uint8_t* permutation)
{
  vd wq[NC], g[NN][D][NC], F[D][D][NC], S[D][D][NC], f[NN][D][NC], M[D][D][NC], mut[NC];
  double lmbda;
  if (points(w, X, wq, g, F, S, f, M, mut, &lmbda))
  {
    for (int r = 0; r < N; ++r)
      b[r] += NAN;
    return;
  }
  vd P[D][D][NC];
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j)
      for (int q = 0; q < NC; ++q)
      {
        vd s = SPLAT(0.0);
        for (int k = 0; k < D; ++k)
          s += F[i][k][q] * S[k][j][q];
        P[i][j][q] = wq[q] * s;
      }
  for (int a = 0; a < NN; ++a)
    for (int i = 0; i < D; ++i)
    {
      vd s = SPLAT(0.0);
      for (int q = 0; q < NC; ++q)
        for (int j = 0; j < D; ++j)
          s += P[i][j][q] * g[a][j][q];
      b[a * D + i] += HSUM(s);
    }
}

/* A += the cell's tangent (row-major N x N): the blocks b >= a, mirrored */
void tangent(double* A, const double* w, const double* c, const double* X, const int* entity,
             const uint8_t* permutation)
{
  vd wq[NC], g[NN][D][NC], F[D][D][NC], S[D][D][NC], f[NN][D][NC], M[D][D][NC], mut[NC];
  double lmbda;
  if (points(w, X, wq, g, F, S, f, M, mut, &lmbda))
  {
    for (int r = 0; r < N * N; ++r)
      A[r] += NAN;
    return;
  }
  /* weighted: lf = wq lambda f, mf = wq mu~ f, Sg = wq S g, mM = wq mu~ M; x: g (SVK) or f (NH) */
  vd lf[NN][D][NC], mf[NN][D][NC], Sg[NN][D][NC], mM[D][D][NC];
  for (int a = 0; a < NN; ++a)
    for (int i = 0; i < D; ++i)
      for (int q = 0; q < NC; ++q)
      {
        lf[a][i][q] = wq[q] * SPLAT(lmbda) * f[a][i][q];
        mf[a][i][q] = wq[q] * mut[q] * f[a][i][q];
        vd s = SPLAT(0.0);
        for (int k = 0; k < D; ++k)
          s += S[i][k][q] * g[a][k][q];
        Sg[a][i][q] = wq[q] * s;
      }
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j)
      for (int q = 0; q < NC; ++q)
        mM[i][j][q] = wq[q] * mut[q] * M[i][j][q];
#if NEO
#define X_ f
#else
#define X_ g
#endif
  for (int a = 0; a < NN; ++a)
    for (int b = a; b < NN; ++b)
    {
      vd K[D][D];
      for (int i = 0; i < D; ++i)
        for (int j = 0; j < D; ++j)
          K[i][j] = SPLAT(0.0);
      for (int q = 0; q < NC; ++q)
      {
        vd s = SPLAT(0.0), t = SPLAT(0.0);
        for (int k = 0; k < D; ++k)
        {
          s += X_[a][k][q] * X_[b][k][q];
          t += g[a][k][q] * Sg[b][k][q];
        }
        for (int i = 0; i < D; ++i)
          for (int j = 0; j < D; ++j)
            K[i][j] += lf[a][i][q] * f[b][j][q] + mf[b][i][q] * f[a][j][q] + s * mM[i][j][q]
                       + (i == j ? t : SPLAT(0.0));
      }
      for (int i = 0; i < D; ++i)
        for (int j = 0; j < D; ++j)
        {
          const double sum = HSUM(K[i][j]);
          A[(a * D + i) * N + b * D + j] += sum;
          if (b > a)
            A[(b * D + j) * N + a * D + i] += sum;
        }
    }
#undef X_
}
"""

_CDEF = """
void residual(double* b, const double* w, const double* c, const double* X, const int* entity,
              const uint8_t* permutation);
void tangent(double* A, const double* w, const double* c, const double* X, const int* entity,
             const uint8_t* permutation);
"""

_MODULES: dict = {}


def _neo(law: type) -> int:
    """1 for the neo-Hookean law, 0 for St Venant–Kirchhoff (the law of every other elastic
    material at large rotations, as in :func:`.laws.first_piola`)."""
    if issubclass(law, NeoHookean):
        return 1
    if issubclass(law, Elastic):
        return 0
    raise TypeError(f"no compiled continuum kernel for {law.__name__}")


def _array(values) -> str:
    """A C initializer of the (nested) array ``values``."""
    if np.ndim(values) == 0:
        return repr(float(values))
    return "{" + ", ".join(_array(v) for v in values) + "}"


def source(law: type, cell: str, degree: int, geometry_degree: int, quadrature_degree: int) -> str:
    """The C source of the kernels of ``law`` on Lagrange elements of ``degree`` on ``cell``
    (basix's name) with geometry of ``geometry_degree``, FFCx's default rule of
    ``quadrature_degree``."""
    import basix

    celltype = basix.cell.string_to_type(cell)
    points, weights = basix.make_quadrature(basix.QuadratureType.Default, celltype, quadrature_degree)
    d = points.shape[1]

    def derivatives(p):
        element = basix.create_element(basix.ElementFamily.P, celltype, p, basix.LagrangeVariant.gll_warped)
        table = element.tabulate(1, points)[1:, :, :, 0]  # (direction, point, node)
        return np.transpose(table, (0, 2, 1))  # (direction, node, point)

    # the rule padded to chunks of 4 points with copies of its first point of weight 0
    nq = len(weights)
    chunks = -(-nq // 4)
    pad = np.concatenate([np.arange(nq), np.zeros(4 * chunks - nq, dtype=int)])
    weights = np.where(np.arange(4 * chunks) < nq, weights[pad], 0.0)
    dn, dg = derivatives(degree)[:, :, pad], derivatives(geometry_degree)[:, :, pad]

    def chunked(table):  # (..., 4 chunks) → (..., chunks, 4)
        return table.reshape(table.shape[:-1] + (chunks, 4))

    text = _TEMPLATE
    for key, value in {"D": d, "NN": dn.shape[1], "NG": dg.shape[1], "NC": chunks, "NEO": _neo(law),
                       "W": _array(chunked(weights)), "DN": _array(chunked(dn)),
                       "DG": _array(chunked(dg))}.items():
        text = text.replace(f"@{key}@", str(value))
    return text


def kernels(law: type, cell: str, degree: int, geometry_degree: int, quadrature_degree: int) -> tuple[int, int]:
    """(residual, tangent): the addresses of the compiled kernels (see :func:`source`), compiled
    on first use and cached on disk."""
    _neo(law)
    key = (law, cell, degree, geometry_degree, quadrature_degree)
    module = _MODULES.get(key)
    if module is None:
        text = source(*key)
        try:  # code for this processor's vector instructions
            module = _cells.build("_dc_hyperelastic_", text, _CDEF, ("-O3", "-march=native", "-Wno-psabi", "-g0"))
        except Exception:  # a compiler without -march=native
            module = _cells.build("_dc_hyperelastic_", text, _CDEF, ("-O3", "-Wno-psabi", "-g0"))
        _MODULES[key] = module
    ffi, lib = module.ffi, module.lib
    return (int(ffi.cast("uintptr_t", ffi.addressof(lib, "residual"))),
            int(ffi.cast("uintptr_t", ffi.addressof(lib, "tangent"))))
