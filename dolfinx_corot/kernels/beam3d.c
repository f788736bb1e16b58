/* Co-rotational two-node beams and bars in space, and the nodal rotation updates, in C.

   The same arithmetic, in the same order, as the numba functions of
   dolfinx_corot.kernels.beam3d (its _evaluate and _tabulate),
   dolfinx_corot.corotation.frame3d (Battini & Pacoste 2002: the element frame, the basic
   deformations and B, the closed-form geometric stiffness), dolfinx_corot.elements.beam3d (the
   small-strain law with Crisfield's shallow-arch strain) and dolfinx_corot.rotations (Spurrier's
   quaternion, the logarithm, T^-1(theta) and its derivative, the multiplicative update of a
   quaternion). Compiled without contraction of products and sums into FMAs, the results equal
   the numba kernels' to rounding; the tests compare the two (and keep the numba versions for the
   complex-step derivatives, which need complex arithmetic).

   Arrays are row-major: a node's state (u (3), quaternion (w, x, y, z)); the element vector
   (u1, w1, u2, w2) with spatial spins w; props = (EA, GJ, EIy, EIz, GAy, GAz, N0, vx, vy, vz). */
#include <math.h>
#include <stdint.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif
#define NSTATE 7
#define NPROPS 10
enum { P_EA, P_GJ, P_EIY, P_EIZ, P_GAY, P_GAZ, P_N0, P_VX, P_VY, P_VZ };

typedef double m3[3][3];

static double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* out = A^T B */
static void matmul3_tn(m3 A, m3 B, m3 out)
{
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[i][j] = A[0][i] * B[0][j] + A[1][i] * B[1][j] + A[2][i] * B[2][j];
}

/* out = A B */
static void matmul3(m3 A, m3 B, m3 out)
{
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      out[i][j] = A[i][0] * B[0][j] + A[i][1] * B[1][j] + A[i][2] * B[2][j];
}

static void quat_to_matrix(const double* q, m3 R)
{
  double w = q[0], x = q[1], y = q[2], z = q[3];
  R[0][0] = 1.0 - 2.0 * (y * y + z * z);
  R[0][1] = 2.0 * (x * y - w * z);
  R[0][2] = 2.0 * (x * z + w * y);
  R[1][0] = 2.0 * (x * y + w * z);
  R[1][1] = 1.0 - 2.0 * (x * x + z * z);
  R[1][2] = 2.0 * (y * z - w * x);
  R[2][0] = 2.0 * (x * z - w * y);
  R[2][1] = 2.0 * (y * z + w * x);
  R[2][2] = 1.0 - 2.0 * (x * x + y * y);
}

/* (w, x, y, z) of R with w >= 0 (Spurrier 1978: from the largest of tr R and the diagonal) */
static void quaternion(m3 R, double* q)
{
  double tr = R[0][0] + R[1][1] + R[2][2];
  if (tr >= R[0][0] && tr >= R[1][1] && tr >= R[2][2])
  {
    double w = 0.5 * sqrt(1.0 + tr);
    double f = 0.25 / w;
    q[0] = w;
    q[1] = (R[2][1] - R[1][2]) * f;
    q[2] = (R[0][2] - R[2][0]) * f;
    q[3] = (R[1][0] - R[0][1]) * f;
    return;
  }
  double d0 = R[0][0], d1 = R[1][1], d2 = R[2][2];
  double m = fmax(fmax(d0, d1), d2);
  int i = 0;
  if (d1 == m)
    i = 1;
  else if (d2 == m)
    i = 2;
  int j = (i + 1) % 3, k = (i + 2) % 3;
  double qi = 0.5 * sqrt(1.0 + 2.0 * R[i][i] - tr);
  double f = 0.25 / qi;
  double w = (R[k][j] - R[j][k]) * f;
  double qj = (R[j][i] + R[i][j]) * f;
  double qk = (R[k][i] + R[i][k]) * f;
  double x, y, z;
  if (i == 0)
  {
    x = qi; y = qj; z = qk;
  }
  else if (i == 1)
  {
    x = qk; y = qi; z = qj;
  }
  else
  {
    x = qj; y = qk; z = qi;
  }
  if (w < 0.0)
  {
    w = -w; x = -x; y = -y; z = -z;
  }
  q[0] = w; q[1] = x; q[2] = y; q[3] = z;
}

