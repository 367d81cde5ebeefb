"""sins-fw: a firmware-in-the-loop emulator of a TMS320F28335 + ADIS16407 strapdown attitude board."""

from __future__ import annotations

from sins_fw import errors
from sins_fw._core import __version__
from sins_fw.profile import Profile, load_profile

__all__ = ["Profile", "__version__", "errors", "load_profile"]
