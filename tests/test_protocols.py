"""Loading protocols: segments, steps, slide-hold-slide, CSV; exact displacement; one-line errors."""

from __future__ import annotations

import numpy as np
import pytest

from stickslip import protocols as pr
from stickslip.errors import DataError, ParameterError
from stickslip.fileio import atomic_write_text, refuse_input_as_output


def test_slide_hold_slide_boundaries_and_exact_displacement():
    p = pr.slide_hold_slide(10e-6, 5.0, 100.0, reslide_time=20.0)
    assert p.duration == 125.0
    np.testing.assert_array_equal(p.boundaries, [0.0, 5.0, 105.0, 125.0])
    np.testing.assert_array_equal(p.change_times, [5.0, 105.0])
    # integrals by hand: 10 um/s * 5 s = 50 um, then held, then 10 um/s * 10 s more
    assert p.displacement_at(5.0) == pytest.approx(50e-6, rel=1e-15)
    assert p.displacement_at(60.0) == pytest.approx(50e-6, rel=1e-15)
    assert p.displacement_at(115.0) == pytest.approx(150e-6, rel=1e-15)
    assert p.velocity_at([0.0, 4.99, 5.0, 105.0, 200.0]).tolist() == [10e-6, 10e-6, 0.0, 10e-6, 10e-6]


def test_equal_neighbours_are_not_changes():
    p = pr.velocity_steps([1e-6, 1e-6, 1e-5], 2.0)
    np.testing.assert_array_equal(p.change_times, [4.0])


def test_parse_segment_units_and_errors():
    s = pr.parse_segment("100 um/s:10 s")
    assert (s.velocity, s.duration) == pytest.approx((1e-4, 10.0))
    with pytest.raises(ParameterError, match="VELOCITY:DURATION"):
        pr.parse_segment("100 um/s")
    with pytest.raises(ParameterError, match="positive"):
        pr.parse_segment("1 um/s:-3 s")
    with pytest.raises(ParameterError, match=">= 0"):
        pr.parse_segment("-1 um/s:3 s")


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("time,velocity\n0,1e-6\n5,2e-6\n5,0\n", "row 4: time 5 s does not increase"),
        ("time,speed\n0,1\n", "expected columns time,velocity"),
        ("time,velocity\n0,abc\n1,0\n", "row 2"),
        ("time,velocity\n0,1e-6\n", "at least two rows"),
        ("velocity,duration\n1e-6,0\n", "row 2"),
    ],
)
def test_bad_protocol_files_get_one_line(tmp_path, text, message):
    path = tmp_path / "p.csv"
    path.write_text(text)
    with pytest.raises(DataError, match=message) as info:
        pr.read_protocol(path)
    assert "\n" not in str(info.value)


def test_csv_change_points_and_segments_agree(tmp_path):
    a = tmp_path / "a.csv"
    a.write_text("time,velocity\n0,1e-6\n10,1e-5\n30,0\n")
    b = tmp_path / "b.tsv"
    b.write_text("velocity\tduration\n1e-6\t10\n1e-5\t20\n")
    pa, pb = pr.read_protocol(a), pr.read_protocol(b)
    assert pa.segments == pb.segments
    assert pa.displacement_at(30.0) == pytest.approx(10e-6 + 200e-6, rel=1e-15)


def test_atomic_write_and_input_guard(tmp_path):
    path = tmp_path / "out.csv"
    atomic_write_text(path, "a,b\n1,2\n")
    assert path.read_text() == "a,b\n1,2\n"
    assert [p.name for p in tmp_path.iterdir()] == ["out.csv"]  # no temporary left behind
    with pytest.raises(DataError, match=r"-o .*input file"):
        refuse_input_as_output([path], [("-o", path)])
    refuse_input_as_output([path], [("-o", tmp_path / "other.csv")])


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"", "empty file"),  # pandas' sniffer: "Could not determine delimiter", an internal error (issue 18)
        (b"  \n\t\n", "empty file"),
        (b"\x90\xff\x00\xc3\x28" * 20, r"not a text \(UTF-8\) file"),
    ],
    ids=["empty", "blank", "binary"],
)
def test_empty_and_binary_protocol_files_are_one_line(tmp_path, content, message):
    path = tmp_path / "p.csv"
    path.write_bytes(content)
    with pytest.raises(DataError, match=message) as info:
        pr.read_protocol(path)
    assert "\n" not in str(info.value)


def test_a_fifo_or_a_folder_is_refused_without_reading(tmp_path):
    import os

    os.mkfifo(tmp_path / "pipe")  # opening it for reading would block until a writer came
    with pytest.raises(DataError, match="not a regular file"):
        pr.read_protocol(tmp_path / "pipe")
    with pytest.raises(DataError, match="is a folder"):
        pr.read_protocol(tmp_path)


def test_a_byte_order_mark_does_not_hide_the_header(tmp_path):
    plain, marked = tmp_path / "plain.csv", tmp_path / "marked.csv"
    plain.write_text("time,velocity\n0,1e-6\n10,2e-6\n12,0\n", encoding="utf-8")
    marked.write_bytes("\ufeff".encode() + plain.read_bytes())
    assert pr.read_protocol(marked).segments == pr.read_protocol(plain).segments