/* th = rotation vector of the quaternion (w >= 0): angle 2 atan(|v|/w) along v */
static void rotation_vector(double w, double x, double y, double z, double* th)
{
  double s2 = x * x + y * y + z * z;
  double c;
  if (fabs(s2) < 1e-16)
    c = (2.0 / w) * (1.0 - s2 / (3.0 * w * w));
  else
  {
    double s = sqrt(s2);
    if (w >= s)
      c = 2.0 * atan(s / w) / s;
    else
      c = (M_PI - 2.0 * atan(w / s)) / s;
  }
  th[0] = c * x;
  th[1] = c * y;
  th[2] = c * z;
}

static void log_so3(m3 R, double* th)
{
  double q[4];
  quaternion(R, q);
  rotation_vector(q[0], q[1], q[2], q[3], th);
}

/* out = I + a W + b W^2, W = spin(w), t2 = |w|^2 */
static void rodrigues_form(const double* w, double t2, double a, double b, m3 out)
{
  double d = 1.0 - b * t2;
  for (int i = 0; i < 3; ++i)
  {
    for (int j = 0; j < 3; ++j)
      out[i][j] = b * w[i] * w[j];
    out[i][i] += d;
  }
  out[0][1] -= a * w[2];
  out[0][2] += a * w[1];
  out[1][0] += a * w[2];
  out[1][2] -= a * w[0];
  out[2][0] -= a * w[1];
  out[2][1] += a * w[0];
}

/* T^-1(w) = I - W/2 + (1 - (t/2) cot(t/2))/t^2 W^2 */
static void tangent_inv_so3(const double* w, m3 out)
{
  double t2 = dot3(w, w);
  double c;
  if (fabs(t2) < 1e-6)
    c = 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0;
  else
  {
    double h = 0.5 * sqrt(t2);
    c = (1.0 - h * cos(h) / sin(h)) / t2;
  }
  rodrigues_form(w, t2, -0.5, c, out);
}

/* out = d(T^-T(th) m)/d th (Battini & Pacoste 2002's K_h; rotations.tangent_inv_so3_derivative) */
static void tangent_inv_so3_derivative(const double* th, const double* m, m3 out)
{
  double s = th[0] * th[0] + th[1] * th[1] + th[2] * th[2];
  double c, dc;
  if (s < 1e-2)
  {
    c = 1.0 / 12.0 + s * (1.0 / 720.0 + s * (1.0 / 30240.0 + s * (1.0 / 1209600.0 + s / 47900160.0)));
    dc = 1.0 / 720.0 + s * (2.0 / 30240.0 + s * (3.0 / 1209600.0 + s * 4.0 / 47900160.0));
  }
  else
  {
    double h = 0.5 * sqrt(s);
    double sn = sin(h);
    double cot = cos(h) / sn;
    c = (1.0 - h * cot) / s;
    dc = -(cot - h / (sn * sn)) / (32.0 * h * h * h) - c / s;
  }
  double tm = th[0] * m[0] + th[1] * m[1] + th[2] * m[2];
  for (int a = 0; a < 3; ++a)
  {
    double wa = th[a] * tm - m[a] * s;
    for (int b = 0; b < 3; ++b)
      out[a][b] = c * (th[a] * m[b] - 2.0 * m[a] * th[b]) + 2.0 * dc * wa * th[b];
    out[a][a] += c * tm;
  }
  out[0][1] += 0.5 * m[2];
  out[0][2] -= 0.5 * m[1];
  out[1][0] -= 0.5 * m[2];
  out[1][2] += 0.5 * m[0];
  out[2][0] += 0.5 * m[1];
  out[2][1] -= 0.5 * m[0];
}

/* -- the element frame (frame3d) -------------------------------------------------------------- */

static double initial_frame(const double* X1, const double* X2, const double* v, m3 R0)
{
  double d0 = X2[0] - X1[0], d1 = X2[1] - X1[1], d2 = X2[2] - X1[2];
  double l0 = sqrt(d0 * d0 + d1 * d1 + d2 * d2);
  double a0 = d0 / l0, a1 = d1 / l0, a2 = d2 / l0;
  double va = v[0] * a0 + v[1] * a1 + v[2] * a2;
  double b0 = v[0] - va * a0, b1 = v[1] - va * a1, b2 = v[2] - va * a2;
  double nb = sqrt(b0 * b0 + b1 * b1 + b2 * b2);
  b0 = b0 / nb;
  b1 = b1 / nb;
  b2 = b2 / nb;
  R0[0][0] = a0; R0[1][0] = a1; R0[2][0] = a2;
  R0[0][1] = b0; R0[1][1] = b1; R0[2][1] = b2;
  R0[0][2] = a1 * b2 - a2 * b1;
  R0[1][2] = a2 * b0 - a0 * b2;
  R0[2][2] = a0 * b1 - a1 * b0;
  return l0;
}

