"""Text helpers shared by the scene readers: lines with their numbers, number tokens checked
before numpy parses a block, homogeneous patches from Cartesian rows (docs/design.md section 2).
Every problem is a :class:`~cltess.scene.SceneError` naming the file and the 1-based line."""
from __future__ import annotations

import math
import os
import re
import warnings
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np

from ..scene import SceneError, check_scene_file
from . import decimal

INT32_MAX = 2**31 - 1

# Characters a numeric block may hold; anything else sends the block to the slow
# line-by-line diagnosis (numpy would accept "1_0", "nan" or non-ASCII digits).
_FLOAT_BLOCK_BAD = re.compile(r"[^0-9eE.+\-,\s]")
_INDEX_BLOCK_BAD = re.compile(r"[^0-9+\-,\s]")
# re.ASCII: \d alone would take any Unicode digit ("\uff11"), which float() and int() accept too.
_FLOAT_TOKEN = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)
_NONFINITE_TOKEN = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE | re.ASCII)
_INT_TOKEN = re.compile(r"[+-]?\d+", re.ASCII)


class _Lines:
    """The non-blank lines of a text file with their 1-based line numbers."""

    def __init__(self, name: str, text: str):
        self.name = name
        raw = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")  # lines as editors count them (not at \f, \x1c, ...)
        self.numbers = [k for k, line in enumerate(raw, 1) if line and not line.isspace()]
        self.texts = [raw[k - 1] for k in self.numbers]

    @staticmethod
    def read(path) -> "_Lines":
        return _Lines(str(path), _read_text(path))

    def __len__(self) -> int:
        return len(self.texts)

    def error(self, k: int, what: str) -> SceneError:
        """An error at non-blank line ``k`` (0-based position in ``texts``)."""
        return SceneError(f"{self.name}: line {self.numbers[k]}: {what}")

    def count(self, k: int, what: str, per_item: int, after: int) -> int:
        """Parse the count on line ``k``: a positive integer whose ``per_item`` lines each,
        plus ``after`` more lines, fit in the lines that follow (checked before any allocation)."""
        tokens = self.texts[k].split()
        if len(tokens) != 1 or not _INT_TOKEN.fullmatch(tokens[0]):
            raise self.error(k, f"expected the {what} count (one integer), got {self.texts[k].strip()[:60]!r}")
        n = _clamped_int(tokens[0])
        if n <= 0:
            raise self.error(k, f"{what} count is {n}; need at least one")
        left = len(self) - k - 1
        if n > (left - after) // per_item:
            raise self.error(
                k,
                f"{what} count {n} needs {n * per_item + after} more lines but only {left} follow "
                f"(file truncated, or the count is wrong)",
            )
        return n

    def no_trailing(self, k: int, what: str) -> None:
        if k < len(self):
            raise self.error(k, f"unexpected content after the last {what}: {self.texts[k].strip()[:60]!r}")


def _read_text(path) -> str:
    return _decode(path, _read_bytes(path))


def _read_bytes(path) -> bytes:
    check_scene_file(path)
    try:
        return Path(path).read_bytes()
    except FileNotFoundError:
        raise SceneError(f"{path}: file not found") from None
    except OSError as exc:
        raise SceneError(f"{path}: cannot read: {exc.strerror or exc}") from None


def _decode(path, data: bytes) -> str:
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data[: exc.start].count(b"\n") + 1
        raise SceneError(f"{path}: line {line}: not UTF-8 text (byte {exc.start})") from None
    text = text.removeprefix("\ufeff")  # a byte-order mark, as some Windows editors write
    if not text.strip():
        raise SceneError(f"{path}: empty file")
    return text


def _clamped_int(token: str) -> int:
    """An ASCII integer token (``_INT_TOKEN``) as an int clamped to +-2**62, without converting
    thousands of digits (which Python refuses above sys.get_int_max_str_digits())."""
    token = token.strip()
    digits = token.lstrip("+-").lstrip("0")
    if len(digits) > 18:
        return -(2**62) if token.startswith("-") else 2**62
    return int(token)


def _token_problem(token: str) -> str | None:
    """Why ``token`` is not a finite float, or None if it is one."""
    token = token.strip()
    if _FLOAT_TOKEN.fullmatch(token):
        return None if math.isfinite(float(token)) else f"number {token!r} overflows to infinity"
    if _NONFINITE_TOKEN.fullmatch(token):
        return f"non-finite value {token!r}"
    return f"not a number: {token[:40]!r}" if token else "empty value"


