#include "plant/expm.h"

#include <math.h>
#include <stddef.h>
#include <string.h>

/* [13/13] Pade coefficients b_k = (26-k)! 13! / (26! k! (13-k)!) scaled by 26!/13!
 * (Higham 2005, table 2.3 numerators). */
static const double kPade13[14] = {64764752532480000.0,
                                   32382376266240000.0,
                                   7771770303897600.0,
                                   1187353796428800.0,
                                   129060195264000.0,
                                   10559470521600.0,
                                   670442572800.0,
                                   33522128640.0,
                                   1323241920.0,
                                   40840800.0,
                                   960960.0,
                                   16380.0,
                                   182.0,
                                   1.0};
static const double kTheta13 = 5.371920351148152;

static void matmul(int n, const double *a, const double *b, double *c)
{
  for (int i = 0; i < n; i++) {
    double *ci = c + i * n;
    for (int j = 0; j < n; j++) ci[j] = 0.0;
    for (int k = 0; k < n; k++) {
      const double aik = a[i * n + k];
      if (aik == 0.0) continue; /* the plant's block matrices are mostly zero */
      const double *bk = b + k * n;
      for (int j = 0; j < n; j++) ci[j] += aik * bk[j];
    }
  }
}

static double norm1(int n, const double *a)
{
  double best = 0.0;
  for (int j = 0; j < n; j++) {
    double s = 0.0;
    for (int i = 0; i < n; i++) s += fabs(a[i * n + j]);
    if (s > best) best = s;
  }
  return best;
}

/* Solve M X = R in place (M overwritten by its LU factors, R by X). */
static int lu_solve(int n, double *m, double *r)
{
  for (int k = 0; k < n; k++) {
    int p = k;
    double big = fabs(m[k * n + k]);
    for (int i = k + 1; i < n; i++) {
      const double v = fabs(m[i * n + k]);
      if (v > big) {
        big = v;
        p = i;
      }
    }
    if (!(big > 0.0)) return -2;
    if (p != k) {
      for (int j = 0; j < n; j++) {
        double t = m[k * n + j];
        m[k * n + j] = m[p * n + j];
        m[p * n + j] = t;
        t = r[k * n + j];
        r[k * n + j] = r[p * n + j];
        r[p * n + j] = t;
      }
    }
    const double inv = 1.0 / m[k * n + k];
    for (int i = k + 1; i < n; i++) {
      const double f = m[i * n + k] * inv;
      if (f == 0.0) continue;
      m[i * n + k] = f;
      for (int j = k + 1; j < n; j++) m[i * n + j] -= f * m[k * n + j];
      for (int j = 0; j < n; j++) r[i * n + j] -= f * r[k * n + j];
    }
  }
  for (int k = n - 1; k >= 0; k--) {
    const double inv = 1.0 / m[k * n + k];
    for (int j = 0; j < n; j++) {
      double s = r[k * n + j];
      for (int i = k + 1; i < n; i++) s -= m[k * n + i] * r[i * n + j];
      r[k * n + j] = s * inv;
    }
  }
  return 0;
}

int expm(int n, const double *a, double *e)
{
  if (n < 1 || n > EXPM_MAX_N || a == NULL || e == NULL) return -1;
  const int nn = n * n;
  for (int i = 0; i < nn; i++)
    if (!isfinite(a[i])) return -1;

  /* six n x n slots, reused as the terms are consumed (same operations, in the same
   * order, as the textbook layout with seven) */
  double m[6][EXPM_MAX_N * EXPM_MAX_N];
  double *b = m[0], *b2 = m[1], *b4 = m[2], *b6 = m[3], *t = m[4], *v = m[5];

  const double nrm = norm1(n, a);
  if (!isfinite(nrm)) return -1; /* finite entries, but beyond any scaling */
  int s = 0;
  if (nrm > kTheta13) s = (int)ceil(log2(nrm / kTheta13));
  const double scale = ldexp(1.0, -s);
  for (int i = 0; i < nn; i++) b[i] = a[i] * scale;

  matmul(n, b, b, b2);
  matmul(n, b2, b2, b4);
  matmul(n, b4, b2, b6);

  const double *c = kPade13;
  /* V = B6 (b12 B6 + b10 B4 + b8 B2) + b6 B6 + b4 B4 + b2 B2 + b0 I */
  for (int i = 0; i < nn; i++) t[i] = c[12] * b6[i] + c[10] * b4[i] + c[8] * b2[i];
  matmul(n, b6, t, v);
  for (int i = 0; i < nn; i++) v[i] += c[6] * b6[i] + c[4] * b4[i] + c[2] * b2[i];
  for (int i = 0; i < n; i++) v[i * n + i] += c[0];
  /* U = B [B6 (b13 B6 + b11 B4 + b9 B2) + b7 B6 + b5 B4 + b3 B2 + b1 I]: the bracket
   * is built in b4, the low-order sum kept in b2, U lands in t */
  for (int i = 0; i < nn; i++) t[i] = c[13] * b6[i] + c[11] * b4[i] + c[9] * b2[i];
  for (int i = 0; i < nn; i++) b2[i] = c[7] * b6[i] + c[5] * b4[i] + c[3] * b2[i];
  matmul(n, b6, t, b4);
  for (int i = 0; i < nn; i++) b4[i] += b2[i];
  for (int i = 0; i < n; i++) b4[i * n + i] += c[1];
  matmul(n, b, b4, t);

  /* (V - U) X = (V + U): denominator into b2, numerator into b4. */
  for (int i = 0; i < nn; i++) {
    b2[i] = v[i] - t[i];
    b4[i] = v[i] + t[i];
  }
  const int rc = lu_solve(n, b2, b4);
  if (rc != 0) return rc;

  double *cur = b4, *nxt = b6;
  for (int k = 0; k < s; k++) {
    matmul(n, cur, cur, nxt);
    double *tmp = cur;
    cur = nxt;
    nxt = tmp;
  }
  memcpy(e, cur, (size_t)nn * sizeof(double));
  return 0;
}