static double current_frame(const double* X1, const double* X2, const double* u1, const double* u2, m3 R1,
                            m3 R2, m3 R0, m3 Rr, double* p1, double* p2)
{
  double x0 = X2[0] + u2[0] - X1[0] - u1[0];
  double x1 = X2[1] + u2[1] - X1[1] - u1[1];
  double x2 = X2[2] + u2[2] - X1[2] - u1[2];
  double l = sqrt(x0 * x0 + x1 * x1 + x2 * x2);
  double a0 = x0 / l, a1 = x1 / l, a2 = x2 / l;
  for (int k = 0; k < 3; ++k)
  {
    p1[k] = R1[k][0] * R0[0][1] + R1[k][1] * R0[1][1] + R1[k][2] * R0[2][1];
    p2[k] = R2[k][0] * R0[0][1] + R2[k][1] * R0[1][1] + R2[k][2] * R0[2][1];
  }
  double q0 = 0.5 * (p1[0] + p2[0]), q1 = 0.5 * (p1[1] + p2[1]), q2 = 0.5 * (p1[2] + p2[2]);
  double c0 = a1 * q2 - a2 * q1;
  double c1 = a2 * q0 - a0 * q2;
  double c2 = a0 * q1 - a1 * q0;
  double nc = sqrt(c0 * c0 + c1 * c1 + c2 * c2);
  c0 = c0 / nc;
  c1 = c1 / nc;
  c2 = c2 / nc;
  Rr[0][0] = a0; Rr[1][0] = a1; Rr[2][0] = a2;
  Rr[0][1] = c1 * a2 - c2 * a1;
  Rr[1][1] = c2 * a0 - c0 * a2;
  Rr[2][1] = c0 * a1 - c1 * a0;
  Rr[0][2] = c0; Rr[1][2] = c1; Rr[2][2] = c2;
  return l;
}

/* B (m, n) = Bl diag(R^T, ...): every 3-column block of Bl times R^T */
static void rotate_columns(const double* Bl, m3 R, double* B, int m, int n)
{
  for (int r = 0; r < m; ++r)
    for (int c0 = 0; c0 < n; c0 += 3)
      for (int j = 0; j < 3; ++j)
        B[r * n + c0 + j] = Bl[r * n + c0] * R[j][0] + Bl[r * n + c0 + 1] * R[j][1] + Bl[r * n + c0 + 2] * R[j][2];
}

/* the basic deformations (returns u-bar; *length = l), B (7, 12), and what the tangent reuses:
   Rr, p1, p2, G^T (3, 12) in local components, T^-1(th_i) */
static double frame_and_basic(const double* X1, const double* X2, const double* u1, const double* u2, m3 R1,
                              m3 R2, m3 R0, double l0, double* th1, double* th2, double B[7][12], m3 Rr,
                              double* p1, double* p2, double GT[3][12], m3 Ti[2], double* length)
{
  double l = current_frame(X1, X2, u1, u2, R1, R2, R0, Rr, p1, p2);
  m3 T, Rb;
  matmul3_tn(Rr, R1, T);
  matmul3(T, R0, Rb);
  log_so3(Rb, th1);
  matmul3_tn(Rr, R2, T);
  matmul3(T, R0, Rb);
  log_so3(Rb, th2);
  double ubar = (l * l - l0 * l0) / (l + l0);
  double q0 = 0.5 * (p1[0] + p2[0]), q1 = 0.5 * (p1[1] + p2[1]), q2 = 0.5 * (p1[2] + p2[2]);
  double pl0 = Rr[0][0] * q0 + Rr[1][0] * q1 + Rr[2][0] * q2;
  double pl1 = Rr[0][1] * q0 + Rr[1][1] * q1 + Rr[2][1] * q2;
  double eta = pl0 / pl1;
  memset(GT, 0, 3 * 12 * sizeof(double));
  GT[0][2] = eta / l;
  GT[0][3] = 0.5 * (Rr[0][1] * p1[0] + Rr[1][1] * p1[1] + Rr[2][1] * p1[2]) / pl1;
  GT[0][4] = -0.5 * (Rr[0][0] * p1[0] + Rr[1][0] * p1[1] + Rr[2][0] * p1[2]) / pl1;
  GT[0][8] = -eta / l;
  GT[0][9] = 0.5 * (Rr[0][1] * p2[0] + Rr[1][1] * p2[1] + Rr[2][1] * p2[2]) / pl1;
  GT[0][10] = -0.5 * (Rr[0][0] * p2[0] + Rr[1][0] * p2[1] + Rr[2][0] * p2[2]) / pl1;
  GT[1][2] = 1.0 / l;
  GT[1][8] = -1.0 / l;
  GT[2][1] = -1.0 / l;
  GT[2][7] = 1.0 / l;
  double Bl[7][12];
  memset(Bl, 0, sizeof(Bl));
  Bl[0][0] = -1.0;
  Bl[0][6] = 1.0;
  for (int i = 0; i < 2; ++i)
  {
    tangent_inv_so3(i == 0 ? th1 : th2, Ti[i]);
    for (int r = 0; r < 3; ++r)
    {
      for (int c = 0; c < 12; ++c)
        Bl[1 + 3 * i + r][c] = -(Ti[i][r][0] * GT[0][c] + Ti[i][r][1] * GT[1][c] + Ti[i][r][2] * GT[2][c]);
      for (int k = 0; k < 3; ++k)
        Bl[1 + 3 * i + r][3 + 6 * i + k] += Ti[i][r][k];
    }
  }
  rotate_columns(&Bl[0][0], Rr, &B[0][0], 7, 12);
  *length = l;
  return ubar;
}

