//! Numpy arrays of directions and random numbers in, checked: shape, dtype, finiteness, unit
//! length. Every failure is a Python exception naming the argument, the row and the fix.

use numpy::{PyArrayDyn, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// How far from 1 the length of a direction may be.
pub const UNIT_TOLERANCE: f64 = 1e-3;

/// Rows of an `(N, k)` array (or one `(k,)` vector) as f64, and whether it was one vector.
pub struct Rows<const K: usize> {
    /// The rows.
    pub rows: Vec<[f64; K]>,
    /// True when the input was a single `(k,)` vector (the result drops the batch axis).
    pub single: bool,
}

/// Reads `obj` (a numpy array of float32 or float64, or anything `numpy.asarray` turns into
/// float64) as rows of `K` numbers.
pub fn rows<const K: usize>(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Rows<K>> {
    let py = obj.py();
    let arr = if obj.is_instance_of::<numpy::PyUntypedArray>() {
        obj.clone()
    } else {
        let np = py.import("numpy")?;
        np.call_method1("asarray", (obj,)).map_err(|e| {
            PyTypeError::new_err(format!(
                "{name}: cannot be read as an array of numbers ({e}); pass a numpy array of shape (N, {K})"
            ))
        })?
    };
    let untyped = arr.cast::<numpy::PyUntypedArray>()?;
    let shape = untyped.shape().to_vec();
    let single = match shape.as_slice() {
        [k] if *k == K => true,
        [_, k] if *k == K => false,
        _ => {
            return Err(PyValueError::new_err(format!(
                "{name}: shape {shape:?}, expected (N, {K}) (or ({K},) for one)"
            )))
        }
    };
    let flat: Vec<f64> = if let Ok(a) = arr.cast::<PyArrayDyn<f64>>() {
        a.readonly().as_array().iter().copied().collect()
    } else if let Ok(a) = arr.cast::<PyArrayDyn<f32>>() {
        a.readonly()
            .as_array()
            .iter()
            .map(|&x| f64::from(x))
            .collect()
    } else {
        let dtype = untyped.dtype().str()?.to_string();
        return Err(PyTypeError::new_err(format!(
            "{name}: dtype {dtype} is not supported; pass float32 or float64 (e.g. {name}.astype(numpy.float64))"
        )));
    };
    let rows = flat
        .chunks_exact(K)
        .map(|c| std::array::from_fn(|k| c[k]))
        .collect();
    Ok(Rows { rows, single })
}

/// Reads `(N, 3)` unit vectors; a row whose length is not 1 (within [`UNIT_TOLERANCE`]) or
/// that holds a NaN or an infinity is an error naming the row.
pub fn unit_rows(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<Rows<3>> {
    let r = rows::<3>(name, obj)?;
    for (i, w) in r.rows.iter().enumerate() {
        check_unit(name, i, *w)?;
    }
    Ok(r)
}

/// Reads `(N, 3)` unit vectors straight into single precision, checked as [`unit_rows`] checks
/// them, in one pass over a contiguous float32 or float64 array (the lookups' fast path: no
/// intermediate copies); anything else goes through [`unit_rows`].
pub fn unit_rows_f32(name: &str, obj: &Bound<'_, PyAny>) -> PyResult<(Vec<[f32; 3]>, bool)> {
    fn read<T: Copy + Into<f64>>(name: &str, flat: &[T]) -> PyResult<Vec<[f32; 3]>> {
        // |w| in [1 - t, 1 + t] as |w|^2 in [(1 - t)^2, (1 + t)^2]: no square root a row
        // (NaN fails the test too); check_unit words the error.
        let (lo, hi) = (
            (1.0 - UNIT_TOLERANCE).powi(2),
            (1.0 + UNIT_TOLERANCE).powi(2),
        );
        let mut out = Vec::with_capacity(flat.len() / 3);
        for (i, c) in flat.chunks_exact(3).enumerate() {
            let w: [f64; 3] = [c[0].into(), c[1].into(), c[2].into()];
            let n2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
            if !(lo..=hi).contains(&n2) {
                check_unit(name, i, w)?;
            }
            out.push(w.map(|x| x as f32));
        }
        Ok(out)
    }
    let shape = obj
        .cast::<numpy::PyUntypedArray>()
        .ok()
        .map(|a| a.shape().to_vec());
    let single = match shape.as_deref() {
        Some([3]) => true,
        Some([_, 3]) => false,
        _ => {
            let r = unit_rows(name, obj)?;
            return Ok((
                r.rows.iter().map(|w| w.map(|x| x as f32)).collect(),
                r.single,
            ));
        }
    };
    if let Ok(a) = obj.cast::<PyArrayDyn<f64>>() {
        if let Ok(flat) = a.readonly().as_slice() {
            return Ok((read(name, flat)?, single));
        }
    } else if let Ok(a) = obj.cast::<PyArrayDyn<f32>>() {
        if let Ok(flat) = a.readonly().as_slice() {
            return Ok((read(name, flat)?, single));
        }
    }
    let r = unit_rows(name, obj)?;
    Ok((
        r.rows.iter().map(|w| w.map(|x| x as f32)).collect(),
        r.single,
    ))
}

/// Reads `uv`, points of the weave period as `(N, 2)` (or `(2,)`) period fractions, one per row
/// of `wi` (`n` rows); a row that is not finite is an error naming it.
/// Checks one footprint of the scalar paths: (u, v) finite period fractions, a width finite
/// and >= 0 (periods).
pub fn check_footprint(u: f64, v: f64, width: f64) -> PyResult<()> {
    if !(u.is_finite() && v.is_finite() && width.is_finite() && width >= 0.0) {
        return Err(PyValueError::new_err(format!(
            "({u}, {v}) with width {width}: give finite period fractions and a width >= 0"
        )));
    }
    Ok(())
}

/// Reads a footprint width: one number for every row, or an array of `n` (one a row), each
/// finite and >= 0 (the side of a square in periods).
pub fn widths(obj: &Bound<'_, PyAny>, n: usize) -> PyResult<Vec<f64>> {
    let out = if let Ok(w) = obj.extract::<f64>() {
        vec![w; n]
    } else {
        let np = obj.py().import("numpy")?;
        let flat = np
            .call_method1("asarray", (obj, "float64"))
            .and_then(|a| a.call_method0("ravel"))
            .and_then(|a| a.call_method0("tolist"))
            .and_then(|l| l.extract::<Vec<f64>>())
            .map_err(|e| {
                PyValueError::new_err(format!(
                    "width: cannot be read as numbers ({e}); give one number or an array (N,)"
                ))
            })?;
        same_len(("wi", n), ("width", flat.len()))?;
        flat
    };
    if let Some((i, w)) = out
        .iter()
        .enumerate()
        .find(|(_, w)| !(w.is_finite() && **w >= 0.0))
    {
        return Err(PyValueError::new_err(format!(
            "width: row {i} is {w}, not a footprint; give the square's side in periods, >= 0"
        )));
    }
    Ok(out)
}

pub fn period_rows(obj: &Bound<'_, PyAny>, n: usize) -> PyResult<Rows<2>> {
    let r = rows::<2>("uv", obj)?;
    same_len(("wi", n), ("uv", r.rows.len()))?;
    if let Some((i, [u, v])) = r
        .rows
        .iter()
        .enumerate()
        .find(|(_, p)| !(p[0].is_finite() && p[1].is_finite()))
    {
        return Err(PyValueError::new_err(format!(
            "uv: row {i} is ({u}, {v}); give finite period fractions"
        )));
    }
    Ok(r)
}

/// Checks one direction (row `i` of argument `name`).
pub fn check_unit(name: &str, i: usize, w: [f64; 3]) -> PyResult<()> {
    let len = (w[0] * w[0] + w[1] * w[1] + w[2] * w[2]).sqrt();
    if (len - 1.0).abs() <= UNIT_TOLERANCE {
        return Ok(());
    }
    Err(PyValueError::new_err(format!(
        "{name}[{i}] = ({}, {}, {}) has length {len}, not 1; pass unit vectors (divide by numpy.linalg.norm({name}, axis=-1, keepdims=True))",
        w[0], w[1], w[2]
    )))
}

/// Checks that two batches have the same number of rows.
pub fn same_len(a: (&str, usize), b: (&str, usize)) -> PyResult<()> {
    if a.1 == b.1 {
        return Ok(());
    }
    Err(PyValueError::new_err(format!(
        "{} has {} rows but {} has {}; give both the same number of rows",
        a.0, a.1, b.0, b.1
    )))
}

/// An `(N, K)` array (or `(K,)` when `single`) from rows.
pub fn to_array<'py, T: numpy::Element + Copy, const K: usize>(
    py: Python<'py>,
    rows: &[[T; K]],
    single: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<T> = rows.iter().flatten().copied().collect();
    let a = numpy::PyArray1::from_vec(py, flat);
    if single {
        Ok(a.into_any())
    } else {
        Ok(a.reshape([rows.len(), K])?.into_any())
    }
}

/// A `(N,)` array (or a scalar array `()` when `single`) from values.
pub fn to_array1<'py, T: numpy::Element + Copy>(
    py: Python<'py>,
    vals: Vec<T>,
    single: bool,
) -> PyResult<Bound<'py, PyAny>> {
    let a = numpy::PyArray1::from_vec(py, vals);
    if single {
        Ok(a.reshape(Vec::<usize>::new())?.into_any())
    } else {
        Ok(a.into_any())
    }
}
