"""ADIS16407 output words: physical value ↔ 16-bit register word, exactly as the device model does.

Channels: ``gyro`` (14-bit two's complement; LSB 0.05 / 0.025 / 0.0125 °/s at ±300 / ±150 / ±75),
``accel`` (14-bit, 3.333 mg), ``mag`` (14-bit, 0.5 mgauss), ``supply`` (12-bit unsigned, 2.418 mV),
``temp`` (12-bit two's complement, 0.136 °C, 0 = 25 °C), ``baro`` (14-bit unsigned, 0.08 mbar),
``baro_low`` (BARO_OUTL's 8 bits), ``aux`` (12-bit unsigned, 0.806 mV). Values beyond a field's
limits saturate and report ``overrange``. Bit 15 of a word is ND (new data), bit 14 EA (an error
flag in DIAG_STAT); decoding ignores them in the value and returns them.
"""

from __future__ import annotations

from typing import NamedTuple

from sins_fw import _core


class Encoded(NamedTuple):
    word: int
    overrange: bool


class Decoded(NamedTuple):
    value: float
    nd: bool
    ea: bool


def encode(channel: str, value: float, range_dps: float = 300) -> Encoded:
    """The output code of ``value`` (in the channel's unit) with the gyro range ``range_dps``."""
    word, over = _core.encode(channel, float(value), float(range_dps))
    return Encoded(word, over)


def decode(channel: str, word: int, range_dps: float = 300) -> Decoded:
    """The value of an output word, and its ND and EA flags."""
    value, nd, ea = _core.decode(channel, int(word), float(range_dps))
    return Decoded(value, nd, ea)
