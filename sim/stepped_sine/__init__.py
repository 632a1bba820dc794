"""The stepped-sine protocol of the seed paper (Sects. 5.1-5.3), its measures (amplitudes, regimes, scattering,
Appendices B and D), the paper's Fig. 6 landmarks measured on an overview, batches of runs for the uncertainty layer
and the result tables."""
