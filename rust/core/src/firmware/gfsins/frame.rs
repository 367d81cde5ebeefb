//! The packet the acquisition node sends the DSP over FPGA SPI #8 → C6727 SPI1, one per 5 ms tick.
//!
//! **[unconfirmed]: designed here.** The thesis (l. 1363, 1583) says only that DMA2 moves the
//! pre-processed packet to SPI #8, that the DSP's dMAX takes each 16-bit word and that a complete
//! packet raises an interrupt; the layout and word count are not published. This design:
//! 16-bit words, MSB first on the wire; 32-bit values high word first; a CRC over everything
//! before it so the DSP can refuse a damaged packet.
//!
//! | word | content |
//! |---|---|
//! | 0 | sync 0xEB90 |
//! | 1 | sequence: the node's tick count, mod 2¹⁶ |
//! | 2 | flags: bit 0 compass words new this tick, bit 1 GPS words new, bit 2 GPS fix valid, bit 3 an NMEA line was dropped since the last packet |
//! | 3–11 | A₁…A₉, the nine sensing channels of algorithms.md §4 (i16 counts, 3.9 mg/LSB full resolution) |
//! | 12–14 | compass heading (0…3600), pitch, roll (±900), tenths of a degree (i16) |
//! | 15–16, 17–18 | GPS latitude, longitude, 1e-7 ° (i32) |
//! | 19–20 | GPS altitude above MSL, cm (i32) |
//! | 21 | GPS speed over ground, cm/s (u16) |
//! | 22 | GPS course over ground, 0.01 ° (u16) |
//! | 23–24 | UTC time of the GPS fix, ms of the day (u32) |
//! | 25 | CRC-16/CCITT-FALSE of words 0–24 (bytes MSB first) |

/// Words in a packet.
pub const WORDS: usize = 26;
/// The sync word.
pub const SYNC: u16 = 0xEB90;
/// Flag: compass words new this tick.
pub const NEW_COMPASS: u16 = 1 << 0;
/// Flag: GPS words new this tick.
pub const NEW_GPS: u16 = 1 << 1;
/// Flag: the GPS fix is valid (status A, fix ≥ 1).
pub const GPS_VALID: u16 = 1 << 2;
/// Flag: an NMEA line was dropped (bad checksum) since the last packet.
pub const NMEA_DROPPED: u16 = 1 << 3;

/// The GPS part of a packet, in the packet's units.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct GpsWords {
    /// Latitude, 1e-7 °.
    pub lat_e7: i32,
    /// Longitude, 1e-7 °.
    pub lon_e7: i32,
    /// Altitude above MSL, cm.
    pub alt_cm: i32,
    /// Speed over ground, cm/s.
    pub speed_cm_s: u16,
    /// Course over ground, 0.01 °.
    pub course_cdeg: u16,
    /// UTC of the fix, ms of the day.
    pub utc_ms: u32,
}

/// One packet's content.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Packet {
    /// The node's tick count, mod 2¹⁶.
    pub sequence: u16,
    /// Flag bits (`NEW_COMPASS`, …).
    pub flags: u16,
    /// A₁…A₉, counts.
    pub accel: [i16; 9],
    /// Heading, pitch, roll, tenths of a degree.
    pub compass: [i16; 3],
    /// The latest GPS fix.
    pub gps: GpsWords,
}

/// CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final XOR) of `words`, each as
/// two bytes MSB first.
pub fn crc16(words: &[u16]) -> u16 {
    crc16_bytes(words.iter().flat_map(|w| w.to_be_bytes()))
}

fn crc16_bytes(bytes: impl IntoIterator<Item = u8>) -> u16 {
    let mut crc: u16 = 0xFFFF;
    for byte in bytes {
        crc ^= u16::from(byte) << 8;
        for _ in 0..8 {
            crc = if crc & 0x8000 != 0 { (crc << 1) ^ 0x1021 } else { crc << 1 };
        }
    }
    crc
}

fn split(v: u32) -> [u16; 2] {
    [(v >> 16) as u16, v as u16]
}

