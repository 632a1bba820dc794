"""Uncertainty studies (intervals, Sobol indices), runners, figures and the `ies` command line."""
