//! The C ABI of the clothbake loader, declared in `include/clothbake.h` (see `docs/reference/loader.md`).
//!
//! A table is opened into an opaque `clothbake_brdf` handle, looked up and sampled with the
//! functions below, and closed. Every function checks its pointers and catches panics: no
//! unwinding crosses the boundary. On failure a function returns `NULL` or `-1` and the
//! reason is kept, per thread, for [`clothbake_last_error`].

use std::cell::RefCell;
use std::ffi::{c_char, c_int, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use clothbake_loader::{Brdf, Memory, Options};

/// `clothbake_open` flag: hold the values as f32 even when the file stores half floats.
pub const CLOTHBAKE_F32: u32 = 1;
/// `clothbake_open` flag: symmetrise lookups, `0.5 (f(wi, wo) + f(wo, wi))`.
pub const CLOTHBAKE_RECIPROCAL: u32 = 2;
/// `clothbake_open` flag: do not build the sampling CDFs (saves 4 bytes a cell).
pub const CLOTHBAKE_NO_SAMPLING: u32 = 4;
/// `clothbake_open` flag: no point level (a spatial table that carries its yarns then answers
/// every footprint under a period with its crossing cells, docs/science/spatial.md).
pub const CLOTHBAKE_NO_POINT_LEVEL: u32 = 8;
const ALL_FLAGS: u32 =
    CLOTHBAKE_F32 | CLOTHBAKE_RECIPROCAL | CLOTHBAKE_NO_SAMPLING | CLOTHBAKE_NO_POINT_LEVEL;

/// The opaque handle of an open table.
pub struct ClothbakeBrdf(Brdf);

thread_local! {
    static LAST_ERROR: RefCell<Option<CString>> = const { RefCell::new(None) };
}

fn set_error(message: &str) {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    let _ = LAST_ERROR.try_with(|e| *e.borrow_mut() = Some(text));
}

/// Runs `f`, turning an `Err` or a panic into `fallback` and a last error.
fn guard<T>(fallback: T, f: impl FnOnce() -> Result<T, String>) -> T {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(v)) => v,
        Ok(Err(message)) => {
            set_error(&message);
            fallback
        }
        Err(_) => {
            set_error("clothbake: internal error (a panic was caught); please report it");
            fallback
        }
    }
}

/// The Brdf behind a handle, or an error naming the function.
unsafe fn brdf<'a>(h: *const ClothbakeBrdf, function: &str) -> Result<&'a Brdf, String> {
    h.as_ref()
        .map(|h| &h.0)
        .ok_or_else(|| format!("{function}: the table handle is NULL; open a table first"))
}

/// Three floats behind a pointer, or an error naming the function and the argument.
unsafe fn vec3(p: *const f32, function: &str, arg: &str) -> Result<[f32; 3], String> {
    if p.is_null() {
        return Err(format!("{function}: {arg} is NULL; pass 3 floats"));
    }
    Ok([*p, *p.add(1), *p.add(2)])
}

/// Writes three floats, or an error naming the function and the argument.
unsafe fn put3(p: *mut f32, v: [f32; 3], function: &str, arg: &str) -> Result<(), String> {
    if p.is_null() {
        return Err(format!("{function}: {arg} is NULL; pass room for 3 floats"));
    }
    for (k, x) in v.into_iter().enumerate() {
        *p.add(k) = x;
    }
    Ok(())
}

