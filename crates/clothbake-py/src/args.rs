//! The Python API's one place for the names its functions take: facet models, analytic
//! variants, bounce counts, and the one-line error naming the argument. `bake`, `fabric` and
//! `two_faced` read their arguments through it, so each name and message is written once.

use clothbake_bake::transport::ALL_BOUNCES;
use clothbake_core::{FacetModel, Variant};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

pub(crate) fn bad(option: &str, msg: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(format!("{option}: {msg}"))
}

/// A count given as a whole number (`samples=`, `paths=`): a negative one is refused naming
/// the argument (the conversion to an unsigned number said only "can't convert negative
/// int"); the upper bounds are the bake settings' own.
pub(crate) fn count(name: &str, value: Option<i64>) -> PyResult<Option<usize>> {
    match value {
        Some(v) if v < 0 => Err(bad(
            name,
            format!("{v} is negative; give a whole number from 1"),
        )),
        Some(v) => Ok(Some(usize::try_from(v).unwrap_or(usize::MAX))),
        None => Ok(None),
    }
}

/// One of `words` (`name=` must be one of them), or the error naming the option.
pub(crate) fn choice<T: Copy>(
    name: &str,
    value: Option<&str>,
    words: &[(&str, T)],
) -> PyResult<Option<T>> {
    let Some(v) = value else { return Ok(None) };
    match words.iter().find(|(w, _)| *w == v) {
        Some(&(_, t)) => Ok(Some(t)),
        None => Err(bad(
            name,
            format!(
                "{v:?} is not one of {}; give one of them",
                words
                    .iter()
                    .map(|(w, _)| format!("{w:?}"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

/// The analytic variants by name (`variant=`).
pub(crate) const VARIANTS: &[(&str, Variant)] = &[
    ("refined", Variant::Refined),
    ("thesis", Variant::Thesis),
    ("sliced", Variant::Sliced),
    ("sliced3d", Variant::Sliced3d),
];

/// The analytic variant named `name`, or the error naming `variant=` and the choices.
pub(crate) fn variant_of(name: &str) -> PyResult<Variant> {
    Ok(choice("variant", Some(name), VARIANTS)?.expect("a name was given"))
}

/// Parses a facet model name (`"huo"`, `"lewis"`).
pub fn facet_model(name: &str) -> PyResult<FacetModel> {
    match name {
        "huo" => Ok(FacetModel::Huo),
        "lewis" => Ok(FacetModel::Lewis),
        other => Err(PyValueError::new_err(format!(
            "facet: {other:?} is not a facet model; use \"huo\" (the thesis's, eqs 4.6, 4.8) or \"lewis\" (energy conserving)"
        ))),
    }
}

/// Reads a bounce count: absent (1), 1, 2, a whole number N from 3 to 64, or "all"
/// (`ALL_BOUNCES`; docs/science/transport.md).
pub fn bounces_arg(obj: Option<&Bound<'_, PyAny>>) -> PyResult<u32> {
    let Some(obj) = obj else {
        return Ok(1);
    };
    if let Ok(n) = obj.extract::<i64>() {
        if (1..=64).contains(&n) {
            return Ok(n as u32);
        }
    } else if obj.extract::<String>().is_ok_and(|s| s == "all") {
        return Ok(ALL_BOUNCES);
    }
    Err(PyValueError::new_err(format!(
        "bounces: {obj}; use 1 (direct reflection), 2 (+ the secondary reflection of thesis ch. 5), a whole number N from 3 to 64 or \"all\" (every bounce, path-traced from the second on; docs/science/transport.md)"
    )))
}
