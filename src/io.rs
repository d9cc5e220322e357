//! CSV and TOML rows with units in their names, and outputs written whole or
//! not at all.
//!
//! Every error names the file, the line (1-based, the header is line 1), the
//! column, the value and what would fix it, so that a user can go straight to
//! the offending cell.

use std::collections::HashMap;
use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

mod guard;
pub(crate) mod temp;
mod toml_de;

pub use guard::{OutputConflict, OutputPlan};
#[cfg(feature = "cli")]
pub use temp::install_cleanup_on_signal;
pub use temp::{remove_temporary_files, temporary_files};

/// An error with its chain of causes, each after a colon, as the command
/// line prints it (a cause whose text ends the message already is not
/// repeated).
pub fn chain(e: &dyn std::error::Error) -> String {
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

/// A problem with an input file, located to the cell where possible.
#[derive(Debug, thiserror::Error)]
#[error("{}: {message}", location(path, *line, column.as_deref()))]
pub struct InputError {
    /// The file that holds the bad value.
    pub path: PathBuf,
    /// 1-based line number (the header is line 1), when known.
    pub line: Option<u64>,
    /// Column name, when known.
    pub column: Option<String>,
    /// What is wrong, the value, and the fix.
    pub message: String,
    /// The setting (its key, e.g. `stress_measure`) that decides the
    /// matter, when one does, so that a caller can name its own way of
    /// setting it (a flag).
    pub setting: Option<&'static str>,
}

/// A value refused by a check: the key it was given for, and what is wrong
/// with it (the value and the fix). [`InputError::from_value`] places it in
/// a file; a caller that sets the key its own way (a flag) names that.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{message}")]
pub struct BadValue {
    /// The key of the value refused (e.g. `thickness_std_m`).
    pub key: &'static str,
    /// What is wrong, the value, and the fix.
    pub message: String,
}

impl BadValue {
    /// A refusal of `key`'s value.
    pub fn new(key: &'static str, message: impl Into<String>) -> Self {
        Self {
            key,
            message: message.into(),
        }
    }
}

fn location(path: &Path, line: Option<u64>, column: Option<&str>) -> String {
    let mut s = path.display().to_string();
    if let Some(l) = line {
        s.push_str(&format!(", line {l}"));
    }
    if let Some(c) = column {
        s.push_str(&format!(", column `{c}`"));
    }
    s
}

impl InputError {
    /// A value of the file refused by a check, the key kept as the setting.
    pub fn from_value(path: &Path, bad: BadValue) -> Self {
        Self {
            setting: Some(bad.key),
            ..Self::file(path, bad.message)
        }
    }

    /// An error about the whole file.
    pub fn file(path: &Path, message: impl Into<String>) -> Self {
        Self {
            path: path.to_path_buf(),
            line: None,
            column: None,
            message: message.into(),
            setting: None,
        }
    }

    /// An error about one cell.
    pub fn cell(path: &Path, line: u64, column: &str, message: impl Into<String>) -> Self {
        Self {
            path: path.to_path_buf(),
            line: Some(line),
            column: Some(column.to_string()),
            message: message.into(),
            setting: None,
        }
    }

    /// The same error, said to be decided by the setting `key`.
    pub fn about_setting(self, key: &'static str) -> Self {
        Self {
            setting: Some(key),
            ..self
        }
    }
}

/// A CSV table read whole into memory: header plus string records, with the
/// line number of every record kept for error messages.
#[derive(Debug, Clone)]
pub struct Table {
    /// The file it was read from (for error messages).
    pub path: PathBuf,
    /// Column names in file order.
    pub headers: Vec<String>,
    /// Records as strings, one per data line.
    pub rows: Vec<Vec<String>>,
    /// 1-based line number of each record.
    pub lines: Vec<u64>,
    index: HashMap<String, usize>,
}

impl Table {
    /// Reads a CSV file with a header line. Empty files and files with a header
    /// but no data are refused with a message saying so.
    pub fn read(path: impl AsRef<Path>) -> Result<Self, InputError> {
        let path = path.as_ref();
        let bytes = fs::read(path)
            .map_err(|e| InputError::file(path, format!("cannot read the file: {e}")))?;
        Self::parse(path, &bytes)
    }

    /// Parses CSV bytes as if read from `path`.
    pub fn parse(path: &Path, bytes: &[u8]) -> Result<Self, InputError> {
        if bytes.iter().all(|b| b.is_ascii_whitespace()) {
            return Err(InputError::file(
                path,
                "the file is empty: expected a header line and at least one data line",
            ));
        }
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .comment(Some(b'#'))
            .from_reader(bytes);
        let headers: Vec<String> = rdr
            .headers()
            .map_err(|e| InputError::file(path, format!("cannot read the header line: {e}")))?
            .iter()
            .map(str::to_string)
            .collect();
        if let [one] = headers.as_slice()
            && (one.contains(';') || one.contains('\t'))
        {
            return Err(InputError {
                path: path.to_path_buf(),
                line: Some(1),
                column: None,
                message: format!(
                    "the header `{one}` is one column: the values are separated by {}, not commas; save the file as comma-separated values with decimal points (header `{}`)",
                    if one.contains(';') {
                        "semicolons"
                    } else {
                        "tabs"
                    },
                    one.replace([';', '\t'], ",")
                ),
                setting: None,
            });
        }
        let mut index = HashMap::new();
        for (i, h) in headers.iter().enumerate() {
            if index.insert(h.clone(), i).is_some() {
                return Err(InputError::cell(
                    path,
                    1,
                    h,
                    "this column name appears twice in the header: rename or drop one",
                ));
            }
        }
        let mut rows = Vec::new();
        let mut lines = Vec::new();
        for rec in rdr.records() {
            let rec = rec.map_err(|e| {
                let line = e.position().map(|p| p.line());
                InputError {
                    path: path.to_path_buf(),
                    line,
                    column: None,
                    message: format!("malformed CSV record: {e}"),
                    setting: None,
                }
            })?;
            let line = rec.position().map(|p| p.line()).unwrap_or(0);
            if rec.iter().all(str::is_empty) {
                continue;
            }
            rows.push(rec.iter().map(str::to_string).collect());
            lines.push(line);
        }
        if rows.is_empty() {
            return Err(InputError::file(
                path,
                "the file has a header but no data lines: add at least one row",
            ));
        }
        Ok(Self {
            path: path.to_path_buf(),
            headers,
            rows,
            lines,
            index,
        })
    }

    /// Number of data rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// True when there are no data rows (never, after a successful read).
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// Index of a column, if present.
    pub fn column_index(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }

    /// Index of a required column, or an error naming the columns found.
    pub fn require(&self, name: &str) -> Result<usize, InputError> {
        self.column_index(name).ok_or_else(|| {
            InputError::cell(
                &self.path,
                1,
                name,
                format!(
                    "missing column `{name}` (found: {}); add it to the header",
                    self.headers.join(", ")
                ),
            )
        })
    }

    /// The raw string of a cell.
    pub fn cell(&self, row: usize, col: usize) -> &str {
        self.rows[row].get(col).map(String::as_str).unwrap_or("")
    }

    /// A finite number from a cell, or an error naming the line and value.
    pub fn number(&self, row: usize, col: usize) -> Result<f64, InputError> {
        let raw = self.cell(row, col);
        let name = &self.headers[col];
        let v: f64 = raw.parse().map_err(|_| {
            InputError::cell(
                &self.path,
                self.lines[row],
                name,
                format!("`{raw}` is not a number; write a decimal number such as 1500 or 2.5e-3"),
            )
        })?;
        if !v.is_finite() {
            return Err(InputError::cell(
                &self.path,
                self.lines[row],
                name,
                format!(
                    "`{raw}` is not a finite number; replace it with a measured value or drop the row"
                ),
            ));
        }
        Ok(v)
    }

    /// A whole required numeric column.
    pub fn numbers(&self, name: &str) -> Result<Vec<f64>, InputError> {
        let c = self.require(name)?;
        (0..self.len()).map(|r| self.number(r, c)).collect()
    }

    /// A whole optional numeric column: `None` when absent; empty cells are
    /// `None` too.
    pub fn optional_numbers(&self, name: &str) -> Result<Option<Vec<Option<f64>>>, InputError> {
        let Some(c) = self.column_index(name) else {
            return Ok(None);
        };
        let mut out = Vec::with_capacity(self.len());
        for r in 0..self.len() {
            if self.cell(r, c).is_empty() {
                out.push(None);
            } else {
                out.push(Some(self.number(r, c)?));
            }
        }
        Ok(Some(out))
    }

    /// An error located at a data row and column.
    pub fn error_at(&self, row: usize, column: &str, message: impl Into<String>) -> InputError {
        InputError::cell(&self.path, self.lines[row], column, message)
    }
}

/// Formats a float for CSV output: shortest round-trip representation, empty
/// for `None`. NaN and infinities are never written (they become empty cells).
pub fn fmt_num(v: Option<f64>) -> String {
    match v {
        Some(x) if x.is_finite() => format!("{x}"),
        _ => String::new(),
    }
}

/// Writes a file whole or not at all: the bytes go to a temporary file in the
/// same folder, which is synced and then renamed over the target. Parent
/// folders are created; the permissions of a file replaced are kept.
///
/// What is at `path` decides how:
///
/// * nothing, or a regular file: replaced atomically as above;
/// * a symbolic link to a regular file: the file it points to is replaced
///   atomically, and the link stays;
/// * a FIFO, a device, a socket (e.g. `/dev/stdout`), or a link to one or to
///   nothing: written through (opened for writing and written), since
///   renaming over it would swap the stream or the link for a regular file;
/// * a folder: refused.
///
/// The temporary file is registered for removal if the process is
/// interrupted (see [`remove_temporary_files`]; the `bulge` binary installs
/// `install_cleanup_on_signal`).
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    match target(path)? {
        Target::Replace(target) => {
            let (tmp, mut f) = temp::TempFile::create(&target)?;
            f.write_all(bytes)?;
            f.sync_all()?;
            drop(f);
            finish(tmp, &target)
        }
        Target::Through(target) => write_through(&target, bytes),
    }
}