/// Opens a table file (OpenEXR or binary) with `flags` (`CLOTHBAKE_*`, or 0); NULL on error.
///
/// # Safety
/// `path` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn clothbake_open(path: *const c_char, flags: u32) -> *mut ClothbakeBrdf {
    guard(std::ptr::null_mut(), || {
        if path.is_null() {
            return Err("clothbake_open: path is NULL; pass the table's file name".to_string());
        }
        if flags & !ALL_FLAGS != 0 {
            return Err(format!(
                "clothbake_open: unknown flags {:#x}; use CLOTHBAKE_F32, CLOTHBAKE_RECIPROCAL, CLOTHBAKE_NO_SAMPLING, CLOTHBAKE_NO_POINT_LEVEL",
                flags & !ALL_FLAGS
            ));
        }
        let path = CStr::from_ptr(path).to_str().map_err(|_| {
            "clothbake_open: the path is not valid UTF-8; rename the file".to_string()
        })?;
        let options = Options {
            memory: if flags & CLOTHBAKE_F32 != 0 {
                Memory::F32
            } else {
                Memory::AsStored
            },
            reciprocal: flags & CLOTHBAKE_RECIPROCAL != 0,
            sampling: flags & CLOTHBAKE_NO_SAMPLING == 0,
            point_level: flags & CLOTHBAKE_NO_POINT_LEVEL == 0,
        };
        let b = Brdf::open(Path::new(path), options).map_err(|e| e.to_string())?;
        Ok(Box::into_raw(Box::new(ClothbakeBrdf(b))))
    })
}

/// Closes a table opened by [`clothbake_open`]; NULL is ignored.
///
/// # Safety
/// `h` is NULL or a handle from [`clothbake_open`] not yet closed.
#[no_mangle]
pub unsafe extern "C" fn clothbake_close(h: *mut ClothbakeBrdf) {
    if !h.is_null() {
        guard((), || {
            drop(Box::from_raw(h));
            Ok(())
        })
    }
}

/// The grid, `{n_theta_i, n_phi_i, n_theta_o, n_phi_o}`, into `out`; 0, or -1 on error.
///
/// # Safety
/// `h` is NULL or an open handle; `out` is NULL or has room for 4 `uint32_t`.
#[no_mangle]
pub unsafe extern "C" fn clothbake_grid(h: *const ClothbakeBrdf, out: *mut u32) -> c_int {
    guard(-1, || {
        let g = *brdf(h, "clothbake_grid")?.grid();
        if out.is_null() {
            return Err("clothbake_grid: out is NULL; pass room for 4 uint32_t".to_string());
        }
        for (k, n) in [g.n_theta_i, g.n_phi_i, g.n_theta_o, g.n_phi_o]
            .into_iter()
            .enumerate()
        {
            *out.add(k) = n;
        }
        Ok(0)
    })
}

/// `f_r(wi, wo)` (1/sr, RGB) into `out` for local-frame unit vectors; 0, or -1 on error.
///
/// # Safety
/// `h` is NULL or an open handle; each pointer is NULL or points to 3 floats.
#[no_mangle]
pub unsafe extern "C" fn clothbake_eval(
    h: *const ClothbakeBrdf,
    wi: *const f32,
    wo: *const f32,
    out: *mut f32,
) -> c_int {
    const F: &str = "clothbake_eval";
    guard(-1, || {
        let b = brdf(h, F)?;
        let f = b.eval(vec3(wi, F, "wi")?, vec3(wo, F, "wo")?);
        put3(out, f, F, "out")?;
        Ok(0)
    })
}

