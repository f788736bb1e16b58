/* Co-rotational two-node beams and bars in the plane, in C.

   The same arithmetic, in the same order, as the numba functions of
   dolfinx_corot.kernels.line2d (evaluate: the co-rotational element and the geometrically linear
   one), dolfinx_corot.corotation.frame2d (the frame from the chord, the element-frame angles from
   sines and cosines, Battini 2002; the projector and the geometric stiffness, Crisfield 1991
   section 7.3) and dolfinx_corot.elements.line2d (the shallow-arch law). Compiled into one library
   with beam3d.c.

   w = [state node 1 (u, v, theta), state node 2, props (EA, EI, GAs, N0)], c[0]: 1 co-rotational,
   0 geometrically linear; coordinate_dofs (2, 3). */

enum { L2_EA, L2_EI, L2_GAS, L2_N0 };

static void l2_basic_response(double l0, double ubar, double t1, double t2, const double* props, double* fbar,
                              double kbar[3][3], int shallow_arch)
{
  double ea = props[L2_EA], ei = props[L2_EI], gas = props[L2_GAS];
  double phi = gas > 0.0 ? 12.0 * ei / (gas * l0 * l0) : 0.0;
  double k = ei / (l0 * (1.0 + phi));
  double kd = k * (4.0 + phi);
  double ko = k * (2.0 - phi);
  double g0, g1, g2, eps;
  int coupled = shallow_arch && ei > 0.0;
  if (coupled)
  {
    g0 = 1.0 / l0;
    g1 = (4.0 * t1 - t2) / 30.0;
    g2 = (4.0 * t2 - t1) / 30.0;
    eps = ubar / l0 + (2.0 * t1 * t1 - t1 * t2 + 2.0 * t2 * t2) / 30.0;
  }
  else
  {
    g0 = 1.0 / l0;
    g1 = 0.0;
    g2 = 0.0;
    eps = ubar / l0;
  }
  double n = ea * eps + props[L2_N0];
  double nl = n * l0;
  fbar[0] = n;
  fbar[1] = kd * t1 + ko * t2 + nl * g1;
  fbar[2] = ko * t1 + kd * t2 + nl * g2;
  double eal = ea * l0;
  kbar[0][0] = eal * g0 * g0;
  kbar[0][1] = eal * g0 * g1;
  kbar[0][2] = eal * g0 * g2;
  kbar[1][0] = kbar[0][1];
  kbar[2][0] = kbar[0][2];
  kbar[1][1] = eal * g1 * g1 + kd;
  kbar[2][2] = eal * g2 * g2 + kd;
  kbar[1][2] = eal * g1 * g2 + ko;
  kbar[2][1] = kbar[1][2];
  if (coupled)
  {
    kbar[1][1] += 4.0 * nl / 30.0;
    kbar[2][2] += 4.0 * nl / 30.0;
    kbar[1][2] -= nl / 30.0;
    kbar[2][1] -= nl / 30.0;
  }
}

static void l2_fill_projector(double l, double c, double s, double P[3][6])
{
  memset(P, 0, 18 * sizeof(double));
  P[0][0] = -c;
  P[0][1] = -s;
  P[0][3] = c;
  P[0][4] = s;
  for (int row = 1; row <= 2; ++row)
  {
    P[row][0] = -s / l;
    P[row][1] = c / l;
    P[row][3] = s / l;
    P[row][4] = -c / l;
  }
  P[1][2] = 1.0;
  P[2][5] = 1.0;
}

/* f = P^T f-bar */
static void l2_force(double P[3][6], const double* fbar, double* f)
{
  for (int i = 0; i < 6; ++i)
  {
    double acc = P[0][i] * fbar[0];
    acc += P[1][i] * fbar[1];
    acc += P[2][i] * fbar[2];
    f[i] = acc;
  }
}