/* out (12) = grad(a . b) = a^T grad b + b^T grad a */
static void grad_dot(const double* a, double da[3][12], const double* b, double db[3][12], double* out)
{
  for (int j = 0; j < 12; ++j)
    out[j] = (a[0] * db[0][j] + a[1] * db[1][j] + a[2] * db[2][j] + b[0] * da[0][j] + b[1] * da[1][j]
              + b[2] * da[2][j]);
}

/* K += dB^T/dd : f-bar, the geometric part of the consistent tangent (frame3d.add_geometric_stiffness) */
static void add_geometric_stiffness(double l, m3 Rr, const double* p1, const double* p2, double GT[3][12],
                                    m3 Ti[2], const double* th1, const double* th2, double B[7][12],
                                    const double* fbar, double* K)
{
  double m[2][3], ms[3], fl[12], Om[3][12], Wg[3][12], HBs[3][12], Z[12][12], Hi[3][3];
  double e1[3], e2[3], de1[3][12], de2[3][12], dp1[3][12], dp2[3][12], p[3], dp[3][12];
  double dP[12], dQ[12], dinvl[12], ds[12], dt_[12];
  memset(HBs, 0, sizeof(HBs));
  memset(Z, 0, sizeof(Z));
  memset(dp1, 0, sizeof(dp1));
  memset(dp2, 0, sizeof(dp2));
  memset(dinvl, 0, sizeof(dinvl));
  for (int i = 0; i < 2; ++i)
    for (int r = 0; r < 3; ++r)
      m[i][r] = Ti[i][0][r] * fbar[1 + 3 * i] + Ti[i][1][r] * fbar[2 + 3 * i] + Ti[i][2][r] * fbar[3 + 3 * i];
  for (int r = 0; r < 3; ++r)
    ms[r] = m[0][r] + m[1][r];
  for (int c = 0; c < 12; ++c)
    fl[c] = -(GT[0][c] * ms[0] + GT[1][c] * ms[1] + GT[2][c] * ms[2]);
  for (int k = 0; k < 3; ++k)
  {
    fl[3 + k] += m[0][k];
    fl[9 + k] += m[1][k];
  }
  rotate_columns(&GT[0][0], Rr, &Om[0][0], 3, 12);
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 12; ++j)
      Wg[k][j] = Rr[k][0] * Om[0][j] + Rr[k][1] * Om[1][j] + Rr[k][2] * Om[2][j];
  /* K_h: (S_i^T - G) H_i B_theta_i */
  for (int i = 0; i < 2; ++i)
  {
    tangent_inv_so3_derivative(i == 0 ? th1 : th2, fbar + 1 + 3 * i, Hi);
    for (int r = 0; r < 3; ++r)
      for (int j = 0; j < 12; ++j)
      {
        double v = Hi[r][0] * B[1 + 3 * i][j] + Hi[r][1] * B[2 + 3 * i][j] + Hi[r][2] * B[3 + 3 * i][j];
        Z[3 + 6 * i + r][j] += v;
        HBs[r][j] += v;
      }
  }
  for (int c = 0; c < 12; ++c)
  {
    double g0 = GT[0][c], g1 = GT[1][c], g2 = GT[2][c];
    if (g0 != 0.0 || g1 != 0.0 || g2 != 0.0)
      for (int j = 0; j < 12; ++j)
        Z[c][j] -= g0 * HBs[0][j] + g1 * HBs[1][j] + g2 * HBs[2][j];
  }
  /* delta E f_l = -S(f_l) Omega */
  for (int b = 0; b < 4; ++b)
  {
    double g0 = fl[3 * b], g1 = fl[3 * b + 1], g2 = fl[3 * b + 2];
    for (int col = 0; col < 12; ++col)
    {
      double o0 = Om[0][col], o1 = Om[1][col], o2 = Om[2][col];
      Z[3 * b + 0][col] -= g1 * o2 - g2 * o1;
      Z[3 * b + 1][col] -= g2 * o0 - g0 * o2;
      Z[3 * b + 2][col] -= g0 * o1 - g1 * o0;
    }
  }
  /* -delta G m: gradients of e1, e2 (omega x e_k), p_i (delta w_i x p_i), l */
  for (int k = 0; k < 3; ++k)
  {
    e1[k] = Rr[k][0];
    e2[k] = Rr[k][1];
  }
  for (int j = 0; j < 12; ++j)
  {
    de1[0][j] = Wg[1][j] * e1[2] - Wg[2][j] * e1[1];
    de1[1][j] = Wg[2][j] * e1[0] - Wg[0][j] * e1[2];
    de1[2][j] = Wg[0][j] * e1[1] - Wg[1][j] * e1[0];
    de2[0][j] = Wg[1][j] * e2[2] - Wg[2][j] * e2[1];
    de2[1][j] = Wg[2][j] * e2[0] - Wg[0][j] * e2[2];
    de2[2][j] = Wg[0][j] * e2[1] - Wg[1][j] * e2[0];
  }
  for (int i = 0; i < 2; ++i)
  {
    const double* pi = i == 0 ? p1 : p2;
    double (*dpi)[12] = i == 0 ? dp1 : dp2;
    int c0 = i == 0 ? 3 : 9;
    dpi[1][c0] = -pi[2];
    dpi[2][c0] = pi[1];
    dpi[0][c0 + 1] = pi[2];
    dpi[2][c0 + 1] = -pi[0];
    dpi[0][c0 + 2] = -pi[1];
    dpi[1][c0 + 2] = pi[0];
  }
  for (int k = 0; k < 3; ++k)
  {
    p[k] = 0.5 * (p1[k] + p2[k]);
    for (int j = 0; j < 12; ++j)
      dp[k][j] = 0.5 * (dp1[k][j] + dp2[k][j]);
  }
  double P = dot3(p, e2);
  double Q = dot3(p, e1);
  grad_dot(p, dp, e2, de2, dP);
  grad_dot(p, dp, e1, de1, dQ);
  for (int k = 0; k < 3; ++k)
  {
    dinvl[k] = e1[k] / (l * l);
    dinvl[6 + k] = -e1[k] / (l * l);
  }
  for (int j = 0; j < 12; ++j)
  {
    double da0 = dQ[j] / (P * l) - Q / (P * P * l) * dP[j] + Q / P * dinvl[j];
    double row2 = ms[0] * da0 + ms[1] * dinvl[j];
    Z[2][j] -= row2;
    Z[8][j] += row2;
    Z[1][j] += ms[2] * dinvl[j];
    Z[7][j] -= ms[2] * dinvl[j];
  }
  for (int i = 0; i < 2; ++i)
  {
    const double* pi = i == 0 ? p1 : p2;
    double (*dpi)[12] = i == 0 ? dp1 : dp2;
    int c0 = i == 0 ? 3 : 9;
    double s = dot3(pi, e2);
    double t = dot3(pi, e1);
    grad_dot(pi, dpi, e2, de2, ds);
    grad_dot(pi, dpi, e1, de1, dt_);
    for (int j = 0; j < 12; ++j)
    {
      Z[c0][j] -= ms[0] * (0.5 * ds[j] / P - 0.5 * s / (P * P) * dP[j]);
      Z[c0 + 1][j] -= ms[0] * (-0.5 * dt_[j] / P + 0.5 * t / (P * P) * dP[j]);
    }
  }
  for (int b = 0; b < 4; ++b)
    for (int k = 0; k < 3; ++k)
      for (int j = 0; j < 12; ++j)
        K[(3 * b + k) * 12 + j] += Rr[k][0] * Z[3 * b][j] + Rr[k][1] * Z[3 * b + 1][j] + Rr[k][2] * Z[3 * b + 2][j];
  double N = fbar[0];
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 12; ++j)
    {
      K[k * 12 + j] -= N * de1[k][j];
      K[(6 + k) * 12 + j] += N * de1[k][j];
    }
}

