#include "matexp_ref.h"

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

extern "C" int ref_matexp(int n, const double *a, double *e)
{
  if (n < 1) return -1;
  Eigen::MatrixXd m(n, n);
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) m(i, j) = a[i * n + j];
  const Eigen::MatrixXd r = m.exp();
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) e[i * n + j] = r(i, j);
  return 0;
}
