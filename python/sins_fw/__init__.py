"""sins-fw: a firmware-in-the-loop emulator of a TMS320F28335 + ADIS16407 strapdown attitude board.

``sins_fw.emulate(trace, profile="reference", **overrides) -> Run`` runs the board on a trace;
keyword overrides use ``__`` for the dot of a profile key (``spi__spibrr=9`` is ``spi.spibrr=9``),
and ``overrides=["key=value", ...]`` takes them as texts.
"""

from __future__ import annotations

from sins_fw import errors
from sins_fw._core import __version__
from sins_fw.harness import Run, emulate
from sins_fw.profile import Profile, load_profile

__all__ = ["Profile", "Run", "__version__", "emulate", "errors", "load_profile"]
