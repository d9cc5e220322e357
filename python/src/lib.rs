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

use bulge::io::chain;
use bulge::setting::Setting;
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyTuple};

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

fn bad(msg: String) -> PyErr {
    BadInput::new_err(msg)
}

fn failed(msg: String) -> PyErr {
    Failure::new_err(msg)
}

/// A Python value as TOML (`key` names it in messages, e.g. `material`):
/// a dict as a table, a list or tuple as an array (a numpy array or a
/// pandas Series through its `tolist`), a bool, an int, a float or a str
/// as themselves.
pub(crate) fn to_toml(key: &str, v: &Bound<'_, PyAny>) -> PyResult<toml::Value> {
    if let Ok(d) = v.downcast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let k: String = k
                .extract()
                .map_err(|_| bad(format!("the key {k} of {key} is not a string")))?;
            let sub = format!("{key}.{k}");
            t.insert(k, to_toml(&sub, &x)?);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.downcast::<PyList>().is_ok() || v.downcast::<PyTuple>().is_ok() {
        let items: Vec<Bound<'_, PyAny>> = v.try_iter()?.collect::<PyResult<_>>()?;
        return items
            .iter()
            .map(|x| to_toml(key, x))
            .collect::<PyResult<Vec<_>>>()
            .map(toml::Value::Array);
    }
    if !v.is_instance_of::<pyo3::types::PyString>()
        && let Ok(list) = v.call_method0("tolist")
    {
        return to_toml(key, &list);
    }
    if v.is_instance_of::<pyo3::types::PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<pyo3::types::PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if let Ok(i) = v.extract::<i64>()
        && !v.is_instance_of::<pyo3::types::PyFloat>()
    {
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    Err(bad(format!(
        "{key} = {v} is not a number, a string, a bool, a list or a table"
    )))
}

/// A progress callback `progress(done, total)` counted up once per step of
/// `total` (from worker threads too: each call takes the GIL). A callback's
/// own error is not the work's: Python prints it and the work goes on.
pub(crate) struct Counter {
    callback: Option<PyObject>,
    done: std::sync::atomic::AtomicUsize,
    total: usize,
}

impl Counter {
    pub(crate) fn new(callback: Option<PyObject>, total: usize) -> Self {
        Counter {
            callback,
            done: std::sync::atomic::AtomicUsize::new(0),
            total,
        }
    }

    /// One more step done.
    pub(crate) fn tick(&self) {
        let n = self.done.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1;
        if let Some(cb) = &self.callback {
            Python::with_gil(|py| {
                if let Err(e) = cb.call1(py, (n, self.total)) {
                    e.print(py);
                }
            });
        }
    }
}

/// A file of a run: its name, its stage and its bytes.
type File = (String, String, Py<PyBytes>);

#[cfg(feature = "opencv")]
mod init;
#[cfg(feature = "opencv")]
mod run;
mod simulate;
mod stages;
#[cfg(feature = "opencv")]
mod study;
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

/// The keyword that sets each setting a library message may name: the
/// library's own name (its option field or file key, quoted), but where the
/// functions' keyword differs from it.
fn keyword_of(s: Setting) -> &'static str {
    match s {
        Setting::Model => "`model`",
        Setting::CameraDistance => "`camera_distance_m`",
        Setting::MetresPerPixel => "`metres_per_pixel`",
        s => s.library_name(),
    }
}

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    bulge::setting::name_settings_with(keyword_of);
    m.add("BadInput", m.py().get_type::<BadInput>())?;
    m.add("Failure", m.py().get_type::<Failure>())?;
    m.add_function(wrap_pyfunction!(has_opencv, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add_function(wrap_pyfunction!(stages::stress, m)?)?;
    m.add_function(wrap_pyfunction!(stages::fit, m)?)?;
    m.add_function(wrap_pyfunction!(simulate::simulate, m)?)?;
    #[cfg(feature = "opencv")]
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    #[cfg(feature = "opencv")]
    m.add_function(wrap_pyfunction!(track::track, m)?)?;
    #[cfg(feature = "opencv")]
    m.add_function(wrap_pyfunction!(init::init, m)?)?;
    #[cfg(feature = "opencv")]
    m.add_function(wrap_pyfunction!(study::study, m)?)?;
    Ok(())
}
