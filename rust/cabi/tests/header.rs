//! The checked-in header is what cbindgen makes of the crate now: this test fails when it is stale
//! (`SINS_BLESS=1 cargo test -p sins-cabi --test header` rewrites it).

use std::path::Path;

#[test]
fn checked_in_header_is_current() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(dir.join("cbindgen.toml")).expect("cbindgen.toml");
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(dir.join("src/lib.rs"))
        .generate()
        .expect("cbindgen generates the header");
    let mut made = Vec::new();
    bindings.write(&mut made);
    let path = dir.join("include/sins_fw.h");
    if std::env::var_os("SINS_BLESS").is_some() {
        std::fs::write(&path, &made).expect("write the header");
    }
    let kept = std::fs::read(&path).unwrap_or_default();
    assert!(
        kept == made,
        "{} is stale: regenerate it with `SINS_BLESS=1 cargo test -p sins-cabi --test header`",
        path.display()
    );
}
