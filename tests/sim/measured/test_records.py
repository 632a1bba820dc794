"""The readers of measured records: CSV with units in the header and UFF 58 through pyuff; each bad input one line
naming the file and what to do."""
from __future__ import annotations

import numpy as np
import pytest

from sim.common.errors import SimulationInputError
from sim.measured.hammer import HammerRecord
from sim.measured.records import (read_frf_csv, read_hammer_inputs, read_time_csv, read_uff, write_uff_frf,
                                  write_uff_time)

T = np.arange(64) / 1000.0


def csv(tmp_path, name: str, header: str, columns) -> str:
    path = tmp_path / name
    rows = np.column_stack(columns)
    path.write_text(header + "\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in rows) + "\n")
    return str(path)


def test_units_in_the_header_are_read_to_si(tmp_path):
    path = csv(tmp_path, "r.csv", "time [ms],force_kN,tip (g),base_mm_s2", [1e3 * T, np.ones(64), np.ones(64), np.ones(64)])
    record = read_time_csv(path)
    assert record.fs == pytest.approx(1000.0) and record.force[0] == 1e3
    assert record.responses["tip"][0] == pytest.approx(9.80665) and record.responses["base"][0] == 1e-3
    assert record.quantities == {"tip": "acceleration", "base": "acceleration"}


def test_frf_csv_in_magnitude_and_phase_is_displacement_per_force(tmp_path):
    f = np.linspace(10, 100, 20)
    path = csv(tmp_path, "h.csv", "frequency_Hz,tip_mag_m_s2_N,tip_phase_deg,tip_coherence",
               [f, np.ones(20), np.zeros(20), np.ones(20)])
    frf = read_frf_csv(path)
    assert np.allclose(frf.frf["tip"], -1 / (2 * np.pi * f) ** 2) and np.allclose(frf.coherence["tip"], 1)


@pytest.mark.parametrize("header, columns, phrase", [
    ("time_s,force_N", [T, T], "no response column"),
    ("time_s,,accel_m_s2", [T, T, T], "column 2 has no name"),
    ("time_s,force_N,accel_furlongs", [T, T, T], "column 'accel_furlongs' has no unit this reader knows"),
    ("time_s,accel_m_s2", [T, T], "no force column"),
    ("time_s,force_N,accel_m_s2", [T, np.r_[np.nan, T[1:]], T], "'force_N' is nan at data row 1"),
    ("time_s,force_N,accel_m_s2", [T[::-1], T, T], "time must increase"),
])
def test_bad_time_records_are_one_line(tmp_path, header, columns, phrase):
    path = csv(tmp_path, "bad.csv", header, columns)
    with pytest.raises(SimulationInputError, match=phrase) as info:
        read_hammer_inputs([path])
    assert str(path) in str(info.value) and "\n" not in str(info.value)


def test_a_frequency_axis_that_does_not_increase_is_one_line(tmp_path):
    f = np.linspace(10, 100, 20)
    path = csv(tmp_path, "h.csv", "frequency_Hz,tip_real_m_N,tip_imag_m_N", [f[::-1], f, f])
    with pytest.raises(SimulationInputError, match="the frequency must increase"):
        read_frf_csv(path)


def test_uff_round_trips_and_refuses_other_data_sets(tmp_path):
    import pyuff

    record = HammerRecord(1000.0, np.sin(T), {"tip": np.cos(T)}, {"tip": "acceleration"})
    back = read_uff(write_uff_time(tmp_path / "t.uff", record))
    assert isinstance(back, HammerRecord) and back.fs == pytest.approx(1000.0)
    assert np.allclose(back.force, record.force) and np.allclose(back.responses["tip"], record.responses["tip"])
    other = tmp_path / "nodes.uff"
    pyuff.UFF(str(other)).write_sets(pyuff.prepare_15(node_nums=[1, 2], def_cs=[0, 0], disp_cs=[0, 0], color=[1, 1],
                                                      x=[0.0, 1.0], y=[0.0, 0.0], z=[0.0, 0.0]), mode="add")
    with pytest.raises(SimulationInputError, match="nodes.uff: holds UFF data sets of type 15"):
        read_uff(other)
    f = np.linspace(10, 100, 20)
    frf = read_uff(write_uff_frf(tmp_path / "f.uff", f, {"tip": 1 / (1 + 1j * f)}))
    assert np.allclose(frf.frf["tip"], 1 / (1 + 1j * f), rtol=1e-6)


def _uff_channel(name: str, data, x, code: int, abscissa: int, func_type: int = 1, **units):
    import pyuff

    return pyuff.prepare_58(func_type=func_type, rsp_node=1, rsp_dir=1, ref_node=1, ref_dir=1, rsp_ent_name=name,
                            ref_ent_name="force", id1=name, data=data, x=x, abscissa_spacing=1,
                            abscissa_spec_data_type=abscissa, ordinate_spec_data_type=code,
                            orddenom_spec_data_type=13 if func_type == 4 else 0, **units)


def test_uff_units_from_the_axis_labels_and_the_units_data_set(tmp_path):
    """A hammer record in g and kN (the data sets' labels), and the same in a mm / mN unit system (data set 164:
    SI = value / 1000^length exponent / 1000^force exponent) both read to SI; an FRF in g/N read as m/N."""
    import pyuff

    labelled = tmp_path / "labelled.uff"
    uff = pyuff.UFF(str(labelled))
    uff.write_sets(_uff_channel("force", np.sin(T), T, 13, 17, ordinate_axis_units_lab="kN",
                                abscissa_axis_units_lab="s"), mode="add")
    uff.write_sets(_uff_channel("tip", np.cos(T), T, 12, 17, ordinate_axis_units_lab="g"), mode="add")
    back = read_uff(labelled)
    assert np.allclose(back.force, 1e3 * np.sin(T)) and np.allclose(back.responses["tip"], 9.80665 * np.cos(T))

    system = tmp_path / "mm.uff"
    uff = pyuff.UFF(str(system))
    uff.write_sets(pyuff.prepare_164(units_code=5, units_description="mm (milli newton)", temp_mode=1, length=1000.0,
                                     force=1000.0, temp=1.0, temp_offset=273.15), mode="add")
    uff.write_sets(_uff_channel("force", np.sin(T), T, 13, 17, ordinate_len_unit_exp=0, ordinate_force_unit_exp=1),
                   mode="add")
    uff.write_sets(_uff_channel("tip", np.cos(T), T, 12, 17, ordinate_len_unit_exp=1, ordinate_force_unit_exp=0),
                   mode="add")
    back = read_uff(system)
    assert np.allclose(back.force, 1e-3 * np.sin(T)) and np.allclose(back.responses["tip"], 1e-3 * np.cos(T))

    f = np.linspace(10, 100, 20)
    accelerance = -((2 * np.pi * f) ** 2) / (1 + 1j * f)  # of the receptance 1 / (1 + i f), in m/s^2/N
    path = tmp_path / "frf_g.uff"
    pyuff.UFF(str(path)).write_sets(_uff_channel("tip", accelerance / 9.80665, f, 12, 18, func_type=4,
                                                 ordinate_axis_units_lab="g", orddenom_axis_units_lab="N"), mode="add")
    assert np.allclose(read_uff(path).frf["tip"], 1 / (1 + 1j * f), rtol=1e-6)


@pytest.mark.parametrize("label, message", [("furlongs", "labels its ordinate 'furlongs', a unit ies does not know"),
                                            ("kN", r"labels its ordinate 'kN' \(force\) where acceleration belongs")])
def test_a_uff_label_of_no_known_unit_or_another_quantity_is_one_line(tmp_path, label, message):
    import pyuff

    path = tmp_path / "odd.uff"
    uff = pyuff.UFF(str(path))
    uff.write_sets(_uff_channel("force", np.sin(T), T, 13, 17), mode="add")
    uff.write_sets(_uff_channel("tip", np.cos(T), T, 12, 17, ordinate_axis_units_lab=label), mode="add")
    with pytest.raises(SimulationInputError, match=message):
        read_uff(path)
