#include "iir_ref.h"

#include <complex>
#include <vector>

#include <Eigen/Dense>

extern "C" void iir_ref_sos_filter(const double *sos, size_t n_sections, const double *x,
                                   double *y, size_t n)
{
  // Direct form I per section: keeps its own input and output history.
  std::vector<long double> xh(2 * n_sections, 0.0L), yh(2 * n_sections, 0.0L);
  for (size_t i = 0; i < n; i++) {
    long double v = x[i];
    for (size_t s = 0; s < n_sections; s++) {
      const double *c = &sos[6 * s];
      long double *xs = &xh[2 * s], *ys = &yh[2 * s];
      const long double out = (c[0] * v + c[1] * xs[0] + c[2] * xs[1] - c[4] * ys[0] -
                               c[5] * ys[1]) /
                              c[3];
      xs[1] = xs[0];
      xs[0] = v;
      ys[1] = ys[0];
      ys[0] = out;
      v = out;
    }
    y[i] = static_cast<double>(v);
  }
}

extern "C" void iir_ref_sos_freqresp(const double *sos, size_t n_sections, double f_hz,
                                     double fs_hz, double *re, double *im)
{
  const std::complex<long double> zi = std::polar(
      1.0L, -2.0L * 3.141592653589793238462643383279L * f_hz / fs_hz);
  std::complex<long double> h = 1.0L;
  for (size_t s = 0; s < n_sections; s++) {
    const double *c = &sos[6 * s];
    const std::complex<long double> num = (long double)c[0] +
                                          zi * ((long double)c[1] + zi * (long double)c[2]);
    const std::complex<long double> den = (long double)c[3] +
                                          zi * ((long double)c[4] + zi * (long double)c[5]);
    h *= num / den;
  }
  *re = static_cast<double>(h.real());
  *im = static_cast<double>(h.imag());
}

extern "C" int iir_ref_poly_roots(const double *c, size_t order, double *re, double *im)
{
  if (order == 0 || c[0] == 0.0) {
    return -1;
  }
  const Eigen::Index n = static_cast<Eigen::Index>(order);
  Eigen::MatrixXd comp = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; j++) {
    comp(0, j) = -c[j + 1] / c[0];
  }
  for (Eigen::Index i = 1; i < n; i++) {
    comp(i, i - 1) = 1.0;
  }
  Eigen::EigenSolver<Eigen::MatrixXd> es(comp, false);
  const Eigen::VectorXcd ev = es.eigenvalues();
  for (Eigen::Index i = 0; i < n; i++) {
    re[i] = ev(i).real();
    im[i] = ev(i).imag();
  }
  return static_cast<int>(order);
}
