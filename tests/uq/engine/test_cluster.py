"""`--cluster` without a batch system: the bad inputs of issue 26 (unknown kind, dask-jobqueue missing, no sbatch,
a wrong [cluster] table, --cluster with --scheduler) are one line, exit 2, nothing written; settings come from
jobqueue.yaml, then [cluster], then the options (the explicit ones win); every study command has the options.
The runs on a real SLURM are in tests/cluster."""
import sys

import pytest

from uq.cli import build_parser, main
from uq.engine.cluster import _cluster_kwargs, cluster_settings
from uq.problem.cluster_settings import ClusterSettings, parse_cluster_table
from uq.errors import StudyError

STUDY = """
[study]
kind = "sobol"
model = "ishigami"
[sobol]
n = 4
{cluster}
"""


def study(tmp_path, cluster=""):
    path = tmp_path / "s.toml"
    path.write_text(STUDY.format(cluster=cluster))
    return path


def run(tmp_path, capsys, *options, cluster=""):
    out = tmp_path / "out"
    code = main(["sobol", str(study(tmp_path, cluster)), "--out", str(out), "--quiet", "--no-figures", *options])
    err = capsys.readouterr().err
    return code, err, out


@pytest.mark.parametrize("options, cluster, message", [
    (["--cluster", "kubernetes"], "", "unknown cluster kind 'kubernetes'; known: slurm, pbs"),
    ([], "[cluster]\nkind = 'yarn'", "unknown cluster kind 'yarn'"),
    ([], "[cluster]\ncores = 0", "[cluster] cores must be a positive integer"),
    ([], "[cluster]\nwalltime = '2h'", "[cluster] walltime must be a time like"),
    ([], "[cluster]\nnodes = 3", "unknown key 'nodes' in [cluster]"),
    (["--cluster-walltime", "90"], "", "--cluster-walltime: must be a time like"),
    (["--cluster-cores", "2"], "", "--cluster-* options need --cluster KIND"),
    (["--cluster", "slurm", "--scheduler", "tcp://127.0.0.1:9"], "", "--cluster and --scheduler exclude each other"),
    (["--cluster", "slurm", "--worker-timeout", "-1"], "", "--worker-timeout: must be a positive number"),
])
def test_bad_cluster_input_is_one_line(tmp_path, capsys, options, cluster, message):
    code, err, out = run(tmp_path, capsys, *options, cluster=cluster)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_missing_dask_jobqueue_names_the_extra(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "dask_jobqueue", None)  # import fails as if not installed
    code, err, out = run(tmp_path, capsys, "--cluster", "slurm")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "needs dask-jobqueue: pip install 'ies-workbench[cluster]'" in err and not out.exists()


def test_no_sbatch_on_the_path(tmp_path, capsys, monkeypatch):
    pytest.importorskip("dask_jobqueue")
    monkeypatch.setenv("PATH", str(tmp_path))  # an empty folder: no sbatch
    code, err, out = run(tmp_path, capsys, "--cluster", "slurm")
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "`sbatch` is not on the PATH" in err and not out.exists()


def test_cluster_none_runs_locally_despite_the_table(tmp_path, capsys):
    code, _err, out = run(tmp_path, capsys, "--cluster", "none", "--jobs", "1", cluster="[cluster]\nkind = 'slurm'")
    assert code == 0 and (out / "sobol.csv").is_file()


def args(*options):
    return build_parser().parse_args(["sobol", "s.toml", *options])


def test_options_win_over_the_table_which_wins_over_jobqueue_yaml():
    dask = pytest.importorskip("dask")
    table = parse_cluster_table({"kind": "slurm", "cores": 4, "memory": "8GB", "queue": "long", "max_jobs": 3,
                                 "directives": ["--qos=low"], "worker_timeout": 30})
    settings = cluster_settings(args("--cluster-queue", "short", "--cluster-walltime", "01:00:00"), table)
    assert settings == ClusterSettings("slurm", 4, "8GB", "01:00:00", "short", None, 3, directives=("--qos=low",),
                                       worker_timeout=30.0)
    with dask.config.set({"jobqueue.slurm.cores": 16, "jobqueue.slurm.memory": "64GB", "jobqueue.slurm.account": "a1",
                          "jobqueue.slurm.walltime": "04:00:00"}):
        kw = _cluster_kwargs(settings)
        assert kw["cores"] == 4 and kw["processes"] == 4 and kw["memory"] == "8GB" and kw["queue"] == "short"
        assert kw["walltime"] == "01:00:00" and kw["job_extra_directives"] == ["--qos=low"]
        assert "account" not in kw  # unset here: dask-jobqueue reads jobqueue.slurm.account itself
        assert kw["worker_extra_args"][:2] == ["--lifetime", f"{3600 - 180}s"]  # retire before the walltime
        bare = _cluster_kwargs(ClusterSettings("slurm"))
        assert bare["cores"] == 16 and bare["memory"] == "64GB" and "walltime" not in bare
    assert cluster_settings(args(), None) is None
    assert cluster_settings(args("--cluster", "none"), table) is None
    assert cluster_settings(args(), table) == table


def test_every_study_command_takes_the_cluster_options():
    parser = build_parser()
    for command in (["interval", "s.toml"], ["sobol", "s.toml"], ["response", "s.toml"], ["reproduce", "fig5"]):
        parsed = parser.parse_args([*command, "--cluster", "pbs", "--cluster-max-jobs", "7", "--worker-timeout", "9"])
        assert (parsed.cluster, parsed.cluster_max_jobs, parsed.worker_timeout) == ("pbs", 7, 9.0)


def test_the_cluster_table_is_not_part_of_the_study_key(tmp_path):
    """The same study on a cluster or locally has the same key: --resume continues it on either."""
    from uq.engine.execution import study_key
    from uq.methods import load_study

    local = load_study(study(tmp_path))
    (tmp_path / "c").mkdir()
    remote = load_study(study(tmp_path / "c", "[cluster]\nkind = 'slurm'\ncores = 2"))
    assert remote.cluster == ClusterSettings("slurm", cores=2)
    assert study_key(local, local.make_model()) == study_key(remote, remote.make_model())
    with pytest.raises(StudyError, match="must be a non-empty string"):
        parse_cluster_table({"queue": ""})
