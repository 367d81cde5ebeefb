"""The GPS model's NMEA 0183 sentences (rust/core/src/device/gps.rs) against an independent parser.

Every sentence the model writes parses with pynmea2 and renders back to the same text; the values
read back are the fix the model was given (within the model's rounding: 0.0001 minute of arc, 0.01
knot); a corrupted sentence is caught by pynmea2's checksum check and is an `nmea_bad_checksum` event
of the receiving side's reader, not a crash.
"""

import pynmea2
import pytest

from sins_fw import _core

KNOTS_PER_M_S = 3600.0 / 1852.0


def _sentences(**kw: object) -> list[str]:
    return [line.rstrip("\r\n") for _, line in _core.gps_nmea_lines(**kw)]


def test_every_sentence_parses_and_round_trips() -> None:
    lines = _sentences(
        seconds=20, seed=3, lat_deg=-33.8651, lon_deg=151.2099, alt_m=58.0, speed_m_s=13.4, course_deg=271.5
    )
    assert len(lines) == 4 * 20
    kinds = [pynmea2.parse(line, check=True).sentence_type for line in lines]
    assert kinds == ["GGA", "GSA", "RMC", "VTG"] * 20
    for line in lines:
        msg = pynmea2.parse(line, check=True)
        assert str(msg) == line
        assert len(line) + 2 <= 82, line


def test_values_read_back_are_the_fix() -> None:
    lines = _sentences(
        seconds=3,
        seed=0,
        lat_deg=37.38745833,
        lon_deg=-121.97236,
        alt_m=9.0,
        speed_m_s=0.0669,
        course_deg=309.62,
    )
    gga = pynmea2.parse(lines[0], check=True)
    rmc = pynmea2.parse(lines[2], check=True)
    vtg = pynmea2.parse(lines[3], check=True)
    # The noise (CEP 5 m) is in the position: 5 sigma is 21 m, i.e. 2e-4 degrees.
    assert gga.latitude == pytest.approx(37.38745833, abs=2e-4)
    assert gga.longitude == pytest.approx(-121.97236, abs=3e-4)
    assert gga.gps_qual == 1 and gga.num_sats == "07"
    assert rmc.status == "A" and rmc.datestamp.isoformat() == "1998-05-12"
    assert rmc.timestamp.isoformat().startswith("16:12:29")
    assert float(vtg.true_track) == pytest.approx(309.62)
    # Speed: 0.0669 m/s ± 0.1 m/s noise (5 sigma), in knots.
    assert float(rmc.spd_over_grnd) == pytest.approx(0.0669 * KNOTS_PER_M_S, abs=0.5 * KNOTS_PER_M_S)


def test_faults_lost_fix_cold_start() -> None:
    lines = _sentences(seconds=50, faults=[("lost", 2, 4), ("cold", 5, 0)])
    rmc = [pynmea2.parse(line, check=True) for line in lines if line.startswith("$GPRMC")]
    status = "".join(m.status for m in rmc)
    assert status == "AA" + "VV" + "A" + "V" * 42 + "A" * 3
    gga = [pynmea2.parse(line, check=True) for line in lines if line.startswith("$GPGGA")]
    assert gga[2].gps_qual == 0 and gga[2].latitude == 0.0


def test_a_bad_checksum_is_an_event_not_a_crash() -> None:
    lines = [line for _, line in _core.gps_nmea_lines(seconds=3, faults=[("corrupt", 1, 2)])]
    bad = lines[6].rstrip("\r\n")
    with pytest.raises(pynmea2.ChecksumError):
        pynmea2.parse(bad, check=True)
    bodies, events = _core.nmea_read("".join(lines))
    assert len(bodies) == 4 * 3 - 1
    assert [e["kind"] for e in events] == ["nmea_bad_checksum"]
    assert "does not match" in events[0]["message"]
    with pytest.raises(Exception, match="expected corrupt, lost or cold"):
        _core.gps_nmea_lines(seconds=1, faults=[("jam", 0, 0)])
