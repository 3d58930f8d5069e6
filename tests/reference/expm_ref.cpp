/* Eigen at -O0 (the Debug preset) is ~30x slower than optimised; the reference is
 * only ever used as a reference, so optimise this file in every build type. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("O2")
#endif

#include "expm_ref.h"

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

/* Bounded dynamic sizes: storage on the stack, no heap traffic per call. */
using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, 64, 64>;
using SmallMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor, 40, 40>;

extern "C" int expm_ref(int n, const double *a, double *e)
{
  if (n < 1 || n > 64) return -1;
  const Eigen::Map<const Mat> am(a, n, n);
  const Mat em = am.exp();
  Eigen::Map<Mat>(e, n, n) = em;
  return 0;
}

extern "C" int expm_ref_zoh_step(int n, int m, const double *a, const double *b,
                                 const double *u, double dt, double *x)
{
  if (n < 1 || n > 32 || m < 0 || m > 8) return -1;
  const int na = n + m;
  SmallMat aug = SmallMat::Zero(na, na);
  for (int i = 0; i < n; i++) {
    for (int j = 0; j < n; j++) aug(i, j) = a[i * n + j] * dt;
    for (int j = 0; j < m; j++) aug(i, n + j) = b[i * m + j] * dt;
  }
  const SmallMat e = aug.exp();
  double nx[32];
  for (int i = 0; i < n; i++) {
    double s = 0.0;
    for (int j = 0; j < n; j++) s += e(i, j) * x[j];
    for (int j = 0; j < m; j++) s += e(i, n + j) * u[j];
    nx[i] = s;
  }
  for (int i = 0; i < n; i++) x[i] = nx[i];
  return 0;
}
