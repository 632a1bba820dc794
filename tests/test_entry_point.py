"""The `ies` entry point: every stage's subcommands are registered, user mistakes end in one line and exit 2."""
import subprocess
import sys

from uq.cli import build_parser, main


def test_every_subcommand_has_help():
    parser = build_parser()
    actions = [a for a in parser._actions if a.dest == "command"]
    assert actions, "no subcommands registered"
    for name in actions[0].choices:
        assert main([name, "--help"]) == 0


def test_version(capsys):
    from importlib.metadata import version

    assert main(["--version"]) == 0
    line = capsys.readouterr().out.strip()
    assert line.startswith(f"ies-workbench {version('ies-workbench')} (simulator code ") and len(line.splitlines()) == 1


def test_unknown_command_is_one_line_and_exit_2():
    proc = subprocess.run([sys.executable, "-m", "uq", "no-such-command"], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
