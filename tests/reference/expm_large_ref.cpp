/* Eigen at -O0 (the Debug preset) is ~30x slower than optimised; the reference is
 * only ever used as a reference, so optimise this file in every build type. */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("O2")
#endif

#include "expm_large_ref.h"

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

using DynMat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

extern "C" int expm_large_ref(int n, const double *a, double *e)
{
  if (n < 1 || n > 256) return -1;
  const Eigen::Map<const DynMat> am(a, n, n);
  const DynMat em = am.exp();
  Eigen::Map<DynMat>(e, n, n) = em;
  return 0;
}
