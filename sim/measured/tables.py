"""The files `ies identify` and `ies linearity` write, column by column (`sim.common.outputs`; uq/OUTPUTS.md is
generated from these tables). "<NAME>" stands for each response's name (a CSV column of the record, e.g. tip)."""
from __future__ import annotations

from sim.common.outputs import Column, OutputFile

MODES_CSV = OutputFile("modes.csv", "ies identify", "One row per identified mode, ascending frequency; `ies update` "
                       "reads it.", (
                           Column("mode", "-", "mode number (1, 2, ...)"),
                           Column("frequency_hz", "Hz", "natural frequency |lambda| / (2 pi) of the chosen stable pole"),
                           Column("damping_ratio", "-", "modal damping ratio, the exponential window's share taken out"),
                           Column("modal_constant_<NAME>_per_kg", "SI", "real modal constant A of the response (1/kg, "
                                  "displacement per force; phi_response phi_drive of the mass-normalised mode, LSFD)"),
                       ))
FRF_CSV = OutputFile("frf.csv", "ies identify", "The measured FRF of displacement per force (H_v, H_1 or H_2: "
                     "`--estimator`), one row per frequency line, after a comment line `# window_decay_per_s = X` "
                     "(1/s: the exponential window's added decay rate); `ies identify frf.csv` reads it back.", (
                         Column("frequency_Hz", "Hz", "frequency line"),
                         Column("<NAME>_real_m_N, <NAME>_imag_m_N", "SI", "real and imaginary part of the response's "
                                "displacement per force (m/N)"),
                         Column("<NAME>_coherence", "-", "coherence gamma^2 of the hits (hammer records only)"),
                     ))
POLES_CSV = OutputFile("poles.csv", "ies identify", "The stabilization diagram: every pole of every order of every "
                       "sub-band (`sim.measured.identification`).", (
                           Column("order", "-", "model order (of its sub-band)"),
                           Column("frequency_hz", "Hz", "the pole's natural frequency"),
                           Column("damping_ratio", "-", "the pole's damping ratio (window's share taken out)"),
                           Column("status", "-", "0 new, 1 stable in frequency, 2 stable in frequency and damping"),
                       ))
LEVELS_CSV = OutputFile("levels.csv", "ies linearity", "One row per level, ascending base amplitude (Appendix B).", (
    Column("a_base_m", "m", "base amplitude of the level"),
    Column("resonance_hz", "Hz", "frequency of the peak of a / a_base"),
    Column("half_power_damping_ratio", "-", "damping ratio by the half-power bandwidth (NaN: a half-power frequency "
           "lies outside the steps)"),
    Column("peak_amplitude_m", "m", "peak tip amplitude relative to the base"),
))
BACKBONE_CSV = OutputFile("backbone.csv", "ies linearity", "The single nonlinear mode over the measured amplitudes.", (
    Column("amplitude_m", "m", "tip amplitude a relative to the base"),
    Column("frequency_hz", "Hz", "natural frequency omega(a) / (2 pi): the backbone"),
    Column("damping_ratio", "-", "damping ratio D(a)"),
))
TABLES = (MODES_CSV, FRF_CSV, POLES_CSV, LEVELS_CSV, BACKBONE_CSV)