/// `f_r` at point (`u`, `v`) of the weave period (fractions, wrapped) through a footprint of
/// side `width` periods (0: the point; 1 or more: [`clothbake_eval`]), at its level of detail
/// (the yarns traced where the table carries them, its crossing cells, its average), into `out`
/// (RGB, 1/sr); the share of the footprint in which the eye meets yarn into `coverage` when it
/// is not NULL. A table baked with `--spatial` shows the weave; another answers
/// [`clothbake_eval`] and coverage 1. 0, or -1 on error (a NaN or infinite `u`, `v` or `width`,
/// or a negative `width`).
///
/// # Safety
/// `h` is NULL or an open handle; `wi`, `wo`, `out` are NULL or point to 3 floats;
/// `coverage` is NULL or points to a float.
#[no_mangle]
pub unsafe extern "C" fn clothbake_eval_at(
    h: *const ClothbakeBrdf,
    wi: *const f32,
    wo: *const f32,
    u: f64,
    v: f64,
    width: f64,
    out: *mut f32,
    coverage: *mut f32,
) -> c_int {
    const F: &str = "clothbake_eval_at";
    guard(-1, || {
        let b = brdf(h, F)?;
        if !(u.is_finite() && v.is_finite()) {
            return Err(format!(
                "{F}: the point ({u}, {v}) is not finite; give period fractions"
            ));
        }
        if !(width.is_finite() && width >= 0.0) {
            return Err(format!(
                "{F}: width {width} is not a footprint; give its side in periods, >= 0"
            ));
        }
        let (wi, wo) = (vec3(wi, F, "wi")?, vec3(wo, F, "wo")?);
        let (f, c) = b.local_at(wi, wo, u, v, width);
        put3(out, f, F, "out")?;
        if !coverage.is_null() {
            *coverage = c;
        }
        Ok(0)
    })
}

/// `f_r` at polar angles and azimuths in degrees into `out`; 0, or -1 on error.
///
/// # Safety
/// `h` is NULL or an open handle; `out` is NULL or has room for 3 floats.
#[no_mangle]
pub unsafe extern "C" fn clothbake_eval_deg(
    h: *const ClothbakeBrdf,
    theta_i: f32,
    phi_i: f32,
    theta_o: f32,
    phi_o: f32,
    out: *mut f32,
) -> c_int {
    const F: &str = "clothbake_eval_deg";
    guard(-1, || {
        let f = brdf(h, F)?.eval_deg(theta_i, phi_i, theta_o, phi_o);
        put3(out, f, F, "out")?;
        Ok(0)
    })
}

/// `n` lookups: `wi`, `wo` and `out` hold `3 n` floats each (x, y, z / R, G, B per item);
/// 0, or -1 on error.
///
/// # Safety
/// `h` is NULL or an open handle; each pointer is NULL or points to `3 n` floats; `out` does
/// not overlap `wi` or `wo`.
#[no_mangle]
pub unsafe extern "C" fn clothbake_eval_batch(
    h: *const ClothbakeBrdf,
    wi: *const f32,
    wo: *const f32,
    n: usize,
    out: *mut f32,
) -> c_int {
    const F: &str = "clothbake_eval_batch";
    guard(-1, || {
        let b = brdf(h, F)?;
        if n == 0 {
            return Ok(0);
        }
        for (p, name) in [(wi, "wi"), (wo, "wo"), (out as *const f32, "out")] {
            if p.is_null() {
                return Err(format!("{F}: {name} is NULL; pass 3 n floats"));
            }
        }
        let wi = std::slice::from_raw_parts(wi as *const [f32; 3], n);
        let wo = std::slice::from_raw_parts(wo as *const [f32; 3], n);
        let out = std::slice::from_raw_parts_mut(out as *mut [f32; 3], n);
        b.eval_batch(wi, wo, out).map_err(|e| e.to_string())?;
        Ok(0)
    })
}

/// Importance-samples an incident direction for `wo` from `u1, u2` in [0, 1): the direction
/// into `wi`, `f_r cos theta_i / pdf` into `weight` (RGB) and the density per unit solid angle
/// into `pdf` (0: no sample). 0, or -1 on error.
///
/// # Safety
/// `h` is NULL or an open handle; `wo`, `wi`, `weight` are NULL or point to 3 floats; `pdf` is
/// NULL or points to a float.
#[no_mangle]
pub unsafe extern "C" fn clothbake_sample(
    h: *const ClothbakeBrdf,
    wo: *const f32,
    u1: f32,
    u2: f32,
    wi: *mut f32,
    weight: *mut f32,
    pdf: *mut f32,
) -> c_int {
    const F: &str = "clothbake_sample";
    guard(-1, || {
        let b = brdf(h, F)?;
        let wo = vec3(wo, F, "wo")?;
        if pdf.is_null() {
            return Err(format!("{F}: pdf is NULL; pass room for 1 float"));
        }
        let s = b.sample(wo, u1, u2);
        put3(wi, s.wi, F, "wi")?;
        put3(weight, s.weight, F, "weight")?;
        *pdf = s.pdf;
        Ok(0)
    })
}

