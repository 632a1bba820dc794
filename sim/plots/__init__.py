"""Figures of the simulation stage (Figs. 4, 5, 6, 9a) and the registry with which `ies plot` redraws any result
folder from its saved data."""
