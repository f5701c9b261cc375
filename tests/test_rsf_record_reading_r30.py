"""Round 30 (tester W): how lab records are read: force columns, encodings, a mapped velocity, implausible friction.

Every expected value is the truth the synthetic file is written from (closed forms), never the reader's output.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from cli_helpers import run_main
from stickslip.errors import DataError
from stickslip.protocols import Protocol, Segment
from stickslip.rsf.data import change_time_uncertainty, read_record
from stickslip.tables import read_table

#: the synthetic record: 200 rows, 0.5 s apart, the load point at 1 um/s, friction about 0.6
TIME = np.arange(200) * 0.5
DISPLACEMENT_UM = 1.0 * TIME
MU = 0.6 + 0.01 * np.sin(TIME / 7.0)
SIGMA_MPA = 20.0
AREA_M2 = 0.01  # 100 cm^2


def _write(path, header, columns, encoding="utf-8", sep=","):
    rows = "\n".join(sep.join(f"{value:.12g}" for value in row) for row in zip(*columns, strict=True))
    path.write_bytes((sep.join(header) + "\n" + rows + "\n").encode(encoding))
    return path


# --- D1: a force is a force ----------------------------------------------------------------------------------------


def test_a_shear_force_over_a_normal_stress_needs_the_contact_area(tmp_path):
    """Shear force (N) = mu sigma A was read as Pa (mu 100x too small with A = 0.01 m^2): refused without the
    area, the truth with it."""
    force_n = MU * SIGMA_MPA * 1e6 * AREA_M2
    path = _write(tmp_path / "force_stress.csv", ["Time (s)", "LP Displacement (um)", "Shear force (N)",
                  "Normal stress (MPa)"], [TIME, DISPLACEMENT_UM, force_n, np.full(TIME.size, SIGMA_MPA)])  # fmt: skip
    mapping = {"shear_stress": "Shear force (N)", "normal_stress": "Normal stress (MPa)"}
    with pytest.raises(DataError, match=r"'Shear force \(N\)' is a force \(N\).*--contact-area") as caught:
        read_record(path, mapping)
    assert "\n" not in str(caught.value)
    record = read_record(path, mapping, contact_area="100 cm^2")
    np.testing.assert_allclose(record.friction, MU, rtol=1e-9)


def test_a_shear_force_over_a_normal_force_is_their_ratio_in_their_units(tmp_path):
    """kN over N, found by name: mu = Fs/Fn with the kilo kept (it was refused as 'no friction column', and mapped
    read as 0.0006 'check the units (a bare header is Pa)')."""
    normal_n = np.full(TIME.size, 50_000.0)
    path = _write(tmp_path / "forces.csv", ["Time (s)", "LP Displacement (um)", "Shear force (kN)", "Normal force (N)"],
                  [TIME, DISPLACEMENT_UM, MU * normal_n / 1e3, normal_n])  # fmt: skip
    record = read_record(path)
    np.testing.assert_allclose(record.friction, MU, rtol=1e-9)
    assert any("Fs/Fn" in note for note in record.notes)


def test_a_force_unit_on_the_friction_column_is_refused(tmp_path):
    """ "Friction (N)" was read as a coefficient (a bracketed word that is no length, time, speed or stress)."""
    path = _write(tmp_path / "fric_n.csv", ["Time (s)", "Displ (um)", "Friction (N)"], [TIME, DISPLACEMENT_UM, MU])
    with pytest.raises(DataError, match=r"'Friction \(N\)' is in N, a force; expected the friction coefficient"):
        read_record(path)


def test_rsf_fit_takes_a_contact_area(tmp_path, capsys):
    path = _write(tmp_path / "force_stress.csv", ["Time (s)", "Displ (um)", "Shear force (kN)", "Normal stress (MPa)"],
                  [TIME, DISPLACEMENT_UM, MU * SIGMA_MPA * 1e3 * AREA_M2, np.full(TIME.size, SIGMA_MPA)])  # fmt: skip
    code, _, err = run_main(capsys, "rsf", "fit", str(path))
    assert code == 2 and "--contact-area" in err and len(err.strip().splitlines()) == 1, err
    code, _, err = run_main(capsys, "rsf", "fit", str(path), "--contact-area", "-1 m^2")
    assert code == 2 and "--contact-area" in err, err


# --- D3: encodings -------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(("encoding", "said"), [("latin-1", "Windows-1252"), ("utf-16", ""), ("utf-32", ""),
                                                ("utf-16-le", "UTF-16 text without a byte-order mark")])  # fmt: skip
def test_records_that_are_not_utf8_read_as_their_utf8_twin(tmp_path, encoding, said):
    header = ["Time [s]", "LP disp [µm]", "µ"]
    twin = read_record(_write(tmp_path / "utf8.txt", header, [TIME, DISPLACEMENT_UM, MU], sep="\t"))
    record = read_record(_write(tmp_path / f"{encoding}.txt", header, [TIME, DISPLACEMENT_UM, MU], encoding, "\t"))
    np.testing.assert_allclose(record.displacement, DISPLACEMENT_UM * 1e-6 - DISPLACEMENT_UM[0] * 1e-6, atol=1e-15)
    np.testing.assert_array_equal(record.friction, twin.friction)
    noted = [n for n in record.notes if "UTF" in n or "1252" in n]
    assert (said in noted[0]) if said else not noted, record.notes


@pytest.mark.parametrize("encoding", ["cp1252", "utf-16"])
def test_measurement_tables_that_are_not_utf8_are_read(tmp_path, encoding):
    """analyze's and fit's reader (tables.read_table): a header with "µm/s" in 8-bit text, or UTF-16."""
    velocity = np.array([0.1, 1.0, 10.0, 100.0])
    path = tmp_path / "table.csv"
    path.write_bytes(("velocity [µm/s],stress [kPa]\n" + "".join(f"{v:g},{2 * v:g}\n" for v in velocity))
                     .encode(encoding))  # fmt: skip
    table = read_table(path, {"velocity": "velocity", "stress": "stress"}, ["velocity", "stress"])
    np.testing.assert_allclose(table["velocity"], velocity * 1e-6, rtol=1e-12)
    np.testing.assert_allclose(table["stress"], 2e3 * velocity, rtol=1e-12)


def test_binary_and_empty_files_are_refused_in_their_own_words(tmp_path):
    binary = tmp_path / "data.csv"
    binary.write_bytes(bytes(np.random.default_rng(3).integers(0, 256, 4000, dtype=np.uint8)))
    with pytest.raises(DataError, match=r"not a text table \(binary data"):
        read_record(binary)
    with pytest.raises(DataError, match=r"not a text table \(binary data"):
        read_table(binary, {"velocity": "velocity"}, ["velocity"])
    empty = tmp_path / "empty.csv"
    empty.write_bytes(b"")
    with pytest.raises(DataError, match="the file is empty") as caught:
        read_record(empty)
    assert "No columns" not in str(caught.value)


# --- D4: a mapped velocity is used ---------------------------------------------------------------------------------


def test_a_mapped_velocity_column_is_used_beside_a_displacement_column(tmp_path):
    """The set velocity (1 then 3 um/s) integrated, not the displacement column (twice it: another history)."""
    velocity = np.where(TIME < 50.0, 1.0, 3.0)
    integral = np.concatenate([[0.0], np.cumsum(velocity[:-1] * np.diff(TIME))])
    path = _write(tmp_path / "both.csv", ["Time (s)", "Displ (um)", "Set velocity (um/s)", "Friction"],
                  [TIME, 2.0 * integral, velocity, MU])  # fmt: skip
    record = read_record(path, {"time": "Time (s)", "velocity": "Set velocity (um/s)", "friction": "Friction"})
    assert record.displacement_from == "velocity"
    np.testing.assert_allclose(record.displacement, integral * 1e-6, rtol=1e-12, atol=1e-18)
    with pytest.raises(DataError, match="maps both displacement and velocity"):
        read_record(path, {"displacement": "Displ (um)", "velocity": "Set velocity (um/s)"})


def test_a_change_read_from_a_velocity_column_is_known_to_its_row_spacing():
    """The rows say only that the velocity changed since the row before: spacing / sqrt(12), not 1e-14 s."""
    t = np.arange(400) * 0.136
    protocol = Protocol((Segment(1e-6, t[200]), Segment(3e-6, t[-1] - t[200])))
    d = protocol.displacement_at(t)
    held = change_time_uncertainty(t, d, protocol)
    assert held[0] < 1e-9  # the displacement itself dates it (its lines meet exactly)
    sampled = change_time_uncertainty(t, d, protocol, sampled_velocity=True)
    assert sampled[0] == pytest.approx(0.136 / math.sqrt(12.0), rel=1e-6)


# --- D5: a friction that is no coefficient -------------------------------------------------------------------------


OUTSIDE = r"outside 0\.001 to 10"


@pytest.mark.parametrize(("friction", "words"), [(-MU, r"negative .*flip the column's sign"),
                                                 (100 * MU, rf"{OUTSIDE}.*percent"),
                                                 (1e5 * MU, rf"{OUTSIDE}.*shear stress or force")])  # fmt: skip
def test_a_friction_column_that_is_no_coefficient_is_refused(tmp_path, friction, words):
    path = _write(tmp_path / "mu.txt", ["Time(s)", "Displ(microns)", "Friction"], [TIME, DISPLACEMENT_UM, friction],
                  sep="\t")  # fmt: skip
    with pytest.raises(DataError, match=rf"mu\.txt: column 'Friction': .*{words}") as caught:
        read_record(path)
    assert "\n" not in str(caught.value)
