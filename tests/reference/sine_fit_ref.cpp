#include "sine_fit_ref.h"

#include <cmath>

#include <Eigen/Dense>

extern "C" double ref_sine_fit(const double *y, size_t n, double t0_s, double dt_s,
                               const double *f_hz, size_t nf, double *coef)
{
  if (nf < 1 || n < 1 + 2 * nf) return -1.0;
  const double pi = 3.14159265358979323846;
  const Eigen::Index cols = (Eigen::Index)(1 + 2 * nf);
  Eigen::MatrixXd a((Eigen::Index)n, cols);
  Eigen::VectorXd b((Eigen::Index)n);
  for (size_t k = 0; k < n; k++) {
    const double t = t0_s + (double)k * dt_s;
    a((Eigen::Index)k, 0) = 1.0;
    for (size_t i = 0; i < nf; i++) {
      const double ph = 2.0 * pi * f_hz[i] * t;
      a((Eigen::Index)k, (Eigen::Index)(1 + 2 * i)) = std::cos(ph);
      a((Eigen::Index)k, (Eigen::Index)(2 + 2 * i)) = std::sin(ph);
    }
    b((Eigen::Index)k) = y[k];
  }
  const Eigen::VectorXd x = a.colPivHouseholderQr().solve(b);
  for (Eigen::Index i = 0; i < cols; i++) coef[i] = x(i);
  const Eigen::VectorXd r = a * x - b;
  return std::sqrt(r.squaredNorm() / (double)n);
}
