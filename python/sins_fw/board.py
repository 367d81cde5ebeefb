"""Drive the emulated board register by register, as a driver does: write and read the F28335
SPI-A registers, LOSPCP and the GPIO data registers (GPIO57 is the ADIS16407's chip select), let
virtual time pass, and read the transaction log (frames with DIN/DOUT and their SCLK edges, CS edges)
and the events, each tied to its frame. The device has the profile's sensor errors (``errors.*``)
and faults (``faults.*``).

    board = Board("reference")
    board.init_spi()                      # the published InitSpi writes, from the profile
    board.configure_spi(sclk_hz=1e6, mode=3)
    board.set_gpio57(False)               # CS low
    word = board.transfer(0x5600)         # read PROD_ID: its value comes in the next frame
    prod_id = board.transfer(0x0000, stall_s=10e-6)   # 0x4017
    board.set_gpio57(True)

The same board is reachable from C through the C ABI (``rust/cabi``, docs/c-drivers.md).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from sins_fw import _core
from sins_fw.profile import Profile, load_profile


class Board:
    """SPI-A, GPIO57 and the ADIS16407 of a profile, at virtual time :attr:`now_s` (starts at 0, SPI-A
    in its reset state until :meth:`init_spi`). ``overrides`` are ``key=value`` strings; one string
    is one override."""

    def __init__(self, profile: Profile | str = "reference", overrides: Sequence[str] | str = ()) -> None:
        prof = profile if isinstance(profile, Profile) else load_profile(profile)
        if isinstance(overrides, str):
            overrides = (overrides,)
        self.profile = prof.with_overrides(*overrides) if overrides else prof
        self._core = _core.Board(self.profile.text, self.profile.source, list(self.profile.overrides))

    @property
    def now_s(self) -> float:
        return float(self._core.now_s)

    @property
    def lspclk_hz(self) -> float:
        return float(self._core.lspclk_hz)

    def advance(self, seconds: float) -> None:
        """Let virtual time pass. A negative step that rounds to no time (a float rounding residue)
        is no step; a real step back raises :class:`~sins_fw.errors.TraceError`."""
        self._core.advance(float(seconds))

    def advance_to(self, t_s: float) -> None:
        """Move virtual time to ``t_s`` seconds since power-on (not before now)."""
        self._core.advance_to(float(t_s))

    def init_spi(self) -> None:
        """The published InitSpi: SPICCR (in reset), SPICTL, SPIBRR, SPICCR (released), SPIPRI."""
        self._core.init_spi()

    def configure_spi(self, sclk_hz: float | None = None, mode: int | None = None) -> dict[str, Any]:
        """Ask for an SCLK in Hz (exact, or the nearest below that SPIBRR can give from LSPCLK) and/or
        a standard SPI mode 0…3 (SPICCR.CLKPOLARITY, SPICTL.CLK_PHASE). Returns what was set:
        ``spibrr``, ``sclk_hz`` (achieved), ``exact``, ``mode``, ``lspclk_hz``. An impossible request
        raises :class:`~sins_fw.errors.ConfigError` naming the register (SPIBRR, LOSPCP)."""
        return dict(self._core.configure_spi(sclk_hz, mode))

    def write(self, register: str, value: int) -> None:
        """Write a register by name (SPICCR, SPITXBUF, …, LOSPCP, GPBSET, …); a value outside the
        register's width raises :class:`~sins_fw.errors.RegisterError`."""
        self._core.write(register, int(value))

    def read(self, register: str) -> int:
        """Read a register by name (reading SPIRXBUF clears INT_FLAG, as on the chip)."""
        return int(self._core.read(register))

    def write_address(self, address: int, value: int) -> None:
        """Write the 16-bit word at a C28x data address."""
        self._core.write_address(int(address), int(value))

    def read_address(self, address: int) -> int:
        """Read the 16-bit word at a C28x data address."""
        return int(self._core.read_address(int(address)))

    def set_gpio57(self, high: bool) -> None:
        """Drive the chip select (through GPBSET/GPBCLEAR): ``False`` asserts it."""
        self._core.set_gpio57(bool(high))

    def set_physical(
        self,
        gyro_dps: Sequence[float],
        accel_g: Sequence[float],
        *,
        mag_gauss: Sequence[float] | None = None,
        baro_mbar: float | None = None,
        temp_c: float | None = None,
        supply_v: float | None = None,
    ) -> None:
        """What the sensor sees from now on (held constant)."""
        mag = None if mag_gauss is None else np.asarray(mag_gauss, dtype=np.float64)
        gyro, accel = np.asarray(gyro_dps, dtype=np.float64), np.asarray(accel_g, dtype=np.float64)
        self._core.set_physical(gyro, accel, mag, baro_mbar, temp_c, supply_v)

    def transfer(self, din: int, stall_s: float = 0.0) -> int:
        """One frame as a polling driver does it (an Arduino-style ``transfer16``): wait ``stall_s``
        (the ADIS16407 wants ≥ 9 µs between normal frames, one SCLK period inside a burst), wait for
        BUFFULL = 0, write SPITXBUF, wait for INT_FLAG, read SPIRXBUF, and return no sooner than the
        device's tSFS after the frame's last SCLK edge, so that CS may rise at once in every mode.
        Returns the received word."""
        return int(self._core.transfer(int(din), float(stall_s)))

    def peek_device(self, address: int) -> int:
        """An ADIS16407 register's contents without SPI traffic."""
        return int(self._core.peek_device(int(address)))

    def take_log(self) -> list[dict[str, Any]]:
        """Frames and CS edges since the last call, in time order."""
        return list(self._core.take_log())

    def take_events(self) -> list[dict[str, Any]]:
        """Events (rule violations, …) since the last call, in time order; ``frame`` and ``din`` tie
        each to its frame in :meth:`take_log` (None when it concerns none)."""
        return list(self._core.take_events())