/* -- the law in the element frame (elements.beam3d) ------------------------------------------- */

static void basic_force(double l0, double ubar, const double* th1, const double* th2, const double* props,
                        double* fbar)
{
  double ea = props[P_EA], gj = props[P_GJ], eiy = props[P_EIY], eiz = props[P_EIZ];
  int bending = eiy > 0.0 || eiz > 0.0;
  double eps = ubar / l0;
  if (bending)
    eps = eps + (2.0 * th1[1] * th1[1] - th1[1] * th2[1] + 2.0 * th2[1] * th2[1] + 2.0 * th1[2] * th1[2]
                 - th1[2] * th2[2] + 2.0 * th2[2] * th2[2]) / 30.0;
  double n = ea * eps + props[P_N0];
  fbar[0] = n;
  double t = gj / l0 * (th2[0] - th1[0]);
  fbar[1] = -t;
  fbar[4] = t;
  for (int a = 1; a <= 2; ++a)
  {
    double ei = a == 1 ? eiy : eiz;
    double gas = a == 1 ? props[P_GAZ] : props[P_GAY];
    double phi = gas > 0.0 ? 12.0 * ei / (gas * l0 * l0) : 0.0;
    double k = ei / (l0 * (1.0 + phi));
    double kd = k * (4.0 + phi);
    double ko = k * (2.0 - phi);
    fbar[1 + a] = kd * th1[a] + ko * th2[a];
    fbar[4 + a] = ko * th1[a] + kd * th2[a];
    if (bending)
    {
      fbar[1 + a] += n * l0 * (4.0 * th1[a] - th2[a]) / 30.0;
      fbar[4 + a] += n * l0 * (4.0 * th2[a] - th1[a]) / 30.0;
    }
  }
}

