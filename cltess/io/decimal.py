"""Decimal number tokens to float64, all at once in NumPy and correctly rounded: bitwise what
Python's ``float`` gives (issue 15: the 1.5 M coordinates of the 30k-patch ``.bpt`` scene).

A token ``[+-]digits[.digits][(e|E)[+-]digits]`` is the integer ``M`` of its mantissa digits
times ``10**E``.  Where ``M < 10**19`` and ``|E| <= 27`` both ``M`` and ``10**|E|`` are exact in
the x87 extended format (64 significand bits; ``5**27 < 2**64``), so ``M * 10**E`` (or
``M / 10**-E``) is *one* correctly rounded operation (IEEE 754-2008 section 4.3).  Rounding that
to float64 again is the correct rounding of the exact value unless the extended result lies
exactly halfway between two float64 (double rounding, Figueroa 1995): a float64 midpoint has 54
significant bits and is an extended number, so a midpoint strictly between the exact value and
its extended rounding would be nearer to the exact value, which contradicts the rounding.  The
few tokens whose extended result *is* a midpoint (the low 11 of its 64 significand bits
``10000000000``), and any outside those limits, go to ``float`` (David Gay's correctly rounded
conversion).  Design notes: docs/design.md section 9, "The numbers themselves".
"""
from __future__ import annotations

import sys

import numpy as np

#: Whether NumPy's long double is the x87 80-bit extended format (x86 Linux and macOS: 64
#: significand bits, the integer bit explicit, in the low 8 of 16 bytes), which the rounding
#: step relies on; elsewhere (MSVC, ARM: float64 or IEEE quad) ``parse_decimals`` is not used.
EXTENDED = (np.finfo(np.longdouble).nmant == 63 and np.dtype(np.longdouble).itemsize == 16
            and sys.byteorder == "little")

#: Widest mantissa read at once (digits, leading zeros included); wider ones go to ``float``.
MANTISSA_WIDTH = 24
#: Largest |E| whose power of ten is exact in the extended format (5**27 < 2**64 < 5**28).
MAX_EXACT_POWER = 27
#: Most exponent digits read at once ("e-307": 3).
EXPONENT_DIGITS = 4
#: The low 11 significand bits of an extended number that is halfway between two float64.
MIDPOINT_BITS, MIDPOINT_MASK = 1 << 10, (1 << 11) - 1

_LANES_8, _LANES_16 = np.uint64(0x00FF00FF00FF00FF), np.uint64(0x0000FFFF0000FFFF)
#: A mask of a word's last k bytes (its high ones, little-endian), k = 0 .. 8.
_LAST_BYTES = np.array([((1 << 64) - 1) ^ ((1 << (64 - 8 * k)) - 1) for k in range(9)], np.uint64)
_DIGITS_AFTER_WORD = np.array([16, 8, 0])  # of a 24-digit window's three words
#: bytes.translate table: a digit to its value, any other byte to 0.
_DIGIT_VALUES = bytes(range(10)).rjust(ord("9") + 1, b"\0").ljust(256, b"\0")


def _exact_powers_of_ten() -> np.ndarray:
    powers = [np.longdouble(1)]
    for _ in range(MAX_EXACT_POWER):
        powers.append(powers[-1] * np.longdouble(10))  # exact: 10**k = 2**k 5**k, 5**k < 2**64
    return np.array(powers, np.longdouble)


POWERS_OF_TEN = _exact_powers_of_ten()
_E, _DOT, _PLUS, _MINUS, _ZERO = ord("e"), ord("."), ord("+"), ord("-"), ord("0")


