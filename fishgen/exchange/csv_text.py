"""CSV text of packed particle records, formatted with array operations instead of row by row."""
from __future__ import annotations

import io

import numpy as np


def format_csv_rows(rec: np.ndarray) -> bytes:
    """CSV lines for a structured array: floats as ``%.9g``, integers as ``%d``.

    Every field is laid out in a fixed number of byte slots (0 = no character),
    the slots of a whole block are filled column by column with array operations,
    and the 0 bytes are dropped at the end, so no Python code runs per row.
    Blocks holding NaN or infinity (never produced by the fill), or floats other than
    float32, use ``%``-formatting.
    """
    names: tuple[str, ...] = rec.dtype.names or ()
    floats = [n for n in names if rec.dtype[n].kind == "f"]
    if any(rec.dtype[n] != np.float32 or not np.isfinite(rec[n]).all() for n in floats):
        return _format_slowly(rec)
    widths = [_FLOAT_SLOTS if rec.dtype[n].kind == "f" else _INT_DIGITS[rec.dtype[n].itemsize] + 2
              for n in names]
    slots = np.zeros((len(rec), sum(widths)), np.uint8)
    at = 0
    for k, (name, width) in enumerate(zip(names, widths, strict=True)):
        part = slots[:, at:at + width]
        (_float_slots if rec.dtype[name].kind == "f" else _int_slots)(rec[name], part)
        part[:, -1] = ord("\n") if k == len(names) - 1 else ord(",")
        at += width
    return slots.tobytes().translate(None, b"\0")  # drop the unused slots, at memory speed


def _format_slowly(rec: np.ndarray) -> bytes:
    fmt = ",".join("%.9g" if rec.dtype[n].kind == "f" else "%d" for n in rec.dtype.names or ())
    text = io.StringIO()
    np.savetxt(text, rec, fmt=fmt)
    return text.getvalue().encode("ascii")


_ZERO, _POINT, _MINUS = ord("0"), ord("."), ord("-")
_BIAS = 64                                                            # float32: 1e-45 to 3e38
_POWERS = np.array([float(f"1e{k}") for k in range(-_BIAS, _BIAS)])  # 10.0**k, correctly rounded
_POW10 = 10 ** np.arange(20, dtype=np.uint64)[::-1]                   # 1e19 ... 1e0
_GROUPS = np.array([[ord(c) for c in f"{i:03d}"] for i in range(1000)], np.uint8)  # "000".."999"
_TRAILING_ZEROS = np.array([3 if i == 0 else len(f"{i:03d}") - len(f"{i:03d}".rstrip("0"))
                            for i in range(1000)], np.int8)
# Float layout: sign, "0." and up to 3 zeros (0.000ddd), 9 digits each followed by a
# possible point, "e", exponent sign, 2 exponent digits, separator.
_FLOAT_SLOTS = 1 + 2 + 3 + 18 + 4 + 1
_DIGIT0 = 6                 # slot of the first significant digit; its point follows it
_EXP = _DIGIT0 + 18         # "e", sign, tens, units
_INT_DIGITS = {1: 3, 2: 6, 4: 12, 8: 21}  # decimal digits by integer byte size (3-digit groups)


def _ascii_digits(values: np.ndarray, count: int) -> np.ndarray:
    """(n, count) ASCII digits of non-negative integers, zero-padded, via 3-digit tables."""
    out = np.empty((len(values), count), np.uint8)
    rest = values
    for at in range(count - 3, -1, -3):
        rest, group = np.divmod(rest, 1000)
        out[:, at:at + 3] = _GROUPS[group]
    return out


