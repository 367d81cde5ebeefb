"""Profiles: loading, overrides, and errors that name the file, key and allowed values."""

from __future__ import annotations

import pytest

from sins_fw import _core
from sins_fw.errors import InputError, ProfileError
from sins_fw.profile import MODEL_DIR, load_profile


def test_reference_profile_is_the_published_board():
    p = load_profile("reference")
    assert p.get("clocks.pllcr") == 10
    assert p.get("spi.spiccr") == 0x00CF
    assert p.get("spi.spictl") == 0x0007
    assert p.get("spi.spibrr") == 49
    assert p.get("device.burst_command") == 0x4200
    assert p.get("device.prod_id") == 0x4017


def test_override_changes_one_field():
    p = load_profile("reference", ["spi.spibrr=127", "firmware.numeric=iq"])
    assert p.get("spi.spibrr") == 127
    assert p.get("firmware.numeric") == "iq"
    assert p.get("spi.spictl") == 7


@pytest.mark.parametrize(
    ("override", "fragments"),
    [
        ("spi.spibr=3", ["unknown key `spi.spibr`", "did you mean `spi.spibrr`"]),
        ("spi.spibrr=128", ["spi.spibrr", "0…127"]),
        ("spi.spiccr=0x00C7", ["spi.spiccr", "SPICHAR = 15"]),
        ("timer.period_us=0", ["timer.period_us", "> 0"]),
        ("firmware.numeric=f16", ["firmware.numeric", "c28x-f32"]),
        ("firmware.dcm.kp=-0.1", ["firmware.dcm.kp", "≥ 0"]),
        ("firmware.dcm.ki=-1e-3", ["firmware.dcm.ki", "≥ 0"]),
        ("firmware.dcm.yaw_reference=compass", ["firmware.dcm.yaw_reference", "magnetometer", "gps"]),
        ("firmware.dcm.integrator_limit_dps=200", ["firmware.dcm.integrator_limit_dps", "0…90"]),
        ("spi.spibrr", ["expected key=value"]),
    ],
)
def test_bad_overrides_name_key_and_allowed_values(override, fragments):
    with pytest.raises(ProfileError) as e:
        load_profile("reference", [override])
    for f in fragments:
        assert f in str(e.value)
    assert isinstance(e.value, InputError)


def test_unknown_profile_lists_known():
    with pytest.raises(ProfileError, match=r"known profiles: .*reference"):
        load_profile("no-such-profile")


def test_schema_documents_every_key():
    schema = (MODEL_DIR / "SCHEMA.md").read_text(encoding="utf-8")
    missing = [k for k in _core.profile_keys() if f"`{k}`" not in schema]
    assert not missing, f"keys not documented in SCHEMA.md: {missing}"
