"""io/decimal.py: decimal tokens to float64 in NumPy, bitwise Python's ``float`` (its reference),
and the text parser built on it (io/text.py ``_Numbers``) piece by piece (issue 15)."""
from decimal import Decimal

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cltess.io import bez, bpt, decimal, text
from cltess.scene import SceneError

pytestmark = pytest.mark.skipif(not decimal.EXTENDED, reason="no x87 long double: np.fromstring is used")


def parse(words):
    """parse_decimals of the words joined by spaces, against float() of each word."""
    data = (" ".join(words) + "\n").encode()
    start, end, _, _ = text._tokens(data, False)
    return decimal.parse_decimals(data, start, end)


def assert_as_float(words):
    got = parse(words)
    want = np.array([float(word) for word in words])
    bad = np.flatnonzero(got.view(np.uint64) != want.view(np.uint64))
    assert not len(bad), [(words[k], got[k], want[k]) for k in bad[:5]]


def test_random_doubles_written_every_way(rng):
    values = (rng.normal(size=20000) * 10.0 ** rng.integers(-40, 40, 20000)).tolist()
    digits = rng.integers(1, 26, 20000).tolist()
    words = [repr(v) for v in values] + [f"{v:.{p}g}" for v, p in zip(values, digits)] \
        + [f"{v:.{p}e}" for v, p in zip(values, digits)] + [f"{v:.{p % 20}f}" for v, p in zip(values, digits)]
    assert_as_float(words)


def test_exact_midpoints_round_to_even(rng):
    """Decimals exactly halfway between two neighbouring doubles (the extended result is then
    a midpoint: the token goes to float), and just beside them."""
    words = []
    for v in (rng.normal(size=3000) * 10.0 ** rng.integers(-20, 20, 3000)).tolist():
        middle = (Decimal(v) + Decimal(float(np.nextafter(v, np.inf)))) / 2
        words += [str(middle), str(middle.next_plus()), str(middle.next_minus()), f"{middle:.18e}"]
    assert_as_float(words)


def test_limits_of_the_fast_path():
    words = ["0", "-0", "+0.0", "-0.0e0", "0e999", "5.", ".5", "+.5", "-5.e-3", "1E5", "1e+05", "1e-0005",
             "9" * 19, "9" * 20, "1" + "0" * 30, "0." + "0" * 30 + "1", "0" * 40 + "1.5",
             "1e27", "1e28", "123456789e-27", "123456789e-28", "1e22", "1e23", "9007199254740993",
             "1.7976931348623157e308", "2.2250738585072014e-308", "4.9e-324", "1e-400", "1e400",
             "12345678901234567890123", "1.00000000000000011102230246251565404236316680908203125"]
    assert_as_float(words)


@settings(max_examples=300, deadline=None)
@given(st.from_regex(r"[+-]?([0-9]{1,25}(\.[0-9]{0,25})?|\.[0-9]{1,25})([eE][+-]?[0-9]{1,5})?", fullmatch=True))
def test_any_decimal_token(token):
    assert_as_float([token, token])


@pytest.mark.parametrize("token", ["1-2", "1e5.2", "1.2.3", "--1", "1e", "+", ".", "e5", "1e5e5", "+-1",
                                   "1e+", "1-", "-.", ".e1", "1e-+2", "1.-2", "E", "1eE2"])
def test_tokens_that_are_no_number(token):
    assert parse(["1.5", token, "2"]) is None


def test_powers_of_ten_are_exact():
    for k, power in enumerate(decimal.POWERS_OF_TEN):
        assert power.as_integer_ratio() == (10**k, 1)


def test_constants():
    assert decimal.MAX_EXACT_POWER == 27 and 5**27 < 2**64 < 5**28
    assert decimal._DIGIT_VALUES == bytes(b - 48 if 48 <= b <= 57 else 0 for b in range(256))
    words = np.frombuffer(bytes(range(1, 9)) * 9, np.uint64)
    for k, mask in enumerate(decimal._LAST_BYTES):
        assert (words & mask).tobytes()[:8] == bytes(8 - k) + bytes(range(9 - k, 9))
    assert (decimal._eight_digits(np.frombuffer(bytes([1, 2, 3, 4, 5, 6, 7, 8]), np.uint64)) == 12345678).all()


def test_midpoint_test_against_its_definition(rng):
    """float64_midpoints (the low 11 significand bits) against its definition: the extended
    value is the mean of the float64 nearest to it and a neighbour of that."""
    doubles = rng.normal(size=30000) * 10.0 ** rng.integers(-40, 40, 30000)
    wide = doubles.astype(np.longdouble)
    above = np.nextafter(doubles, np.inf).astype(np.longdouble)
    values = np.concatenate([wide, (wide + above) / 2, wide * (1 + np.longdouble(2.0**-60) * rng.integers(1, 2**8, 30000)),
                             (wide + above) / 2 + np.longdouble(2.0**-63) * wide])
    rounded = values.astype(np.float64)
    near = rounded.astype(np.longdouble)
    below, above = (np.nextafter(rounded, side).astype(np.longdouble) for side in (-np.inf, np.inf))
    midpoint = (values == (near + below) / 2) | (values == (near + above) / 2)
    assert (decimal.float64_midpoints(values) == midpoint).all()
    assert midpoint.sum() >= 30000 and (~midpoint).sum() >= 60000


