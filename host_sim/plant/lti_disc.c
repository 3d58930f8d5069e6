#include "plant/lti_disc.h"

#include <math.h>
#include <string.h>

void lti_matmul(int n, const double *a, const double *b, double *c)
{
  for (int i = 0; i < n; i++) {
    for (int j = 0; j < n; j++) {
      double s = 0.0;
      for (int k = 0; k < n; k++) s += a[i * n + k] * b[k * n + j];
      c[i * n + j] = s;
    }
  }
}

int lti_expm(int n, const double *a, double *e)
{
  if (n < 1 || n > LTI_MAX_N) return -1;
  double norm = 0.0; /* 1-norm: largest column sum */
  for (int j = 0; j < n; j++) {
    double col = 0.0;
    for (int i = 0; i < n; i++) {
      const double v = a[i * n + j];
      if (!isfinite(v)) return -1;
      col += fabs(v);
    }
    if (col > norm) norm = col;
  }
  int s = 0;
  double scale = 1.0;
  while (norm * scale > 0.5) {
    scale *= 0.5;
    s++;
    if (s > 1000) return -1;
  }
  double b[LTI_MAX_N * LTI_MAX_N], term[LTI_MAX_N * LTI_MAX_N], tmp[LTI_MAX_N * LTI_MAX_N];
  double sum[LTI_MAX_N * LTI_MAX_N];
  const int nn = n * n;
  for (int i = 0; i < nn; i++) b[i] = a[i] * scale;
  memset(sum, 0, sizeof(double) * (size_t)nn);
  memset(term, 0, sizeof(double) * (size_t)nn);
  for (int i = 0; i < n; i++) {
    sum[i * n + i] = 1.0;
    term[i * n + i] = 1.0;
  }
  for (int k = 1; k <= 18; k++) {
    lti_matmul(n, term, b, tmp);
    const double inv_k = 1.0 / (double)k;
    for (int i = 0; i < nn; i++) {
      term[i] = tmp[i] * inv_k;
      sum[i] += term[i];
    }
  }
  for (int q = 0; q < s; q++) {
    lti_matmul(n, sum, sum, tmp);
    memcpy(sum, tmp, sizeof(double) * (size_t)nn);
  }
  memcpy(e, sum, sizeof(double) * (size_t)nn);
  return 0;
}