/// [`write_atomic`] for writers that want a path rather than bytes (image
/// encoders, plotting back-ends): `write` is given a temporary path next to
/// `path` (same extension, so writers that choose the format by extension
/// still work), and what it writes there then replaces `path` as in
/// [`write_atomic`]. If `write` fails, the temporary file is removed and
/// `path` is left as it was.
pub fn write_atomic_with<E>(
    path: &Path,
    write: impl FnOnce(&Path) -> Result<(), E>,
) -> Result<(), AtomicWriteError<E>> {
    let target = target(path).map_err(AtomicWriteError::Io)?;
    let created = match &target {
        Target::Replace(t) => temp::TempFile::create(t),
        // never a temporary file beside a device or a FIFO (in /dev, say)
        Target::Through(t) => temp::TempFile::create_in(&std::env::temp_dir(), t),
    };
    let (tmp, f) = created.map_err(AtomicWriteError::Io)?;
    drop(f);
    write(tmp.path()).map_err(AtomicWriteError::Write)?;
    match target {
        Target::Replace(t) => {
            fs::File::open(tmp.path())
                .and_then(|f| f.sync_all())
                .map_err(AtomicWriteError::Io)?;
            finish(tmp, &t).map_err(AtomicWriteError::Io)
        }
        Target::Through(t) => {
            let bytes = fs::read(tmp.path()).map_err(AtomicWriteError::Io)?;
            drop(tmp);
            write_through(&t, &bytes).map_err(AtomicWriteError::Io)
        }
    }
}