def numbers_fields(numbers):
    return [numbers.values.tobytes(), numbers.start.tolist(), numbers.lengths.tolist(), numbers.per_line.tolist(),
            None if numbers.commas is None else numbers.commas.tolist()]


@pytest.mark.parametrize("commas", [False, True])
def test_pieces_and_fromstring_give_the_same_numbers(monkeypatch, rng, commas):
    """Tokens found piece by piece (any piece size) and converted here are np.fromstring's."""
    separator = "," if commas else " "
    lines = [separator.join(repr(v) for v in rng.normal(size=rng.integers(1, 6)).tolist()) for _ in range(300)]
    data = ("\n".join(lines[:100]) + "\n\n  \n" + "\n".join(lines[100:]) + "\n").encode()
    whole = text._Numbers.of(data, commas)
    assert whole is not None
    reference = text._Numbers._of_fromstring(data, commas)
    assert numbers_fields(whole) == numbers_fields(reference)
    for piece in (1, 7, 64, 1000):
        monkeypatch.setattr(text, "PIECE_BYTES", piece)
        assert numbers_fields(text._Numbers.of(data, commas)) == numbers_fields(reference)
    monkeypatch.setattr(decimal, "EXTENDED", False)
    assert numbers_fields(text._Numbers.of(data, commas)) == numbers_fields(reference)


def test_a_comma_on_a_line_of_no_token_is_refused(monkeypatch):
    monkeypatch.setattr(text, "PIECE_BYTES", 4)
    assert text._Numbers.of(b"1,2\n,\n3\n", True) is None
    assert text._Numbers._of_fromstring(b"1,2\n,\n3\n", True) is None
    assert text._Numbers.of(b"1,2\n3,\n", True) is not None


def test_a_bad_token_in_a_later_piece_is_reported_at_its_line(tmp_path, monkeypatch, rng):
    monkeypatch.setattr(text, "PIECE_BYTES", 256)
    path = tmp_path / "p.bpt"
    patches = rng.normal(size=(20, 4, 4, 4))
    patches[..., 3] = 1.0
    bpt.write(path, patches)
    assert bpt.read(path).patches.tobytes() == np.asarray(patches, np.float64).tobytes()
    lines = path.read_text().splitlines()
    lines[300] = lines[300].replace(".", "..", 1)
    path.write_text("\n".join(lines) + "\n")
    assert bpt._fast_bpt(path.read_bytes()) is None
    with pytest.raises(SceneError, match="line 301"):
        bpt.read(path)


def test_bez_files_read_the_same_piece_by_piece(tmp_path, monkeypatch, rng):
    patches = rng.normal(size=(30, 4, 4, 4))
    patches[..., 3] = rng.uniform(0.5, 2.0, size=(30, 4, 4))
    path = tmp_path / "p.bez"
    bez.write(path, patches)
    whole = bez._fast_bez(path.read_bytes())
    monkeypatch.setattr(text, "PIECE_BYTES", 100)
    assert whole is not None and bez._fast_bez(path.read_bytes()).tobytes() == whole.tobytes()


@pytest.mark.parametrize("commas", [False, True])
def test_pieces_on_threads_finishing_in_any_order_give_the_serial_numbers(monkeypatch, rng, commas):
    """The pieces parse on threads (text.PARSE_THREADS): pieces made to finish out of order
    (random delays) give bitwise what one thread gives, and a bad token in any piece makes the
    whole text None (the line-by-line reader then names its line)."""
    import threading
    import time

    separator = "," if commas else " "
    lines = [separator.join(repr(v) for v in rng.normal(size=rng.integers(1, 6)).tolist()) for _ in range(400)]
    data = ("\n".join(lines) + "\n").encode()
    monkeypatch.setattr(text, "PIECE_BYTES", 200)
    monkeypatch.setattr(text, "PARSE_THREADS", 1)
    serial = numbers_fields(text._Numbers.of(data, commas))
    threads, piece = set(), text._piece

    def late(*args):
        threads.add(threading.get_ident())
        time.sleep(float(rng.uniform(0, 0.003)))
        return piece(*args)

    monkeypatch.setattr(text, "_piece", late)
    monkeypatch.setattr(text, "PARSE_THREADS", 4)
    monkeypatch.setattr(text.os, "cpu_count", lambda: 4)
    assert numbers_fields(text._Numbers.of(data, commas)) == serial
    assert len(threads) > 1
    for line in (0, 150, 399):
        bad = lines.copy()
        bad[line] = bad[line].replace(".", "..", 1)
        assert text._Numbers.of(("\n".join(bad) + "\n").encode(), commas) is None


def test_a_bad_token_in_any_piece_on_threads_is_reported_at_its_line(tmp_path, monkeypatch, rng):
    """The same file, a bad token on each of a few lines in turn: the error names its line
    whichever thread's piece holds it."""
    monkeypatch.setattr(text, "PIECE_BYTES", 128)
    monkeypatch.setattr(text.os, "cpu_count", lambda: 4)
    path = tmp_path / "p.bpt"
    patches = rng.normal(size=(12, 4, 4, 4))
    patches[..., 3] = 1.0
    bpt.write(path, patches)
    lines = path.read_text().splitlines()
    for line in (3, 100, 150, len(lines) - 1):
        bad = lines.copy()
        bad[line] = bad[line].replace(".", "e.", 1)
        path.write_text("\n".join(bad) + "\n")
        with pytest.raises(SceneError, match=f"p.bpt: line {line + 1}: "):
            bpt.read(path)