static void basic_stiffness_linear(double l0, const double* props, double kbar[7][7])
{
  memset(kbar, 0, 49 * sizeof(double));
  kbar[0][0] = props[P_EA] / l0;
  double g = props[P_GJ] / l0;
  kbar[1][1] = g;
  kbar[4][4] = g;
  kbar[1][4] = -g;
  kbar[4][1] = -g;
  for (int a = 1; a <= 2; ++a)
  {
    double ei = a == 1 ? props[P_EIY] : props[P_EIZ];
    double gas = a == 1 ? props[P_GAZ] : props[P_GAY];
    double phi = gas > 0.0 ? 12.0 * ei / (gas * l0 * l0) : 0.0;
    double k = ei / (l0 * (1.0 + phi));
    kbar[1 + a][1 + a] = k * (4.0 + phi);
    kbar[4 + a][4 + a] = k * (4.0 + phi);
    kbar[1 + a][4 + a] = k * (2.0 - phi);
    kbar[4 + a][1 + a] = k * (2.0 - phi);
  }
}

static void basic_stiffness(double l0, double ubar, const double* th1, const double* th2, const double* props,
                            double kbar[7][7])
{
  basic_stiffness_linear(l0, props, kbar);
  double ea = props[P_EA], eiy = props[P_EIY], eiz = props[P_EIZ];
  if (!(eiy > 0.0 || eiz > 0.0))
    return;
  double g[7] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  g[0] = 1.0 / l0;
  double eps = ubar / l0;
  for (int a = 1; a <= 2; ++a)
  {
    g[1 + a] = (4.0 * th1[a] - th2[a]) / 30.0;
    g[4 + a] = (4.0 * th2[a] - th1[a]) / 30.0;
    eps += (2.0 * th1[a] * th1[a] - th1[a] * th2[a] + 2.0 * th2[a] * th2[a]) / 30.0;
  }
  double n = ea * eps + props[P_N0];
  kbar[0][0] = 0.0;
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 7; ++j)
      kbar[i][j] += ea * l0 * g[i] * g[j];
  for (int a = 1; a <= 2; ++a)
  {
    kbar[1 + a][1 + a] += n * l0 * 4.0 / 30.0;
    kbar[4 + a][4 + a] += n * l0 * 4.0 / 30.0;
    kbar[1 + a][4 + a] -= n * l0 / 30.0;
    kbar[4 + a][1 + a] -= n * l0 / 30.0;
  }
}

