"""Reduced models of the IES on a flexible host: the one-mode slow flow with Newton's impact law
(`sim.reduced.slow_flow`), for fast screening of designs and for explaining the full simulator's regimes."""
