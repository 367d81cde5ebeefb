"""sins-fw: a firmware-in-the-loop emulator of a TMS320F28335 + ADIS16407 strapdown attitude board.

``sins_fw.emulate(trace, profile="reference", **overrides) -> Run`` runs the board on a trace;
keyword overrides use ``__`` for the dot of a profile key (``spi__spibrr=9`` is ``spi.spibrr=9``),
and ``overrides=["key=value", ...]`` takes them as texts.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

from sins_fw import errors

if TYPE_CHECKING:
    from sins_fw._core import __version__
    from sins_fw.harness import Run, emulate
    from sins_fw.profile import Profile, load_profile

__all__ = ["Profile", "Run", "__version__", "emulate", "errors", "load_profile"]

#: Imported on first use (PEP 562), so that ``import sins_fw.launch`` loads neither numpy nor the
#: extension before it has fitted the process to a memory cap (sins_fw.launch).
_LAZY = {
    "__version__": "sins_fw._core",
    "Run": "sins_fw.harness",
    "emulate": "sins_fw.harness",
    "Profile": "sins_fw.profile",
    "load_profile": "sins_fw.profile",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'sins_fw' has no attribute {name!r}")
