//! `bulge._native`: the Python bindings of the bulge library.
//!
//! Each function calls the library's own entry (no re-implementation, no
//! call of the `bulge` binary) with the GIL released, and hands back the
//! files the command line would write, as bytes in memory: the Python side
//! (`bulge/__init__.py`) reads the CSV files into pandas DataFrames and the
//! TOML files into dicts, so that column names, units and numbers are the
//! command line's. An input the library refuses raises `bulge.BadInput`
//! (the command line's exit status 2), a failure of the work raises
//! `bulge.Failure` (exit status 1), both with the command line's message.

use std::error::Error;

use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBytes;

create_exception!(
    _native,
    BadInput,
    PyValueError,
    "The input was refused (the command line's exit status 2)."
);
create_exception!(
    _native,
    Failure,
    PyRuntimeError,
    "The work failed (the command line's exit status 1)."
);

/// An error with its chain of causes, as the command line prints it
/// (`{:#}` of its error: each cause after a colon).
fn chain(e: &dyn Error) -> String {
    let mut s = e.to_string();
    let mut cur = e.source();
    while let Some(c) = cur {
        let c_text = c.to_string();
        if !s.ends_with(&c_text) {
            s.push_str(": ");
            s.push_str(&c_text);
        }
        cur = c.source();
    }
    s
}

fn bad(msg: String) -> PyErr {
    BadInput::new_err(msg)
}

fn failed(msg: String) -> PyErr {
    Failure::new_err(msg)
}

/// A file of a run: its name, its stage and its bytes.
type File = (String, String, Py<PyBytes>);

#[cfg(feature = "opencv")]
mod run;
mod stages;
#[cfg(feature = "opencv")]
mod track;

/// True when this build has the photo stages (track, run, study).
#[pyfunction]
fn has_opencv() -> bool {
    cfg!(feature = "opencv")
}

/// The version of the bulge library this module was built from.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("BadInput", m.py().get_type::<BadInput>())?;
    m.add("Failure", m.py().get_type::<Failure>())?;
    m.add_function(wrap_pyfunction!(has_opencv, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(stages::stress, m)?)?;
    m.add_function(wrap_pyfunction!(stages::fit, m)?)?;
    #[cfg(feature = "opencv")]
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    #[cfg(feature = "opencv")]
    m.add_function(wrap_pyfunction!(track::track, m)?)?;
    Ok(())
}