/* -- between the frame and the global axes (corotation.transform) ----------------------------- */

static void force(double B[7][12], const double* fbar, double* f)
{
  for (int i = 0; i < 12; ++i)
  {
    double acc = B[0][i] * fbar[0];
    for (int r = 1; r < 7; ++r)
      acc += B[r][i] * fbar[r];
    f[i] = acc;
  }
}

static void stiffness(double B[7][12], double kbar[7][7], double* K)
{
  double KB[7][12];
  for (int r = 0; r < 7; ++r)
    for (int j = 0; j < 12; ++j)
    {
      double acc = kbar[r][0] * B[0][j];
      for (int s = 1; s < 7; ++s)
        acc += kbar[r][s] * B[s][j];
      KB[r][j] = acc;
    }
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
    {
      double acc = B[0][i] * KB[0][j];
      for (int r = 1; r < 7; ++r)
        acc += B[r][i] * KB[r][j];
      K[i * 12 + j] = acc;
    }
}

/* -- the element ------------------------------------------------------------------------------ */

static void nodal_states(const double* S, double u[2][3], m3 R[2])
{
  for (int a = 0; a < 2; ++a)
  {
    for (int k = 0; k < 3; ++k)
      u[a][k] = S[NSTATE * a + k];
    quat_to_matrix(S + NSTATE * a + 3, R[a]);
  }
}

static void corotational(const double* X, const double* S, const double* props, double* f, double* K, int tangent)
{
  m3 R0, Rr, R[2], Ti[2];
  double u[2][3], th1[3], th2[3], p1[3], p2[3], B[7][12], GT[3][12], fbar[7], kbar[7][7], l;
  double l0 = initial_frame(X, X + 3, props + P_VX, R0);
  nodal_states(S, u, R);
  double ubar = frame_and_basic(X, X + 3, u[0], u[1], R[0], R[1], R0, l0, th1, th2, B, Rr, p1, p2, GT, Ti, &l);
  basic_force(l0, ubar, th1, th2, props, fbar);
  force(B, fbar, f);
  if (!tangent)
    return;
  basic_stiffness(l0, ubar, th1, th2, props, kbar);
  stiffness(B, kbar, K);
  add_geometric_stiffness(l, Rr, p1, p2, GT, Ti, th1, th2, B, fbar, K);
}

