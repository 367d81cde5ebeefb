//! The C ABI called as C would call it.

use std::ffi::{c_char, CStr, CString};
use std::ptr;

use sins_cabi::*;

fn last_error() -> String {
    unsafe { CStr::from_ptr(sins_last_error()) }.to_string_lossy().into_owned()
}

fn new_board(overrides: &[&str]) -> *mut SinsBoard {
    let name = CString::new("reference").unwrap();
    let ov: Vec<CString> = overrides.iter().map(|s| CString::new(*s).unwrap()).collect();
    let ptrs: Vec<*const c_char> = ov.iter().map(|s| s.as_ptr()).collect();
    let mut b = ptr::null_mut();
    let s = unsafe { sins_board_new(name.as_ptr(), ptrs.as_ptr(), ptrs.len(), &mut b) };
    assert_eq!(s, SinsStatus::SinsOk, "{}", last_error());
    b
}

#[test]
fn prod_id_over_two_frames() {
    let b = new_board(&[]);
    unsafe {
        assert_eq!(sins_init_spi(b), SinsStatus::SinsOk);
        assert_eq!(sins_advance_ps(b, 10_000_000_000), SinsStatus::SinsOk);
        assert_eq!(sins_set_gpio(b, 57, 0), SinsStatus::SinsOk);
        let mut w = 0u16;
        assert_eq!(sins_transfer16(b, 0x5600, 40_000_000, &mut w), SinsStatus::SinsOk);
        assert_eq!(sins_transfer16(b, 0x0000, 40_000_000, &mut w), SinsStatus::SinsOk);
        assert_eq!(w, 0x4017);
        assert_eq!(sins_set_gpio(b, 57, 1), SinsStatus::SinsOk);
        let mut n = 99usize;
        let mut ev = [SinsEvent { t_ps: 0, frame: 0, din: 0, severity: 0, kind: [0; 40] }; 4];
        assert_eq!(sins_take_events(b, ev.as_mut_ptr(), ev.len(), &mut n), SinsStatus::SinsOk);
        assert_eq!(n, 0);
        sins_board_free(b);
    }
}

#[test]
fn registers_at_their_c28x_addresses() {
    let b = new_board(&[]);
    unsafe {
        assert_eq!(sins_write16(b, 0x7044, 37), SinsStatus::SinsOk); // SPIBRR
        let mut v = 0u16;
        assert_eq!(sins_read16(b, 0x7044, &mut v), SinsStatus::SinsOk);
        assert_eq!(v, 37);
        // GPBCLEAR's high word, bit 9 = GPIO57: CS falls.
        assert_eq!(sins_read16(b, 0x6FC9, &mut v), SinsStatus::SinsOk);
        assert_eq!(v & (1 << 9), 1 << 9);
        assert_eq!(sins_write16(b, 0x6FCD, 1 << 9), SinsStatus::SinsOk);
        assert_eq!(sins_read16(b, 0x6FC9, &mut v), SinsStatus::SinsOk);
        assert_eq!(v & (1 << 9), 0);
        // LOSPCP is EALLOW-protected: without EALLOW the write is ignored, as on the chip.
        assert_eq!(sins_write16(b, 0x701B, 6), SinsStatus::SinsOk);
        assert_eq!(sins_read16(b, 0x701B, &mut v), SinsStatus::SinsOk);
        assert_eq!(v, 2);
        assert_eq!(sins_set_eallow(b, 1), SinsStatus::SinsOk);
        assert_eq!(sins_write16(b, 0x701B, 6), SinsStatus::SinsOk); // LOSPCP: 12.5 MHz
        assert_eq!(sins_set_eallow(b, 0), SinsStatus::SinsOk);
        let mut set = SinsSpiSetting::default();
        assert_eq!(sins_configure_spi(b, 100e3, 3, &mut set), SinsStatus::SinsOk, "{}", last_error());
        assert_eq!((set.spibrr, set.exact, set.mode, set.sclk_hz), (124, 1, 3, 100e3));
        sins_board_free(b);
    }
}

