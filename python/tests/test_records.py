"""Records read by the library's readers (aemstep::records) through read_at2 and
read_column: the El Centro files, text given directly, and typed errors with the line."""

import numpy as np
import pytest

import aemstep
from conftest import ROOT

AT2 = ROOT / "data" / "elcentro-ns-1940.AT2"
TXT = ROOT / "data" / "elcentro-ns-1940.txt"


def test_at2_and_column_files_hold_the_same_record():
    acc, dt = aemstep.read_at2(AT2)
    col, dt2 = aemstep.read_column(TXT, 0.02)
    assert dt == dt2 == 0.02 and acc.shape == col.shape == (3995,)
    # Both files print the same values (the AT2 in E format): equal after parsing.
    np.testing.assert_array_equal(acc, col)


def test_path_as_str_and_text_give_the_same_values():
    text = AT2.read_text()
    a, dt = aemstep.read_at2(str(AT2))
    b, dt2 = aemstep.read_at2(text)
    np.testing.assert_array_equal(a, b)
    assert dt == dt2


def test_at2_text_values_exact():
    text = "T\nE\nU\nNPTS=     3, DT=   .0100 SEC\n  .1000000E-02 -.2000000E-02\n 3.5\n"
    acc, dt = aemstep.read_at2(text)
    assert dt == 0.01
    assert acc.tolist() == [0.001, -0.002, 3.5]


def test_column_text_with_comments():
    acc, dt = aemstep.read_column("# header\n0.5\n-0.25 # note\n\n1e-3\n", 0.005)
    assert dt == 0.005 and acc.tolist() == [0.5, -0.25, 1e-3]


@pytest.mark.parametrize(
    "text, line",
    [
        ("T\nE\nU\nNPTS= 2, DT= .01 SEC\n0.1 oops\n", 5),  # not a number
        ("T\nE\nU\nNPTS= x, DT= .01 SEC\n0.1 0.2\n", 4),  # no count
        ("T\nE\nU\nNPTS= 2, DT= -1 SEC\n0.1 0.2\n", 4),  # DT not > 0
        ("T\nE\nU\nNPTS= 3, DT= .01 SEC\n0.1 0.2\n", 6),  # too few values: the line after
        ("T\nE\nU\nNPTS= 1, DT= .01 SEC\n0.1\n0.2\n", 6),  # too many
    ],
)
def test_malformed_at2_raises_with_the_line(text, line):
    with pytest.raises(aemstep.MalformedRecord) as e:
        aemstep.read_at2(text)
    assert e.value.line == line
    assert isinstance(e.value, aemstep.AemstepError)
    assert f"(line {line})" in str(e.value)


def test_malformed_column_raises_with_the_line():
    with pytest.raises(aemstep.MalformedRecord) as e:
        aemstep.read_column("0.1\n0.2 0.3\n", 0.01)
    assert e.value.line == 2
    with pytest.raises(aemstep.MalformedRecord):
        aemstep.read_column("# nothing\n\n", 0.01)
    with pytest.raises(aemstep.InvalidTimeStep):
        aemstep.read_column("0.1\n", 0.0)


def test_missing_file_is_an_os_error():
    with pytest.raises(FileNotFoundError):
        aemstep.read_at2(ROOT / "data" / "no-such-record.AT2")