def _floats(lines: _Lines, ks, rows: list[list[str]]) -> np.ndarray:
    """Rows of numeric tokens (``rows[r]`` from line position ``ks[r]``, equal lengths) ->
    finite float64 (R, C).  Fast path: one numpy conversion; on any doubt, find the first bad
    line for the message."""
    block = "\n".join(lines.texts[k] for k in ks)
    if not _FLOAT_BLOCK_BAD.search(block):
        try:
            values = np.array(rows, dtype=np.float64)
        except ValueError:
            pass
        else:
            if np.isfinite(values).all():
                return values
    for k, row in zip(ks, rows):
        for token in row:
            problem = _token_problem(token)
            if problem:
                raise lines.error(k, problem)
    # every token is an ASCII float numpy did not take (e.g. whitespace it does not strip)
    return np.array([[float(token) for token in row] for row in rows], dtype=np.float64)


def _homogeneous(xyzw: np.ndarray) -> np.ndarray:
    """(..., 4) Cartesian ``(x, y, z, w)`` -> homogeneous ``(w x, w y, w z, w)`` (docs/design.md section 2)."""
    return np.concatenate([xyzw[..., :3] * xyzw[..., 3:], xyzw[..., 3:]], axis=-1)


def _cartesian_rows(patches: np.ndarray) -> np.ndarray:
    """(..., 4) homogeneous -> (..., 4) Cartesian ``(x, y, z, w)``, -0.0 written as 0.0."""
    w = patches[..., 3:]
    return np.concatenate([patches[..., :3] / w, w], axis=-1) + 0.0


# --- the fast path: a whole file of plain decimal numbers parsed by NumPy ---------------------

_NUMBER_FILE_BYTES = b"0123456789eE.+- \t\n"
_NUMBER_FILE_BYTES_COMMA = _NUMBER_FILE_BYTES + b","


def _byte_set(chars: bytes) -> np.ndarray:
    table = np.zeros(256, bool)
    table[list(chars)] = True
    return table


_DIGITS = _byte_set(b"0123456789")
_COMMA_TO_SPACE = bytes.maketrans(b",", b" ")
#: Bytes per piece the tokens are found and converted in (whole lines): the temporaries of a
#: piece stay in memory the process already has (fresh pages cost more than the work here:
#: bench/RESULTS.md, "Issue 15: the 30k-patch PLY cold and warm (session 8)").
PIECE_BYTES = 1 << 20
#: Most threads the pieces are parsed on (one per core up to this).
PARSE_THREADS = 4