/// The density with which [`clothbake_sample`] draws `wi` for `wo`, per unit solid angle, into
/// `pdf`; 0, or -1 on error.
///
/// # Safety
/// `h` is NULL or an open handle; `wo`, `wi` are NULL or point to 3 floats; `pdf` is NULL or
/// points to a float.
#[no_mangle]
pub unsafe extern "C" fn clothbake_pdf(
    h: *const ClothbakeBrdf,
    wo: *const f32,
    wi: *const f32,
    pdf: *mut f32,
) -> c_int {
    const F: &str = "clothbake_pdf";
    guard(-1, || {
        let b = brdf(h, F)?;
        let (o, i) = (vec3(wo, F, "wo")?, vec3(wi, F, "wi")?);
        let p = b.pdf(i, o);
        if pdf.is_null() {
            return Err(format!("{F}: pdf is NULL; pass room for 1 float"));
        }
        *pdf = p;
        Ok(0)
    })
}

/// The message of this thread's last error (UTF-8, NUL-terminated), or NULL if there was
/// none. Valid until the next failing call on the same thread; do not free it.
#[no_mangle]
pub extern "C" fn clothbake_last_error() -> *const c_char {
    LAST_ERROR
        .try_with(|e| e.borrow().as_ref().map_or(std::ptr::null(), |s| s.as_ptr()))
        .unwrap_or(std::ptr::null())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn last_error() -> String {
        let p = clothbake_last_error();
        assert!(!p.is_null());
        unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned()
    }

    #[test]
    fn null_pointers_are_errors_not_crashes() {
        let mut out = [0f32; 3];
        let w = [0f32, 0.0, 1.0];
        let r =
            unsafe { clothbake_eval(std::ptr::null(), w.as_ptr(), w.as_ptr(), out.as_mut_ptr()) };
        assert_eq!(r, -1);
        assert!(last_error().contains("handle is NULL"));
        assert!(unsafe { clothbake_open(std::ptr::null(), 0) }.is_null());
        assert!(last_error().contains("path is NULL"));
        let path = CString::new("/no/such/folder/t.exr").unwrap();
        assert!(unsafe { clothbake_open(path.as_ptr(), 0) }.is_null());
        assert!(last_error().contains("t.exr"), "{}", last_error());
        assert!(unsafe { clothbake_open(path.as_ptr(), 64) }.is_null());
        assert!(last_error().contains("unknown flags 0x40"));
        unsafe { clothbake_close(std::ptr::null_mut()) };
    }

    #[test]
    fn every_exported_function_is_declared_in_the_header() {
        let header = include_str!("../include/clothbake.h");
        let source = include_str!("lib.rs");
        let exported: Vec<&str> = source
            .split("pub unsafe extern \"C\" fn ")
            .chain(source.split("pub extern \"C\" fn "))
            .skip(1)
            .filter_map(|s| s.split('(').next())
            .filter(|name| name.starts_with("clothbake_"))
            .collect();
        assert!(exported.len() >= 9, "{exported:?}");
        for name in exported {
            assert!(
                header.contains(&format!("{name}(")),
                "{name} missing from the header"
            );
        }
        for (name, value) in [
            ("CLOTHBAKE_F32", CLOTHBAKE_F32),
            ("CLOTHBAKE_RECIPROCAL", CLOTHBAKE_RECIPROCAL),
            ("CLOTHBAKE_NO_SAMPLING", CLOTHBAKE_NO_SAMPLING),
        ] {
            assert!(
                header.contains(&format!("#define {name} {value}u")),
                "{name}"
            );
        }
    }
}