fn join(w: &[u16]) -> u32 {
    (u32::from(w[0]) << 16) | u32::from(w[1])
}

impl Packet {
    /// The packet's words, CRC last.
    pub fn encode(&self) -> [u16; WORDS] {
        let mut w = [0u16; WORDS];
        w[0] = SYNC;
        w[1] = self.sequence;
        w[2] = self.flags;
        for (d, &a) in w[3..12].iter_mut().zip(&self.accel) {
            *d = a as u16;
        }
        for (d, &c) in w[12..15].iter_mut().zip(&self.compass) {
            *d = c as u16;
        }
        let g = &self.gps;
        w[15..17].copy_from_slice(&split(g.lat_e7 as u32));
        w[17..19].copy_from_slice(&split(g.lon_e7 as u32));
        w[19..21].copy_from_slice(&split(g.alt_cm as u32));
        w[21] = g.speed_cm_s;
        w[22] = g.course_cdeg;
        w[23..25].copy_from_slice(&split(g.utc_ms));
        w[25] = crc16(&w[..25]);
        w
    }

    /// The packet in `w`, or why it is refused (wrong length, sync or CRC).
    pub fn decode(w: &[u16]) -> Result<Packet, String> {
        if w.len() != WORDS {
            return Err(format!("packet of {} words, expected {WORDS}", w.len()));
        }
        if w[0] != SYNC {
            return Err(format!("sync word 0x{:04X}, expected 0x{SYNC:04X}", w[0]));
        }
        let crc = crc16(&w[..25]);
        if crc != w[25] {
            return Err(format!("CRC 0x{:04X}, computed 0x{crc:04X}", w[25]));
        }
        Ok(Packet {
            sequence: w[1],
            flags: w[2],
            accel: std::array::from_fn(|i| w[3 + i] as i16),
            compass: std::array::from_fn(|i| w[12 + i] as i16),
            gps: GpsWords {
                lat_e7: join(&w[15..17]) as i32,
                lon_e7: join(&w[17..19]) as i32,
                alt_cm: join(&w[19..21]) as i32,
                speed_cm_s: w[21],
                course_cdeg: w[22],
                utc_ms: join(&w[23..25]),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The CRC's published check value: "123456789" → 0x29B1 (CRC-16/CCITT-FALSE catalogue entry);
    /// the word form is the byte form, MSB first.
    #[test]
    fn crc_is_ccitt_false() {
        assert_eq!(crc16_bytes(*b"123456789"), 0x29B1);
        assert_eq!(crc16(&[0x3132, 0x3334]), crc16_bytes(*b"1234"));
    }

    fn sample() -> Packet {
        Packet {
            sequence: 0xFFFF,
            flags: NEW_COMPASS | NEW_GPS | GPS_VALID,
            accel: [i16::MIN, -1, 0, 1, i16::MAX, 256, -256, 4095, -4096],
            compass: [3599, -900, 900],
            gps: GpsWords {
                lat_e7: 282_002_100,
                lon_e7: -1_129_264_700,
                alt_cm: -513,
                speed_cm_s: 2222,
                course_cdeg: 35_999,
                utc_ms: 86_399_999,
            },
        }
    }

    #[test]
    fn packets_round_trip() {
        let p = sample();
        let w = p.encode();
        assert_eq!((w[0], w[WORDS - 1]), (SYNC, crc16(&w[..25])));
        assert_eq!(Packet::decode(&w), Ok(p));
        assert_eq!(Packet::decode(&Packet::default().encode()), Ok(Packet::default()));
    }

    #[test]
    fn damaged_packets_are_refused() {
        let w = sample().encode();
        for i in 0..WORDS {
            for bit in [0, 7, 15] {
                let mut bad = w;
                bad[i] ^= 1 << bit;
                assert!(Packet::decode(&bad).is_err(), "word {i} bit {bit} flipped went through");
            }
        }
        assert!(Packet::decode(&w[..25]).is_err());
    }
}