class _Numbers:
    """The tokens of a text file of plain decimal numbers, parsed at once (no Python per token):

    values (N,) float64, every token in file order; lengths (N,) its characters; start (N,)
    its byte offset; per_line (L,) the tokens of each non-blank line and first (L,) the index
    of a line's first token; commas (L,) the commas of each non-blank line (comma files).

    ``_Numbers.of`` returns None for anything unusual (a byte outside ASCII digits, signs,
    ``.``, ``e``, ``E``, spaces, tabs, newlines (and commas); a token that is not one number
    read to its end; a non-finite value): the readers then parse line by line, which
    finds the first problem and names its line.  Values are correctly rounded, as ``float``
    (io/decimal.py).
    """

    def __init__(self, data, values, start, lengths, per_line, commas):
        self.data, self.values, self.start, self.lengths = data, values, start, lengths
        self.per_line, self.commas = per_line, commas
        self.first = np.concatenate(([0], np.cumsum(per_line)[:-1])).astype(np.int64)

    @staticmethod
    def of(data: bytes, commas: bool = False) -> "_Numbers | None":
        if b"\r" in data:  # line ends as _Lines counts them
            data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
        if not data or data.translate(None, _NUMBER_FILE_BYTES_COMMA if commas else _NUMBER_FILE_BYTES):
            return None
        if not decimal.EXTENDED:
            return _Numbers._of_fromstring(data, commas)
        # Outputs sized for the most tokens the bytes can hold: pages no token reaches are
        # never touched (no copy of per-piece parts, and no fresh memory beyond the results).
        most = len(data) // 2 + 1
        values, start, lengths = np.empty(most), np.empty(most, np.int64), np.empty(most, np.int64)
        per_line, commas_per_line = [], []
        count = 0
        # The pieces on threads, one per core, their results copied out in file order: NumPy
        # releases the GIL in nearly all of a piece's work (the 30k-patch scene on two cores:
        # 0.255 s median against 0.301 on one, bench/RESULTS.md "Issue 15: the cold 30k-patch
        # PLY (session 10, branch `ply15d`)").
        with ThreadPoolExecutor(min(PARSE_THREADS, os.cpu_count() or 1)) as pool:
            for part in pool.map(lambda bounds: _piece(data, *bounds, commas), _pieces(data)):
                if part is None:
                    return None
                numbers, begin, end, lines, comma_lines = part
                values[count:count + len(numbers)] = numbers
                start[count:count + len(numbers)] = begin
                lengths[count:count + len(numbers)] = end - begin
                count += len(numbers)
                per_line.append(lines)
                commas_per_line.append(comma_lines)
        values, start, lengths, per_line = values[:count], start[:count], lengths[:count], np.concatenate(per_line)
        if not count or not np.isfinite(values).all():
            return None
        lines = np.flatnonzero(per_line)
        if commas:
            commas_per_line = np.concatenate(commas_per_line)
            if commas_per_line[per_line == 0].any():  # a comma on a line of no token
                return None
            commas_per_line = commas_per_line[lines]
        return _Numbers(np.frombuffer(data, np.uint8), values, start, lengths, per_line[lines],
                        commas_per_line if commas else None)

    @staticmethod
    def _of_fromstring(data: bytes, commas: bool) -> "_Numbers | None":
        """The same without an x87 long double (io/decimal.py EXTENDED): ``np.fromstring``
        (strtod token after token) for the values."""
        start, end, newlines, comma = _tokens(data, commas)
        if not len(start):
            return None
        # strtod token after token: a token it cannot read to its end leaves a remainder that is
        # either unreadable (NumPy stops: an error, or a warning made one) or read as one more
        # number (then there are more values than tokens).  Equal counts and no stop: every
        # token was one number, read in full.
        text = data.translate(_COMMA_TO_SPACE) if commas else data
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                values = np.fromstring(text, dtype=np.float64, sep=" ")
        except (ValueError, DeprecationWarning):
            return None
        if len(values) != len(start) or not np.isfinite(values).all():
            return None
        per_line = np.bincount(np.searchsorted(newlines, start))
        lines = np.flatnonzero(per_line)
        commas_per_line = None
        if commas:
            commas_per_line = np.bincount(np.searchsorted(newlines, comma), minlength=len(per_line))
            if len(commas_per_line) > len(per_line) or commas_per_line[per_line == 0].any():
                return None  # a comma on a line of no token
            commas_per_line = commas_per_line[lines]
        return _Numbers(np.frombuffer(data, np.uint8), values, start, end - start, per_line[lines], commas_per_line)

    def integer_token(self, k: int) -> int | None:
        """Token k as a positive integer if it is plain digits (at most 18), else None."""
        begin, size = int(self.start[k]), int(self.lengths[k])
        if size > 18 or not _DIGITS[self.data[begin:begin + size]].all():
            return None
        return int(self.values[k])

    def only(self, table: np.ndarray, first_line: int, last_line: int) -> bool:
        """Whether the characters of non-blank lines first_line .. last_line - 1 are all in table."""
        if last_line <= first_line:
            return True
        begin = int(self.start[self.first[first_line]])
        end_token = self.first[last_line - 1] + self.per_line[last_line - 1] - 1
        end = int(self.start[end_token] + self.lengths[end_token])
        return bool(table[self.data[begin:end]].all())


def _pieces(data: bytes):
    """(offset, end) of each piece of whole lines of about PIECE_BYTES."""
    offset = 0
    while offset < len(data):
        cut = data.find(b"\n", offset + PIECE_BYTES) + 1 or len(data)
        yield offset, cut
        offset = cut


def _piece(data: bytes, offset: int, cut: int, commas: bool):
    """The tokens of ``data[offset:cut]`` (whole lines): (values, start, end) in ``data``'s
    offsets, and the tokens (commas) on each physical line, the last slot a line the next piece
    goes on; None if a token is not one number (``decimal.parse_decimals``)."""
    piece = data[offset:cut]
    begin, end, newlines, comma = _tokens(piece, commas)
    numbers = decimal.parse_decimals(piece, begin, end)
    if numbers is None:
        return None
    # a token's line: the newlines before it (a binary search among them)
    lines = np.bincount(np.searchsorted(newlines, begin), minlength=len(newlines) + 1)
    comma_lines = np.bincount(np.searchsorted(newlines, comma), minlength=len(newlines) + 1) if commas else None
    return numbers, begin + offset, end + offset, lines, comma_lines


def _tokens(text: bytes, commas: bool):
    """Token offsets of a text of number bytes (_NUMBER_FILE_BYTES): start (N,) and end (N,
    exclusive); the offsets of its newlines and (comma files) of its commas."""
    chars = np.frombuffer(text, np.uint8)
    gap = chars <= 32  # space, tab, newline: the only such bytes here
    comma = None
    if commas:
        comma = np.flatnonzero(chars == 44)
        gap[comma] = True
    begins = np.empty(len(chars), bool)  # a gap, then a token byte
    begins[0] = not gap[0]
    np.greater(gap[:-1], gap[1:], out=begins[1:])
    ends = np.empty(len(chars), bool)  # a token byte, then a gap (or the end)
    ends[-1] = not gap[-1]
    np.less(gap[:-1], gap[1:], out=ends[:-1])
    return np.flatnonzero(begins), np.flatnonzero(ends) + 1, np.flatnonzero(chars == 10), comma