/// Why [`write_atomic_with`] failed: in the caller's writer, or in the file
/// handling around it.
#[derive(Debug, thiserror::Error)]
pub enum AtomicWriteError<E> {
    /// The writer failed.
    #[error(transparent)]
    Write(E),
    /// Creating, syncing or renaming the temporary file failed.
    #[error(transparent)]
    Io(std::io::Error),
}

enum Target {
    /// Write a temporary file and rename it onto this path.
    Replace(PathBuf),
    /// Open this path for writing and write.
    Through(PathBuf),
}

fn target(path: &Path) -> std::io::Result<Target> {
    use std::io::ErrorKind;
    let meta = match fs::symlink_metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == ErrorKind::NotFound => {
            let dir = match path.parent() {
                Some(d) if !d.as_os_str().is_empty() => d,
                _ => Path::new("."),
            };
            fs::create_dir_all(dir)?;
            return Ok(Target::Replace(path.to_path_buf()));
        }
        Err(e) => return Err(e),
    };
    let ft = meta.file_type();
    if ft.is_file() {
        Ok(Target::Replace(path.to_path_buf()))
    } else if ft.is_dir() {
        Err(std::io::Error::new(
            ErrorKind::IsADirectory,
            format!("{} is a folder, not a file", path.display()),
        ))
    } else if ft.is_symlink() {
        match fs::canonicalize(path) {
            Ok(real) => match fs::metadata(&real) {
                Ok(m) if m.is_file() => Ok(Target::Replace(real)),
                Ok(m) if m.is_dir() => Err(std::io::Error::new(
                    ErrorKind::IsADirectory,
                    format!("{} links to a folder, not a file", path.display()),
                )),
                _ => Ok(Target::Through(path.to_path_buf())),
            },
            // a link to nothing: writing through it creates its target
            Err(_) => Ok(Target::Through(path.to_path_buf())),
        }
    } else {
        Ok(Target::Through(path.to_path_buf()))
    }
}

