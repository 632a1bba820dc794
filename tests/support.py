"""Pieces several test files share."""

#: two abstract parameters a, b on [0, 1] (nominal 0.5) as a study file's [parameters] tables
AB_PARAMETERS = """
[parameters.a]
nominal = 0.5
min = 0.0
max = 1.0
[parameters.b]
nominal = 0.5
min = 0.0
max = 1.0
"""