/* K = P^T K-bar P + N/l z z^T + (M1 + M2)/l^2 (r z^T + z r^T) */
static void l2_global_stiffness(double l, double c, double s, double P[3][6], double kbar[3][3],
                                const double* fbar, double* K)
{
  for (int i = 0; i < 6; ++i)
  {
    double a0 = kbar[0][0] * P[0][i] + kbar[1][0] * P[1][i] + kbar[2][0] * P[2][i];
    double a1 = kbar[0][1] * P[0][i] + kbar[1][1] * P[1][i] + kbar[2][1] * P[2][i];
    double a2 = kbar[0][2] * P[0][i] + kbar[1][2] * P[1][i] + kbar[2][2] * P[2][i];
    for (int j = 0; j < 6; ++j)
      K[i * 6 + j] = a0 * P[0][j] + a1 * P[1][j] + a2 * P[2][j];
  }
  double gN = fbar[0] / l;
  double gM = (fbar[1] + fbar[2]) / (l * l);
  double r0 = -c, r1 = -s, z0 = s, z1 = -c;
  static const int idx[4] = {0, 1, 3, 4};
  static const double sgn[4] = {1.0, 1.0, -1.0, -1.0};
  for (int a = 0; a < 4; ++a)
  {
    int i = idx[a];
    double ri = sgn[a] * (i % 3 == 0 ? r0 : r1);
    double zi = sgn[a] * (i % 3 == 0 ? z0 : z1);
    for (int b = 0; b < 4; ++b)
    {
      int j = idx[b];
      double rj = sgn[b] * (j % 3 == 0 ? r0 : r1);
      double zj = sgn[b] * (j % 3 == 0 ? z0 : z1);
      K[i * 6 + j] += gN * zi * zj + gM * (ri * zj + zi * rj);
    }
  }
}

static void l2_evaluate(double x1, double y1, double x2, double y2, const double* d, const double* props,
                        int large_rotations, double* f, double* K)
{
  double P[3][6], fbar[3], kbar[3][3];
  double dx0 = x2 - x1, dy0 = y2 - y1;
  double l0 = sqrt(dx0 * dx0 + dy0 * dy0);
  double c0 = dx0 / l0, s0 = dy0 / l0;
  if (large_rotations)
  {
    double dx = x2 + d[3] - x1 - d[0];
    double dy = y2 + d[4] - y1 - d[1];
    double l = sqrt(dx * dx + dy * dy);
    double c = dx / l, s = dy / l;
    double ubar = (l * l - l0 * l0) / (l + l0);
    double cb = c0 * c + s0 * s;
    double sb = s0 * c - c0 * s;
    double ct1 = cos(d[2]), st1 = sin(d[2]);
    double ct2 = cos(d[5]), st2 = sin(d[5]);
    double t1 = atan2(st1 * cb + ct1 * sb, ct1 * cb - st1 * sb);
    double t2 = atan2(st2 * cb + ct2 * sb, ct2 * cb - st2 * sb);
    l2_basic_response(l0, ubar, t1, t2, props, fbar, kbar, 1);
    l2_fill_projector(l, c, s, P);
    l2_force(P, fbar, f);
    l2_global_stiffness(l, c, s, P, kbar, fbar, K);
    return;
  }
  l2_fill_projector(l0, c0, s0, P);
  double ub = 0.0, t1 = 0.0, t2 = 0.0;
  for (int j = 0; j < 6; ++j)
  {
    ub += P[0][j] * d[j];
    t1 += P[1][j] * d[j];
    t2 += P[2][j] * d[j];
  }
  l2_basic_response(l0, ub, t1, t2, props, fbar, kbar, 0);
  l2_force(P, fbar, f);
  double KB[3][6];
  for (int r = 0; r < 3; ++r)
    for (int j = 0; j < 6; ++j)
    {
      double acc = kbar[r][0] * P[0][j];
      acc += kbar[r][1] * P[1][j];
      acc += kbar[r][2] * P[2][j];
      KB[r][j] = acc;
    }
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j)
    {
      double acc = P[0][i] * KB[0][j];
      acc += P[1][i] * KB[1][j];
      acc += P[2][i] * KB[2][j];
      K[i * 6 + j] = acc;
    }
}

void line2d_vector(double* A, const double* w, const double* c, const double* coordinate_dofs,
                   const int* entity_local_index, const uint8_t* quadrature_permutation)
{
  double K[36];
  const double* X = coordinate_dofs;
  l2_evaluate(X[0], X[1], X[3], X[4], w, w + 6, c[0] != 0.0, A, K);
}

void line2d_matrix(double* A, const double* w, const double* c, const double* coordinate_dofs,
                   const int* entity_local_index, const uint8_t* quadrature_permutation)
{
  double f[6];
  const double* X = coordinate_dofs;
  l2_evaluate(X[0], X[1], X[3], X[4], w, w + 6, c[0] != 0.0, f, A);
}

/* all elements: X (n, 2, 2), D (n, 6), props (n, 4) -> F (n, 6), K (n, 6, 6) (kernels.line2d.evaluate_all) */
void line2d_evaluate_all(int64_t n, const double* X, const double* D, const double* props, int64_t large_rotations,
                         double* F, double* K)
{
  for (int64_t e = 0; e < n; ++e)
  {
    const double* Xe = X + 4 * e;
    l2_evaluate(Xe[0], Xe[1], Xe[2], Xe[3], D + 6 * e, props + 4 * e, large_rotations != 0, F + 6 * e, K + 36 * e);
  }
}
