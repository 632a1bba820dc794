"""The stepped-sine protocol of the seed paper (Sects. 5.1-5.3), its measures (amplitudes, regimes, scattering,
Appendices B and D), batches of runs for the uncertainty layer and the result tables."""