/// Gives the temporary file the permissions of the file it replaces, then
/// renames it over it.
fn finish(tmp: temp::TempFile, target: &Path) -> std::io::Result<()> {
    if let Ok(m) = fs::metadata(target) {
        fs::set_permissions(tmp.path(), m.permissions())?;
    }
    tmp.persist(target)
}

fn write_through(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let mut f = fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(path)?;
    f.write_all(bytes)?;
    f.flush()
}

/// Builds a CSV document in memory (so that it can be written atomically).
pub struct CsvOut {
    wtr: csv::Writer<Vec<u8>>,
}

impl CsvOut {
    /// Starts a document with the given header.
    pub fn new<S: AsRef<str>>(header: &[S]) -> Self {
        let mut wtr = csv::Writer::from_writer(Vec::new());
        wtr.write_record(header.iter().map(|s| s.as_ref()))
            .expect("writing to memory cannot fail");
        Self { wtr }
    }

    /// Appends a record.
    pub fn row<S: AsRef<str>>(&mut self, fields: &[S]) {
        self.wtr
            .write_record(fields.iter().map(|s| s.as_ref()))
            .expect("writing to memory cannot fail");
    }

    /// The finished bytes.
    pub fn into_bytes(self) -> Vec<u8> {
        self.wtr
            .into_inner()
            .expect("writing to memory cannot fail")
    }

    /// Writes the document atomically to `path`.
    pub fn write(self, path: &Path) -> std::io::Result<()> {
        write_atomic(path, &self.into_bytes())
    }
}

/// Reads and parses a TOML file into `T`, with the file named in the error.
/// A misspelt key or value refused by `T` gets the nearest valid name
/// suggested ("did you mean `radius_m`?").
pub fn read_toml<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T, InputError> {
    parse_toml(path, &read_text(path)?)
}

/// The text of a file, a failure to read it named with the file.
pub(crate) fn read_text(path: &Path) -> Result<String, InputError> {
    fs::read_to_string(path)
        .map_err(|e| InputError::file(path, format!("cannot read the file: {e}")))
}

/// `text`, read from `path`, parsed into `T`; a refusal names the key, its
/// table and its line ([`toml_de`]).
pub(crate) fn parse_toml<T: serde::de::DeserializeOwned>(
    path: &Path,
    text: &str,
) -> Result<T, InputError> {
    toml_de::from_str(text).map_err(|e| match e {
        toml_de::Error::Syntax(e) => toml_error(path, text, &e),
        toml_de::Error::Refused(r) => {
            // a missing key is refused at its table, whose span starts with
            // the whitespace before the header: name the header's line
            let skip = matches!(r.kind, toml_de::Kind::Missing(_));
            InputError {
                path: path.to_path_buf(),
                line: r.span.as_ref().map(|s| line_at(text, s.start, skip)),
                column: None,
                message: r.to_string(),
                setting: None,
            }
        }
    })
}

/// 1-based line of `key` in `[table]` of the TOML `text`, from the
/// parser's spans (`None` when the file does not parse or has no such key).
pub(crate) fn key_line(text: &str, table: &str, key: &str) -> Option<u64> {
    let doc = toml_edit::Document::parse(text).ok()?;
    let (k, _) = doc.get(table)?.as_table_like()?.get_key_value(key)?;
    Some(line_at(text, k.span()?.start, false))
}

/// 1-based line of byte `at` of `text` (past the whitespace there when
/// `skip_space`).
fn line_at(text: &str, at: usize, skip_space: bool) -> u64 {
    // a span never splits a character, but a byte offset might
    let mut end = (0..=at.min(text.len()))
        .rev()
        .find(|&i| text.is_char_boundary(i))
        .unwrap_or(0);
    if skip_space {
        end += text[end..].len() - text[end..].trim_start().len();
    }
    text[..end].matches('\n').count() as u64 + 1
}

