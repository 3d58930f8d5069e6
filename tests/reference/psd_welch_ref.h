/* Welch power spectral density (Eigen FFT, double precision) as an independent
 * reference for the plant's noise tests. Host only. */
#ifndef PSD_WELCH_REF_H
#define PSD_WELCH_REF_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* One-sided PSD (unit^2/Hz) of x[0..n) by averaged periodograms: segments of nseg
 * samples (a power of two is fastest), Hann window, 50 % overlap, segment mean removed.
 * psd must hold nseg/2 + 1 values; bin i is at i * fs / nseg. Returns the number of
 * segments averaged, or 0 if n < nseg or nseg < 8. */
size_t ref_psd_welch(const double *x, size_t n, double fs_hz, size_t nseg, double *psd);

#ifdef __cplusplus
}
#endif

#endif /* PSD_WELCH_REF_H */