static void linear(const double* X, const double* S, const double* props, double* f, double* K)
{
  m3 R0, I3 = {{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}, Rr, Ti[2];
  double zero[3] = {0.0, 0.0, 0.0}, th1[3], th2[3], p1[3], p2[3], B[7][12], GT[3][12], kbar[7][7], d[12], l;
  double l0 = initial_frame(X, X + 3, props + P_VX, R0);
  frame_and_basic(X, X + 3, zero, zero, I3, I3, R0, l0, th1, th2, B, Rr, p1, p2, GT, Ti, &l);
  basic_stiffness_linear(l0, props, kbar);
  stiffness(B, kbar, K);
  for (int a = 0; a < 2; ++a)
  {
    m3 Ra;
    for (int k = 0; k < 3; ++k)
      d[6 * a + k] = S[NSTATE * a + k];
    quat_to_matrix(S + NSTATE * a + 3, Ra);
    log_so3(Ra, d + 6 * a + 3);
  }
  for (int i = 0; i < 12; ++i)
  {
    double acc = 0.0;
    for (int j = 0; j < 12; ++j)
      acc += K[i * 12 + j] * d[j];
    f[i] = acc + B[0][i] * props[P_N0];
  }
}

/* w = [state node 1 (7), state node 2 (7), props (10)], c[0]: 0 linear, 1 co-rotational,
   2 co-rotational with the symmetric part of the tangent */
static void tabulate(const double* w, const double* c, const double* X, double* f, double* K, int tangent)
{
  if (c[0] != 0.0)
    corotational(X, w, w + 2 * NSTATE, f, K, tangent);
  else
    linear(X, w, w + 2 * NSTATE, f, K);
  if (tangent && c[0] == 2.0)
    for (int i = 0; i < 12; ++i)
      for (int j = i + 1; j < 12; ++j)
      {
        double s = 0.5 * (K[i * 12 + j] + K[j * 12 + i]);
        K[i * 12 + j] = s;
        K[j * 12 + i] = s;
      }
}

void beam3d_vector(double* A, const double* w, const double* c, const double* coordinate_dofs,
                   const int* entity_local_index, const uint8_t* quadrature_permutation)
{
  double K[144];
  tabulate(w, c, coordinate_dofs, A, K, 0);
}

void beam3d_matrix(double* A, const double* w, const double* c, const double* coordinate_dofs,
                   const int* entity_local_index, const uint8_t* quadrature_permutation)
{
  double f[12];
  tabulate(w, c, coordinate_dofs, f, A, 1);
}

/* out (n, 2, 6): the section forces (N, Vy, Vz, T, My, Mz) at both ends of every element, in its
   current axes (the initial ones if !large_rotations): -R^T f1 at end 1, +R^T f2 at end 2 of the
   nodal forces f; axes (n, 3, 3): rows e1, e2, e3 (kernels.beam3d.section_forces_all) */
void beam3d_section_forces_all(int64_t n, const double* X, const double* S, const double* props,
                               int64_t large_rotations, double* out, double* axes)
{
  const double c = large_rotations ? 1.0 : 0.0;
  for (int64_t e = 0; e < n; ++e)
  {
    const double* Xe = X + 6 * e;
    const double* Se = S + 2 * NSTATE * e;
    const double* pe = props + NPROPS * e;
    double w[2 * NSTATE + NPROPS], f[12], K[144];
    memcpy(w, Se, 2 * NSTATE * sizeof(double));
    memcpy(w + 2 * NSTATE, pe, NPROPS * sizeof(double));
    tabulate(w, &c, Xe, f, K, 0);
    m3 R0, Rr;
    initial_frame(Xe, Xe + 3, pe + P_VX, R0);
    memcpy(Rr, R0, sizeof(m3));
    if (large_rotations)
    {
      double u[2][3], p1[3], p2[3];
      m3 R[2];
      nodal_states(Se, u, R);
      current_frame(Xe, Xe + 3, u[0], u[1], R[0], R[1], R0, Rr, p1, p2);
    }
    double* oe = out + 12 * e;
    for (int a = 0; a < 2; ++a)
    {
      double sign = a == 0 ? -1.0 : 1.0;
      for (int i = 0; i < 3; ++i)
      {
        double F = 0.0, M = 0.0;
        for (int k = 0; k < 3; ++k)
        {
          F += Rr[k][i] * f[6 * a + k];
          M += Rr[k][i] * f[6 * a + 3 + k];
        }
        oe[6 * a + i] = sign * F;
        oe[6 * a + 3 + i] = sign * M;
      }
    }
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        axes[9 * e + 3 * i + j] = Rr[j][i];
  }
}

/* -- nodal rotations (rotations.quat_update, rotvec_from_quat) -------------------------------- */

/* state (n, 7) <- (u + du, exp(dw) q) for the first n nodes; dx (n, 6) */
void update_quaternions(int64_t n, double* state, const double* dx)
{
  for (int64_t i = 0; i < n; ++i)
  {
    double* s = state + NSTATE * i;
    const double* d = dx + 6 * i;
    for (int k = 0; k < 3; ++k)
      s[k] += d[k];
    const double* w = d + 3;
    double t = sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
    double h = 0.5 * t, f;
    if (t < 1e-3)
    {
      double t2 = t * t;
      f = 0.5 - t2 / 48.0 + t2 * t2 / 3840.0;
    }
    else
      f = sin(h) / t;
    double p[4] = {cos(h), f * w[0], f * w[1], f * w[2]};
    const double* q = s + 3;
    double r[4];
    r[0] = p[0] * q[0] - p[1] * q[1] - p[2] * q[2] - p[3] * q[3];
    r[1] = p[0] * q[1] + p[1] * q[0] + p[2] * q[3] - p[3] * q[2];
    r[2] = p[0] * q[2] - p[1] * q[3] + p[2] * q[0] + p[3] * q[1];
    r[3] = p[0] * q[3] + p[1] * q[2] - p[2] * q[1] + p[3] * q[0];
    double norm = sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
    for (int k = 0; k < 4; ++k)
      s[3 + k] = r[k] / norm;
  }
}

/* out (n, 3): the rotation vectors (norm in [0, pi]) of the unit quaternions Q (n, 4) */
void rotvecs_from_quats(int64_t n, const double* Q, double* out)
{
  for (int64_t i = 0; i < n; ++i)
  {
    const double* q = Q + 4 * i;
    if (q[0] < 0.0)
      rotation_vector(-q[0], -q[1], -q[2], -q[3], out + 3 * i);
    else
      rotation_vector(q[0], q[1], q[2], q[3], out + 3 * i);
  }
}