/// An [`InputError`] from a TOML syntax error of `text`, read from `path`:
/// the line of the error and the parser's message.
pub fn toml_error(path: &Path, text: &str, e: &toml::de::Error) -> InputError {
    InputError {
        path: path.to_path_buf(),
        line: e.span().map(|s| line_at(text, s.start, false)),
        column: None,
        message: format!("invalid TOML: {}", e.message().trim_end()),
        setting: None,
    }
}

/// The candidate nearest to a misspelt `name`, if one is near enough to be
/// what was meant: at most one edit (insertion, deletion, substitution or
/// swap of two neighbours, ignoring case) per three letters, or `name` with
/// its unit suffix missing (`young` for `young_pa`).
pub fn nearest_name<'a>(
    name: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> Option<&'a str> {
    let lower = name.to_lowercase();
    let budget = (lower.chars().count() / 3).max(1);
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        let lc = c.to_lowercase();
        let d = if lc.strip_prefix(&lower).is_some_and(|r| r.starts_with('_')) {
            1
        } else {
            edit_distance(&lower, &lc)
        };
        if d <= budget && best.is_none_or(|(bd, _)| d < bd) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// Optimal string alignment distance (Levenshtein plus swaps of adjacent
/// characters).
fn edit_distance(a: &str, b: &str) -> usize {
    let a: Vec<char> = a.chars().collect();
    let b: Vec<char> = b.chars().collect();
    let (n, m) = (a.len(), b.len());
    let mut d = vec![vec![0usize; m + 1]; n + 1];
    for (i, row) in d.iter_mut().enumerate() {
        row[0] = i;
    }
    d[0] = (0..=m).collect();
    for i in 1..=n {
        for j in 1..=m {
            let cost = usize::from(a[i - 1] != b[j - 1]);
            let mut v = (d[i - 1][j] + 1)
                .min(d[i][j - 1] + 1)
                .min(d[i - 1][j - 1] + cost);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                v = v.min(d[i - 2][j - 2] + 1);
            }
            d[i][j] = v;
        }
    }
    d[n][m]
}

/// Why a value could not be written as TOML.
#[derive(Debug, thiserror::Error)]
pub enum TomlWriteError {
    /// A number is NaN or infinite: TOML can spell it, but no reader of
    /// this crate accepts it, and it means the computation went wrong.
    #[error(
        "`{key} = {value}` is not a finite number; nothing was written (a file must hold measured or fitted values only: check the data that produced it)"
    )]
    NonFinite {
        /// Dotted path of the key, with `[i]` for array entries.
        key: String,
        /// The value.
        value: f64,
    },
    /// The value has no TOML form.
    #[error("cannot write as TOML: {0}")]
    Serialize(#[from] toml::ser::Error),
}

/// Serialises `value` as a TOML document, refusing NaN and infinities
/// anywhere in it (the error names the first such key). Use it for every
/// TOML file written, e.g. `material.toml`, then [`write_atomic`].
pub fn to_toml_string<T: serde::Serialize + ?Sized>(value: &T) -> Result<String, TomlWriteError> {
    let v = toml::Value::try_from(value)?;
    if let Some((key, value)) = first_non_finite(&v, "") {
        return Err(TomlWriteError::NonFinite { key, value });
    }
    Ok(toml::to_string(value)?)
}

fn first_non_finite(v: &toml::Value, at: &str) -> Option<(String, f64)> {
    match v {
        toml::Value::Float(x) if !x.is_finite() => Some((at.to_string(), *x)),
        toml::Value::Table(t) => t.iter().find_map(|(k, v)| {
            let key = if at.is_empty() {
                k.clone()
            } else {
                format!("{at}.{k}")
            };
            first_non_finite(v, &key)
        }),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, v)| first_non_finite(v, &format!("{at}[{i}]"))),
        _ => None,
    }
}

/// A number for a message: up to 6 significant digits, in exponent form
/// outside [1e-3, 1e7) (never the 300 digits of a plain `{}` of 1e-300).
pub fn fmt_short(v: f64) -> String {
    let a = v.abs();
    if v == 0.0 || !v.is_finite() || (1e-3..1e7).contains(&a) {
        let s = format!("{:.6}", v);
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s.is_empty() || s == "-" {
            "0".into()
        } else {
            s.to_string()
        }
    } else {
        format!("{v:.5e}")
    }
}

#[cfg(test)]
mod tests;