def parse_decimals(data: bytes, start: np.ndarray, end: np.ndarray) -> np.ndarray | None:
    """The float64 values of the tokens ``data[start[k]:end[k]]`` (ascending, disjoint, every
    byte of each a digit, ``.``, ``e``, ``E``, ``+`` or ``-``), bitwise ``float(token)``; None
    if a token is not one decimal number (``text._FLOAT_TOKEN``), e.g. ``1-2``, ``1e``, ``.``.
    Requires EXTENDED."""
    count = len(start)
    chars = np.frombuffer(data, np.uint8)
    # Non-digits are few (about one dot a token): the form is checked at their offsets.
    e_at = np.flatnonzero((chars | 32) == _E)  # 'e' or 'E'
    dot_at = np.flatnonzero(chars == _DOT)
    sign_at = np.flatnonzero((chars == _PLUS) | (chars == _MINUS))
    e_token = np.searchsorted(start, e_at, "right") - 1
    dot_token = np.searchsorted(start, dot_at, "right") - 1
    if (np.diff(e_token) == 0).any() or (np.diff(dot_token) == 0).any():
        return None  # two e or two dots in a token
    mantissa_end = end.copy()
    mantissa_end[e_token] = e_at
    if (dot_at > mantissa_end[dot_token]).any():
        return None  # a dot in the exponent
    after_e = np.zeros(len(chars) + 1, bool)
    after_e[e_at + 1] = True
    if not ((start[np.searchsorted(start, sign_at, "right") - 1] == sign_at) | after_e[sign_at]).all():
        return None  # a sign neither first nor right after the e
    first = chars[start]
    signed = (first == _PLUS) | (first == _MINUS)
    has_dot = np.zeros(count, bool)
    has_dot[dot_token] = True
    digits = mantissa_end - start - signed - has_dot
    e_end = end[e_token]
    after = np.minimum(e_at + 1, len(chars) - 1)  # the byte after each e, where the token has one
    exponent_sign = (e_at + 1 < e_end) & ((chars[after] == _PLUS) | (chars[after] == _MINUS))
    exponent_negative = (e_at + 1 < e_end) & (chars[after] == _MINUS)
    exponent_digits = e_end - e_at - 1 - exponent_sign
    if (digits < 1).any() or (exponent_digits < 1).any():
        return None  # a mantissa or an exponent without digits

    exponent = np.zeros(count, np.int64)
    fraction = np.zeros(count, np.int64)
    fraction[dot_token] = mantissa_end[dot_token] - dot_at - 1
    slow = digits > MANTISSA_WIDTH
    if len(e_at):
        value = np.zeros(len(e_at), np.int64)
        for j in range(EXPONENT_DIGITS):  # Horner over at most 4 digits
            more = exponent_digits > j
            at = np.minimum(e_at + 1 + exponent_sign + j, len(chars) - 1)
            value = np.where(more, value * 10 + (chars[at].astype(np.int64) - _ZERO), value)
        value[exponent_negative] *= -1
        exponent[e_token] = value
        slow[e_token[exponent_digits > EXPONENT_DIGITS]] = True
    power = exponent - fraction

    mantissa, too_long = _mantissas(data, mantissa_end, has_dot, digits)
    slow |= too_long | (np.abs(power) > MAX_EXACT_POWER)
    values, ambiguous = _round(mantissa, np.clip(power, -MAX_EXACT_POWER, MAX_EXACT_POWER))
    slow |= ambiguous
    values[first == _MINUS] *= -1
    for k in np.flatnonzero(slow):  # Python's correctly rounded conversion, token by token
        values[k] = float(chars[start[k]:end[k]].tobytes())
    return values


def _mantissas(data, mantissa_end, has_dot, digits):
    """Each token's mantissa digits as one integer (uint64), and where that has more than 19
    significant digits or the mantissa more than MANTISSA_WIDTH digits (the token then goes to
    ``float``).

    In the text with its dots taken out and every byte but a digit read as 0, a mantissa is
    the ``digits`` values before its end: the last 24 before the end read as three
    little-endian words of 8, the bytes before the mantissa masked off, each word's digits
    joined by SWAR (``_eight_digits``) and the three groups of 8 digits joined."""
    padded = np.frombuffer((bytes(MANTISSA_WIDTH) + data).translate(_DIGIT_VALUES, b"."), np.uint8)
    windows = np.ndarray((len(padded) - MANTISSA_WIDTH + 1,), f"V{MANTISSA_WIDTH}", padded, strides=(1,))
    window = mantissa_end - np.cumsum(has_dot)  # dotless[end - WIDTH : end] = padded[window : window + WIDTH]
    words = windows[window].view(np.uint64).reshape(-1, 3).T.copy()  # (3, N): the WIDTH bytes there
    words &= _LAST_BYTES[np.clip(digits - _DIGITS_AFTER_WORD[:, None], 0, 8)]
    high, middle, low = _eight_digits(words)
    mantissa = high * np.uint64(10**16) + middle * np.uint64(10**8) + low
    too_long = (digits > MANTISSA_WIDTH) | (high >= 1000)  # >= 10**19: more than 19 significant digits
    return mantissa, too_long


def _eight_digits(words: np.ndarray) -> np.ndarray:
    """Little-endian words of 8 digit values (first digit in the low byte) -> their number,
    by halves ("SWAR": 10 a + b in 16-bit lanes, 100 a + b in 32-bit lanes, 10**4 a + b)."""
    words = (words & _LANES_8) * np.uint64(10) + ((words >> np.uint64(8)) & _LANES_8)
    words = (words & _LANES_16) * np.uint64(100) + ((words >> np.uint64(16)) & _LANES_16)
    return (words & np.uint64(0xFFFFFFFF)) * np.uint64(10**4) + (words >> np.uint64(32))


def _round(mantissa: np.ndarray, power: np.ndarray):
    """float64 of ``mantissa * 10**power`` (|power| <= MAX_EXACT_POWER) by one extended
    operation, and where that extended result is a float64 midpoint (double rounding may then
    be wrong: module docstring)."""
    exact = mantissa.astype(np.longdouble)
    scale = POWERS_OF_TEN[np.abs(power)]
    scaled = exact / scale
    up = power > 0
    scaled[up] = exact[up] * scale[up]
    return scaled.astype(np.float64), float64_midpoints(scaled)


def float64_midpoints(values: np.ndarray) -> np.ndarray:
    """Which extended (long double) values lie exactly halfway between two float64 (normal
    range): the low 11 of their 64 significand bits are 10000000000."""
    significand = values.view(np.uint64)[0::2]  # x87: the low 8 of 16 bytes
    return (significand & np.uint64(MIDPOINT_MASK)) == MIDPOINT_BITS
