"""`ies impacts` and `ies modal-fit`: the library's results as JSON and tables, the check against a simulated
trace's own contacts, and given impact lists."""
import json

import numpy as np
import pytest

from sim.common.files import write_csv
from sim.analysis.impacts import DEFAULT_THRESHOLDS, detect_impacts, synthetic_impact_signal
from sim.hosts.modal_file import save_modal_model
from uq.cli import main


@pytest.fixture
def synthetic_csv(tmp_path):
    case = synthetic_impact_signal(2.0, periods=20, seed=1)
    s = case.signal
    path = write_csv(tmp_path / "measured.csv", ("t", "a_left", "a_right", "a_tip"),
                     np.column_stack([s.t, s["a_left"], s["a_right"], s["a_tip"]]))
    return path, case


def test_impacts_json_matches_the_library(synthetic_csv, capsys):
    path, case = synthetic_csv
    assert main(["impacts", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    library = detect_impacts(path)
    assert data["thresholds"] == pytest.approx(DEFAULT_THRESHOLDS)
    assert data["impacts_per_period"] == pytest.approx(library.impacts_per_period.tolist())
    assert [i["t"] for i in data["impacts"]] == pytest.approx(library.times.tolist())
    assert data["fs"] == pytest.approx(51.2e3) and data["simulator_check"] is None  # a measurement: no forces
    assert data["impacts_per_period"][-1] == pytest.approx(2.0, abs=0.15)


def test_impacts_table_with_one_threshold_and_given_frequency(synthetic_csv, capsys):
    path, _ = synthetic_csv
    assert main(["impacts", str(path), "--threshold", "1.0", "--excitation-hz", "117"]) == 0
    text = capsys.readouterr().out
    assert "excitation 117.000 Hz (given)" in text and "per period" in text and len(text.splitlines()) == 3


@pytest.fixture(scope="module")
def simulated(tmp_path_factory):
    """A short trace of the three-mode model by ies trace (its 19.8 kHz mode rings through 20 kHz)."""
    from sim.model.system import ModalModel

    folder = tmp_path_factory.mktemp("trace")
    model = ModalModel(frequencies_hz=np.array([117.4, 2494.0, 19800.0]), damping_ratios=np.array([0.00085, 0.0005, 0.001]),
                       phi_wall_left=np.array([1.05, 0.95, 0.6]), phi_wall_right=np.array([1.05, 0.95, 0.6]),
                       phi_tip=np.array([1.0, 0.8, 0.3]), participation=np.array([0.95, 0.35, 0.1]), source="three modes")
    model_path = str(save_modal_model(model, folder / "three.toml"))
    assert main(["trace", "--level", "6", "--eta", "0.99", "--periods", "20", "--wait", "0.3", "--model", model_path,
                 "--out", str(folder / "t")]) == 0
    return folder / "t", model_path


def test_impacts_on_a_simulated_trace_are_checked_against_its_contacts(simulated, capsys):
    folder, _ = simulated
    capsys.readouterr()
    assert main(["impacts", str(folder / "trace.csv"), "--threshold", "0.5", "--highpass", "22000", "--json"]) == 0
    check = json.loads(capsys.readouterr().out)["simulator_check"]
    contacts = json.loads((folder / "trace.json").read_text())["impacts"]
    assert check["contacts"] == len(contacts) > 10
    assert 0 <= check["false_share"] <= 1 and 0 <= check["found_share"] <= 1


def test_modal_fit_with_the_traces_impacts(simulated, tmp_path, capsys):
    folder, model_path = simulated
    capsys.readouterr()
    plot = tmp_path / "fit.png"
    assert main(["modal-fit", str(folder / "trace.csv"), "--model", model_path, "--impacts",
                 str(folder / "trace.json"), "--json", "--plot", str(plot)]) == 0
    data = json.loads(capsys.readouterr().out)
    trace = json.loads((folder / "trace.json").read_text())
    assert data["impacts"] == pytest.approx(sorted(i["t"] for i in trace["impacts"]))
    assert data["n_modes"] == 3 and 0 < data["higher_share"] < 1 and data["simulator_check"] is None
    assert plot.stat().st_size > 1000
    assert main(["modal-fit", str(folder / "trace.csv"), "--model", model_path, "--impacts",
                 str(folder / "trace.json")]) == 0
    text = capsys.readouterr().out
    assert "share of modes 2..3" in text and "well posed" in text
