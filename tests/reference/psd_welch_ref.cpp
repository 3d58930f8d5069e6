#include "psd_welch_ref.h"

#include <cmath>
#include <complex>
#include <vector>

#include <unsupported/Eigen/FFT>

extern "C" size_t ref_psd_welch(const double *x, size_t n, double fs_hz, size_t nseg, double *psd)
{
  if (nseg < 8 || n < nseg) return 0;
  const double pi = 3.14159265358979323846;
  std::vector<double> w(nseg);
  double wss = 0.0;
  for (size_t i = 0; i < nseg; i++) {
    w[i] = 0.5 - 0.5 * std::cos(2.0 * pi * (double)i / (double)nseg); /* periodic Hann */
    wss += w[i] * w[i];
  }
  const size_t nb = nseg / 2 + 1;
  for (size_t i = 0; i < nb; i++) psd[i] = 0.0;
  Eigen::FFT<double> fft;
  std::vector<double> seg(nseg);
  std::vector<std::complex<double>> spec;
  size_t count = 0;
  for (size_t start = 0; start + nseg <= n; start += nseg / 2) {
    double mean = 0.0;
    for (size_t i = 0; i < nseg; i++) mean += x[start + i];
    mean /= (double)nseg;
    for (size_t i = 0; i < nseg; i++) seg[i] = (x[start + i] - mean) * w[i];
    fft.fwd(spec, seg);
    for (size_t i = 0; i < nb; i++) psd[i] += std::norm(spec[i]);
    count++;
  }
  const double scale = 1.0 / (fs_hz * wss * (double)count);
  for (size_t i = 0; i < nb; i++) {
    const double one_sided = (i == 0 || i == nseg / 2) ? 1.0 : 2.0;
    psd[i] *= scale * one_sided;
  }
  return count;
}
