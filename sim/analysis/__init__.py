"""Analyses of measured or simulated signals: signals, impact detection (Appendix D.1), modal reconstruction between
impacts (Sect. 5.5, Eq. 9), time traces of one stepped-sine point (Figs. 4, 9a), and their commands."""
