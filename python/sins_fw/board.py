"""Drive the emulated board register by register, as firmware does: write and read the F28335
SPI-A registers, drive GPIO57 (the ADIS16407's chip select), let virtual time pass, and read the
transaction log (frames with DIN/DOUT and their SCLK edges, CS edges) and the events.

    board = Board("reference")
    board.init_spi()                      # the published InitSpi writes, from the profile
    board.set_gpio57(False)               # CS low
    word = board.transfer(0x5600)         # read PROD_ID: its value comes in the next frame
    prod_id = board.transfer(0x0000)      # 0x4017
    board.set_gpio57(True)
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from sins_fw import _core
from sins_fw.errors import ConfigError
from sins_fw.profile import Profile, load_profile

#: Polling granularity of `transfer`: how often it looks at SPISTS, s (one LSPCLK-scale step).
POLL_S = 100e-9


class Board:
    """SPI-A, GPIO57 and the ADIS16407 of a profile, at virtual time :attr:`now_s` (starts at 0, SPI-A
    in its reset state until :meth:`init_spi`)."""

    def __init__(self, profile: Profile | str = "reference", overrides: Sequence[str] = ()) -> None:
        prof = profile if isinstance(profile, Profile) else load_profile(profile)
        self.profile = prof.with_overrides(*overrides) if overrides else prof
        self._args = (self.profile.text, self.profile.source, list(self.profile.overrides))
        self._core = _core.Board(*self._args)

    @property
    def now_s(self) -> float:
        return float(self._core.now_s)

    def advance(self, seconds: float) -> None:
        """Let virtual time pass."""
        self._core.advance(float(seconds))

    def init_spi(self) -> None:
        """The published InitSpi: SPICCR (in reset), SPICTL, SPIBRR, SPICCR (released), SPIPRI."""
        self._core.init_spi(*self._args)

    def write(self, register: str, value: int) -> None:
        """Write an SPI-A register by name (SPICCR, SPITXBUF, …)."""
        self._core.write(register, int(value))

    def read(self, register: str) -> int:
        """Read an SPI-A register by name (reading SPIRXBUF clears INT_FLAG, as on the chip)."""
        return int(self._core.read(register))

    def set_gpio57(self, high: bool) -> None:
        """Drive the chip select: ``False`` asserts it."""
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

    def transfer(self, din: int, stall_s: float = 0.0, timeout_s: float = 1e-3) -> int:
        """One frame as polling firmware does it: wait ``stall_s`` (the ADIS16407 wants ≥ 9 µs between
        normal frames and one SCLK period inside a burst), wait for BUFFULL = 0, write SPITXBUF, wait
        for INT_FLAG, read SPIRXBUF. Returns the received word; virtual time moves to the read."""
        if stall_s:
            self.advance(stall_s)
        self._wait(lambda: not self.read("SPISTS") & 0x20, timeout_s, "BUFFULL_FLAG = 0")
        self.write("SPITXBUF", din)
        flag = self._core.int_flag_time_s()
        if flag is None:
            raise ConfigError(
                "SPI-A started no character: is it released from reset (SPICCR bit 7) and master?"
            )
        if flag > self.now_s:
            self.advance(flag - self.now_s)
        self._wait(lambda: bool(self.read("SPISTS") & 0x40), timeout_s, "INT_FLAG = 1")
        return self.read("SPIRXBUF")

    def _wait(self, ready: Any, timeout_s: float, what: str) -> None:
        waited = 0.0
        while not ready():
            if waited > timeout_s:
                raise ConfigError(f"waited {timeout_s * 1e3:.3f} ms for {what} at {self.now_s:.9f} s")
            self.advance(POLL_S)
            waited += POLL_S

    def peek_device(self, address: int) -> int:
        """An ADIS16407 register's contents without SPI traffic."""
        return int(self._core.peek_device(int(address)))

    def take_log(self) -> list[dict[str, Any]]:
        """Frames and CS edges since the last call, in time order."""
        return list(self._core.take_log())

    def take_events(self) -> list[dict[str, Any]]:
        """Events (rule violations, …) since the last call, in time order."""
        return list(self._core.take_events())
