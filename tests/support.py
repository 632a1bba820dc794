"""Pieces several test files share."""
from pathlib import Path

#: the shortest stepped sine a command test needs (3 frequencies, 1 repetition)
FAST = ["--eta", "0.98:1.0:3", "--wait", "0.02", "--hold", "0.03", "--reps", "1"]
#: the shipped study files
STUDIES = Path(__file__).resolve().parents[1] / "uq" / "studies"

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
