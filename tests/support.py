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

#: the shortest stepped sine of a study file's [excitation] table (one level, two frequencies)
TINY_EXCITATION = ("[excitation]\nlevels = [7.4]\neta = { start = 0.98, stop = 0.99, n = 2 }\nwait = 0.02\n"
                   "hold = 0.05\n")


def interval_runs(tmp_path: Path, head: str, name: str = "study") -> tuple[Path, list[dict[str, str]]]:
    """Run a tiny interval study (its [study] and [parameters.*] tables in `head`, TINY_EXCITATION, no interior
    points) through `ies interval` in this process; returns (the output folder, the rows of its runs.csv)."""
    import csv

    from uq.cli import main

    study = tmp_path / f"{name}.toml"
    study.write_text(f"[study]\nkind = 'interval'\nrepetitions = 1\n{head}{TINY_EXCITATION}[interval]\ninterior = 0\n")
    out = tmp_path / f"{name}-out"
    assert main(["interval", str(study), "--out", str(out), "--quiet", "--jobs", "1", "--no-figures"]) == 0
    with open(out / "runs.csv", newline="") as fh:
        return out, list(csv.DictReader(fh))


def tiny_design(tmp_path: Path, model: str | Path) -> dict:
    """Run `ies design` on a tiny design study (1.5 um: below the switch by more than the margin; clearances 0.5 and
    0.6 mm, the paper's radius, one candidate, one repetition, a two-frequency stepped sine) with the host `model` (a
    file); returns its design.json."""
    import json

    from uq.cli import main

    study = tmp_path / "design.toml"
    study.write_text(f"[study]\nkind = 'design'\noutput = '{tmp_path / 'design-out'}'\n[design]\nexcitation = '1.5um'\n"
                     f"clearance = '0.5mm:0.6mm:2'\nradius = '7.92mm'\ncandidates = 1\nreps = 1\nmodel = '{model}'\n"
                     "[excitation]\neta = { start = 0.98, stop = 0.99, n = 2 }\nwait = 0.02\nhold = 0.05\n")
    assert main(["design", str(study), "--jobs", "1", "--quiet", "--no-figures"]) == 0
    return json.loads((tmp_path / "design-out" / "design.json").read_text())


def sleepy(params: dict, level: float, rep: int, seed: int) -> float:
    """A model of a study file (``model = "tests.support:sleepy"``) whose runs take 0.25 s each: a study that is
    still running when a second process starts."""
    import time

    time.sleep(0.25)
    return sum(params.values()) + level


def one_line(capsys, code: int, expected: int, *phrases: str, absent: tuple[str, ...] = ()) -> str:
    """Assert exit code `expected` with one line on stderr holding `phrases` and none of `absent`; return the line."""
    err = capsys.readouterr().err
    assert code == expected, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    for phrase in phrases:
        assert phrase in err, err
    for phrase in absent:
        assert phrase not in err, err
    return err


def refused(capsys, code: int, *phrases: str) -> str:
    """Assert the one-line refusal (exit 2) and return its line."""
    return one_line(capsys, code, 2, *phrases)