#[test]
fn errors_come_back_as_codes_with_a_message() {
    let b = new_board(&[]);
    unsafe {
        let mut v = 0u16;
        assert_eq!(sins_read16(b, 0x0C0D, &mut v), SinsStatus::SinsErrRegister); // CPU timer 1: reserved word
        assert!(last_error().contains("C28x address 0x0C0D"), "{}", last_error());
        assert_eq!(sins_read16(b, 0x7044, ptr::null_mut()), SinsStatus::SinsErrNull);
        assert!(last_error().contains("out"), "{}", last_error());
        assert_eq!(sins_advance_ps(b, 1000), SinsStatus::SinsOk);
        assert_eq!(sins_advance_to_ps(b, 10), SinsStatus::SinsErrInput);
        // 150 SYSCLKOUT cycles at 150 MHz from 1000 ps: from the next cycle boundary (cycle 1) to cycle
        // 151, 151 × 6666.67 ps floored to whole picoseconds.
        let mut t = 0u64;
        assert_eq!(sins_advance_cycles(b, 150), SinsStatus::SinsOk);
        assert_eq!(sins_now_ps(b, &mut t), SinsStatus::SinsOk);
        assert_eq!(t, 1_006_666, "{t}");
        assert!(last_error().contains("only moves forward"), "{}", last_error());
        assert_eq!(sins_configure_spi(b, 100e3, -1, ptr::null_mut()), SinsStatus::SinsErrConfig);
        assert!(last_error().contains("LOSPCP"), "{}", last_error());
        assert_eq!(sins_peek_device(b, 0x100, &mut v), SinsStatus::SinsErrRegister);
        assert_eq!(sins_write16(ptr::null_mut(), 0x7044, 1), SinsStatus::SinsErrNull);
        sins_board_free(b);
        let mut h = ptr::null_mut();
        let bad = CString::new("no-such-profile").unwrap();
        assert_eq!(sins_board_new(bad.as_ptr(), ptr::null(), 0, &mut h), SinsStatus::SinsErrProfile);
        assert!(h.is_null() && last_error().contains("no-such-profile"), "{}", last_error());
        let name = CString::new("reference").unwrap();
        let ov = [CString::new("spi.spibrr").unwrap()];
        let ptrs = [ov[0].as_ptr()];
        assert_eq!(sins_board_new(name.as_ptr(), ptrs.as_ptr(), 1, &mut h), SinsStatus::SinsErrProfile);
        assert!(last_error().contains("spi.spibrr"), "{}", last_error());
    }
}

#[test]
fn c28x_operations_are_the_backend_s() {
    use sins_core::numerics::{C28xF32Rn, Scalar};
    let xs = [1.0f32, 3.0, -7.5, 1e-30, 1e-39, 0.1, 12345.678, -0.0];
    for &a in &xs {
        for &b in &xs {
            let (ca, cb) = (C28xF32Rn::new(a), C28xF32Rn::new(b));
            assert_eq!(sins_c28x_add(a, b).to_bits(), (ca + cb).value().to_bits());
            assert_eq!(sins_c28x_sub(a, b).to_bits(), (ca - cb).value().to_bits());
            assert_eq!(sins_c28x_mul(a, b).to_bits(), (ca * cb).value().to_bits());
            assert_eq!(sins_c28x_div(a, b).to_bits(), (ca / cb).value().to_bits());
        }
        assert_eq!(sins_c28x_sqrt(a.abs()).to_bits(), C28xF32Rn::new(a.abs()).sqrt().value().to_bits());
    }
    // What sets them apart from host IEEE float: tiny results and denormal inputs flush to zero.
    assert_eq!(sins_c28x_mul(1e-20, 1e-20), 0.0);
    assert_eq!(sins_c28x_add(1e-39, 0.0), 0.0);
}
