"""Characterisation and calibration analysis of the digital MEMS gyroscope (thesis ch. 7).

Modules
-------
csvlog          reader/validator of gyro-sim and `gyroctl log` CSV logs and sweep CSVs
allan           overlapping Allan deviation (allantools, rate as frequency data), N, B, K
psd             Welch noise density of the rate output, one- and two-sided figures
scalefactor     rate-table scale factor, bias, nonlinearity, CW/CCW asymmetry (table 7-2)
freqresp        second-order resonance fit of a frequency sweep (fig. 7-3, 7-5)
tempcomp        bias (and scale factor) against the drive phase P and a temperature,
                polynomial order by blocked cross-validation (7.3)
gyroctl_bridge  writes fitted coefficients to the gyro through the `gyroctl` tool
paramset        firmware parameter sets (docs/param-set.md): read, check, write
plotting        shared matplotlib helpers (Agg backend, no display needed)
cli             what every command-line script shares: errors, output, JSON
lotfile         a wafer lot's file and spec, validated; the parts drawn (Gaussian copula)
lotpart         one part of a lot on a worker: calibration flow and scenarios
lotjudge        a lot's table judged against its spec, per line and per part
lotrun          the lot's engine: Dask scheduling, resumption, version stamp, tables
lotreport       the lot report: yield and its interval, histograms, what costs yield

Every function takes and returns plain numpy arrays and floats in the units its name
says; InputError (errors.py) is raised for input that cannot give an answer.
"""
