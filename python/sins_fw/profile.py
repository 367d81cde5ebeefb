"""Board and firmware profiles: TOML files in `firmware_model/`, validated by the Rust core.

A profile is named (``reference`` → ``firmware_model/reference.toml``) or given as a path; ``key=value``
overrides change one field for one run. The schema, with units and allowed values, is
``firmware_model/SCHEMA.md``.
"""

from __future__ import annotations

import os
import tomllib
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sins_fw import _core
from sins_fw.errors import ProfileError

#: Where named profiles and data tables live: the folder $SINS_FW_MODEL_DIR names if set, else the
#: package's ``firmware_model`` (a link to the repository's folder in a checkout, a copy in a wheel).
MODEL_DIR = Path(os.environ.get("SINS_FW_MODEL_DIR") or (Path(__file__).parent / "firmware_model").resolve())


def resolve_profile_path(name_or_path: str | os.PathLike[str]) -> Path:
    """The file of a named profile or the path itself; a clear error if neither exists."""
    path = Path(name_or_path)
    if path.suffix == ".toml" or path.exists():
        if not path.is_file():
            raise ProfileError(f"{path}: profile file not found")
        return path
    candidate = MODEL_DIR / f"{name_or_path}.toml"
    if candidate.is_file():
        return candidate
    known = sorted(p.stem for p in MODEL_DIR.glob("*.toml") if _is_profile(p))
    raise ProfileError(f"unknown profile `{name_or_path}`; known profiles: {', '.join(known) or 'none'}")


def _is_profile(path: Path) -> bool:
    # Data tables (costs, parity thresholds) share the folder; profiles have a [meta] section.
    try:
        return "meta" in tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, tomllib.TOMLDecodeError, UnicodeDecodeError, RecursionError):
        return False


@dataclass(frozen=True)
class ProfileValues:
    """A checked profile of any board: its file, text, ``--set`` overrides and every value."""

    source: str
    text: str
    overrides: tuple[str, ...] = ()
    values: dict[str, Any] = field(default_factory=dict)

    def get(self, dotted: str) -> Any:
        """One value by dotted key, e.g. ``profile.get("spi.spibrr")``."""
        if not isinstance(dotted, str):
            raise ProfileError(f"dotted = {short(dotted)}: expected a dotted key text, e.g. 'spi.spibrr'")
        node: Any = self.values
        for part in dotted.split("."):
            if not isinstance(node, dict) or part not in node:
                raise ProfileError(f"unknown key `{dotted}`")
            node = node[part]
        return node


def read_profile_text(name_or_path: str | os.PathLike[str]) -> tuple[Path, str]:
    """A profile's file (a name in the model folder or a path) and its text (ProfileError when it
    is not UTF-8, or ``name_or_path`` neither a text nor a path)."""
    if not isinstance(name_or_path, str | os.PathLike):
        raise ProfileError(
            f"name_or_path = {short(name_or_path)}: expected a profile name (e.g. 'reference') or the path "
            "of a profile TOML file"
        )
    path = resolve_profile_path(name_or_path)
    try:
        return path, path.read_text(encoding="utf-8")
    except UnicodeDecodeError as e:
        raise ProfileError(f"{path}: not UTF-8 text (byte {e.start})") from None


@dataclass(frozen=True)
class Profile(ProfileValues):
    """A validated F28335 board profile."""

    def with_overrides(self, *overrides: str) -> Profile:
        """The same profile with more ``key=value`` overrides (validated)."""
        return _build(self.source, self.text, (*self.overrides, *check_overrides(overrides)))


def load_profile(
    name_or_path: str | os.PathLike[str] = "reference", overrides: tuple[str, ...] | list[str] = ()
) -> Profile:
    """Load, override and validate a profile. Raises ProfileError naming the file and key, or the
    argument that is not what is expected (``name_or_path`` a text or a path; ``overrides`` a list of
    ``key=value`` texts, never one bare text)."""
    checked = check_overrides(overrides)
    path, text = read_profile_text(name_or_path)
    return _build(str(path), text, checked)


def check_overrides(overrides: Any, name: str = "overrides") -> tuple[str, ...]:
    """``overrides`` as ``key=value`` texts; one text (not in a list) or non-text items are a
    ProfileError naming ``name`` (a lone text would otherwise be read character by character)."""
    if isinstance(overrides, str | bytes) or not isinstance(overrides, Iterable):
        raise ProfileError(
            f"{name} = {short(overrides)}: expected a list of 'key=value' texts"
            + (f" (write {name}=[{overrides!r}])" if isinstance(overrides, str) else "")
        )
    out = tuple(overrides)
    for i, o in enumerate(out):
        if not isinstance(o, str):
            raise ProfileError(f"{name}[{i}] = {short(o)}: expected a 'key=value' text")
    return out


def short(value: Any) -> str:
    """A value for an error message: its repr, cut to a line."""
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:57]}... ({type(value).__name__})"


def _build(source: str, text: str, overrides: tuple[str, ...]) -> Profile:
    resolved = _core.resolve_profile(text, source, list(overrides))
    return Profile(source=source, text=text, overrides=overrides, values=tomllib.loads(resolved))


def cost_table_text(profile: Profile) -> tuple[str, str]:
    """The text and path of the profile's cycle-cost table."""
    name = str(profile.get("timing.costs"))
    path = Path(name) if Path(name).is_absolute() else Path(profile.source).parent / name
    if not path.is_file():
        path = MODEL_DIR / name
    if not path.is_file():
        raise ProfileError(
            f"key `timing.costs` = {name!r}: no such file next to {profile.source} or in {MODEL_DIR}"
        )
    return path.read_text(encoding="utf-8"), str(path)