def _float_slots(values: np.ndarray, out: np.ndarray) -> None:
    """``"%.9g" % value`` for finite floats, into byte slots (see format_csv_rows)."""
    x = values.astype(np.float64)
    mantissa, exp = _nine_digits(x)
    exp = exp.astype(np.int32)
    high, low = np.divmod(mantissa, 1000)
    high, middle = np.divmod(high, 1000)
    digits = np.empty((len(x), 9), np.uint8)                         # most significant first
    for at, group in enumerate((high, middle, low)):
        digits[:, 3 * at:3 * at + 3] = _GROUPS[group]
    # %g drops trailing zeros: count the significant digits group by group
    used = np.where(low != 0, 9 - _TRAILING_ZEROS[low],
                    np.where(middle != 0, 6 - _TRAILING_ZEROS[middle], 3 - _TRAILING_ZEROS[high]))
    used[mantissa == 0] = 1                                          # the value 0 prints "0"

    fixed = (exp >= -4) & (exp < 9)                                  # %g's choice of notation
    small = fixed & (exp < 0)                                        # 0.000ddd
    whole = fixed & ~small                                           # ddd.ddd or ddd
    shown = np.where(whole, np.maximum(used, exp + 1), used)         # digits written
    point_after = np.where(whole, np.where(used > exp + 1, exp, -1),
                           np.where(~small & (used > 1), 0, -1))

    out[:, 0] = np.where(np.signbit(x), _MINUS, 0)
    if small.any():
        out[:, 1] = np.where(small, _ZERO, 0)
        out[:, 2] = np.where(small, _POINT, 0)
        for j in range(3):
            out[:, 3 + j] = np.where(small & (j < -exp - 1), _ZERO, 0)
    k = np.arange(9, dtype=np.int32)
    digits[k[None, :] >= shown[:, None]] = 0
    out[:, _DIGIT0:_EXP:2] = digits
    out[:, _DIGIT0 + 1:_EXP:2] = (k[None, :] == point_after[:, None]) * np.uint8(_POINT)
    sci = ~fixed
    if sci.any():
        out[:, _EXP] = np.where(sci, ord("e"), 0)
        out[:, _EXP + 1] = np.where(sci, np.where(exp < 0, _MINUS, ord("+")), 0)
        size = np.abs(exp)                                           # float32: at most 45
        out[:, _EXP + 2] = np.where(sci, size // 10 + _ZERO, 0)
        out[:, _EXP + 3] = np.where(sci, size % 10 + _ZERO, 0)


def _nine_digits(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """|x| = mantissa * 10**(exp - 8) rounded to 9 significant digits, as %.9g rounds.

    Float64 arithmetic gets the mantissa right unless the exact value lies within a
    hair of a rounding tie; those few values (and exact ties) are redone with Python's
    correctly rounded ``%.8e``.
    """
    a = np.abs(x)
    zero = a == 0
    a[zero] = 1.0
    # floor(log10(a)) from the binary exponent (cheaper than log10), then one compare
    binary = np.frexp(a)[1].astype(np.int64) - 1                     # a in [2**binary, 2**(binary+1))
    exp = (binary * 78913) >> 18                                     # floor(binary * log10(2))
    exp += a >= _POWERS[exp + 1 + _BIAS]
    scaled = a * _POWERS[8 - exp + _BIAS]
    off = np.where(scaled < 1e8 - 0.5, -1, np.where(scaled >= 1e9 - 0.5, 1, 0))
    if off.any():                                                    # rounded up to 10**9
        exp += off
        scaled = a * _POWERS[8 - exp + _BIAS]
    mantissa = np.rint(scaled)
    doubt = (np.abs(scaled - np.floor(scaled) - 0.5) < 1e-5) | (mantissa < 1e8) | (mantissa >= 1e9)
    mantissa = mantissa.astype(np.int32)                             # 9 digits fit
    for i in np.flatnonzero(doubt & ~zero):                          # ~1 value in 10^5
        text = f"{abs(float(x[i])):.8e}"
        mantissa[i], exp[i] = int(text[0] + text[2:10]), int(text[11:])
    mantissa[zero], exp[zero] = 0, 0
    return mantissa, exp


_BYTE_TEXT = np.array([[ord(c) for c in f"{i:>3}".replace(" ", "\0")] for i in range(256)], np.uint8)


def _int_slots(values: np.ndarray, out: np.ndarray) -> None:
    """``"%d" % value`` for integers, into byte slots (see format_csv_rows)."""
    if values.dtype == np.uint8:                                     # colours: one table lookup
        out[:, 1:4] = _BYTE_TEXT[values]
        return
    count = out.shape[1] - 2
    v = values.astype(np.int64)
    size = np.abs(v)
    if values.dtype.itemsize >= 8:
        size = size.astype(np.uint64)                                # |int64 min| fits uint64
    digits = _ascii_digits(size, count)
    # digits shown: 1 + the number of powers of ten <= size (no leading zeros; 0 prints "0")
    powers = _POW10[-count:][::-1][1:].astype(size.dtype)           # 10, 100, ...
    shown = 1 + np.searchsorted(powers, size, side="right")
    digits[np.arange(count)[None, :] < (count - shown)[:, None]] = 0
    out[:, 0] = np.where(v < 0, _MINUS, 0)
    out[:, 1:1 + count] = digits
