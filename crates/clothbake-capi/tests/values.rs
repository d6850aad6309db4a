//! The C API on tables whose values are not physical: `clothbake_open` refuses a CRC-valid
//! table of 3e38 (whose albedo and sampling weights would be infinite) with an error naming
//! the value, and samples the largest allowed value with finite weights.

use std::ffi::{CStr, CString};
use std::path::{Path, PathBuf};

use clothbake_capi::{clothbake_close, clothbake_last_error, clothbake_open, clothbake_sample};
use clothbake_loader::{write_container, ContainerKind, Grid, Metadata, MAX_VALUE};

fn table(name: &str, value: f32) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join("capi-values");
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    let g = Grid::new(2, 4, 2, 4);
    let header = serde_json::to_value(Metadata::new("clothbake test", g, "{}", "{}", "none"));
    let values = vec![value; 3 * g.len()];
    write_container(&p, ContainerKind::Table, &header.unwrap(), &values, true).unwrap();
    p
}

fn c_path(p: &Path) -> CString {
    CString::new(p.to_str().unwrap()).unwrap()
}

#[test]
fn open_refuses_values_whose_albedo_overflows() {
    let p = c_path(&table("huge.bin", 3e38));
    // SAFETY: a NUL-terminated path; the error string is read before any other call.
    let h = unsafe { clothbake_open(p.as_ptr(), 0) };
    assert!(h.is_null());
    let e = unsafe { CStr::from_ptr(clothbake_last_error()) }
        .to_string_lossy()
        .into_owned();
    assert!(e.contains("huge.bin") && e.contains("is 3e38"), "{e}");
    assert!(e.contains("largest value a table may hold is 1e30"), "{e}");
}

#[test]
fn the_largest_value_samples_finitely() {
    let p = c_path(&table("max.bin", MAX_VALUE));
    // SAFETY: a NUL-terminated path; the handle is used while open, then closed once.
    unsafe {
        let h = clothbake_open(p.as_ptr(), 0);
        assert!(!h.is_null());
        let wo = [0.0f32, 0.0, 1.0];
        let (mut wi, mut weight, mut pdf) = ([0f32; 3], [0f32; 3], 0f32);
        for k in 0..64 {
            let u = (k as f32 + 0.5) / 64.0;
            let r = clothbake_sample(
                h,
                wo.as_ptr(),
                u,
                1.0 - u,
                wi.as_mut_ptr(),
                weight.as_mut_ptr(),
                &mut pdf,
            );
            assert_eq!(r, 0);
            assert!(pdf > 0.0, "{pdf}");
            assert!(
                weight.iter().all(|w| w.is_finite() && *w > 0.0),
                "{weight:?}"
            );
        }
        clothbake_close(h);
    }
}
