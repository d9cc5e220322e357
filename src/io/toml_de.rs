//! TOML files read into serde types with every refusal kept as data: the
//! key, its table, its place in the file and what was wrong, as values
//! (not a message to take apart afterwards).
//!
//! The text is parsed by the `toml` crate into its spanned document
//! ([`toml::de::DeTable`]); this deserializer walks that document, so that
//! serde's refusals (a missing key, an unknown key or variant, a value of
//! the wrong type or length) are built by [`Refused`]'s own constructors,
//! and the walk adds where they happened.

// A refusal carries its key, table and span by value: it is made once per
// file read, so its size costs nothing worth a box.
#![allow(clippy::result_large_err)]

use std::fmt;
use std::ops::Range;

use serde::de::{self, DeserializeSeed, IntoDeserializer, Visitor};
use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// What a refused value was refused for.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Kind {
    /// A required key is missing.
    Missing(&'static str),
    /// A key (or, for `variant`, a value naming a variant) that is not one
    /// of `expected`.
    Unknown {
        name: String,
        expected: &'static [&'static str],
        variant: bool,
    },
    /// A value of the wrong type: what was found, what was expected.
    Type { found: String, expected: String },
    /// A list of the wrong length.
    Length { found: usize, expected: usize },
    /// A value refused by a check of its own.
    Custom(String),
}

/// A value of a TOML file refused while reading it into a type.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Refused {
    pub(crate) kind: Kind,
    /// The key of the value refused, when the refusal is about one.
    pub(crate) key: Option<String>,
    /// The table it is in (`[photos]`, `[[load]]`); `None` at the top.
    pub(crate) table: Option<String>,
    /// Bytes of the file where it is.
    pub(crate) span: Option<Range<usize>>,
}

impl Refused {
    fn new(kind: Kind) -> Self {
        Refused {
            kind,
            key: None,
            table: None,
            span: None,
        }
    }
}

/// serde's own wording for a list of names ("`a`", "`a` or `b`", "one of
/// `a`, `b`, `c`").
fn one_of(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.len() {
        0 => "nothing".to_string(),
        1 => quoted[0].clone(),
        2 => format!("{} or {}", quoted[0], quoted[1]),
        _ => format!("one of {}", quoted.join(", ")),
    }
}

impl fmt::Display for Refused {
    /// In the words of the file: the key and its table named, what it must
    /// be; an unknown name with the nearest known one suggested.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let within = self
            .table
            .as_deref()
            .map_or(String::new(), |t| format!(" in {t}"));
        let what = |default: &str| {
            self.key
                .as_deref()
                .map_or(default.to_string(), |k| format!("`{k}`"))
        };
        match &self.kind {
            Kind::Missing(field) => write!(
                f,
                "missing key `{field}`{within}: add `{field} = ...` (see the file formats in docs/)"
            ),
            Kind::Unknown {
                name,
                expected,
                variant,
            } => {
                let noun = if *variant { "variant" } else { "field" };
                if let Some(k) = &self.key {
                    write!(f, "`{k}`{within}: ")?;
                }
                write!(f, "unknown {noun} `{name}`, expected {}", one_of(expected))?;
                if self.key.is_none() {
                    write!(f, "{within}")?;
                }
                if let Some(hint) = super::nearest_name(name, expected.iter().copied()) {
                    write!(f, "; did you mean `{hint}`?")?;
                }
                Ok(())
            }
            Kind::Type { found, expected } => {
                write!(
                    f,
                    "{}{within} must be {expected}, not {found}",
                    what("a value")
                )
            }
            Kind::Length { found, expected } => write!(
                f,
                "{}{within} must be a list of {expected} values, not {found}",
                what("a list")
            ),
            Kind::Custom(m) => match &self.key {
                Some(k) => write!(f, "`{k}`{within}: {m}"),
                None => write!(f, "{m}{within}"),
            },
        }
    }
}

impl std::error::Error for Refused {}

impl de::Error for Refused {
    fn custom<T: fmt::Display>(msg: T) -> Self {
        Refused::new(Kind::Custom(msg.to_string()))
    }

    fn invalid_type(unexp: de::Unexpected<'_>, exp: &dyn de::Expected) -> Self {
        Refused::new(Kind::Type {
            found: unexp.to_string(),
            expected: exp.to_string(),
        })
    }

    fn invalid_value(unexp: de::Unexpected<'_>, exp: &dyn de::Expected) -> Self {
        Self::invalid_type(unexp, exp)
    }

    fn unknown_variant(variant: &str, expected: &'static [&'static str]) -> Self {
        Refused::new(Kind::Unknown {
            name: variant.to_string(),
            expected,
            variant: true,
        })
    }

    fn unknown_field(field: &str, expected: &'static [&'static str]) -> Self {
        Refused::new(Kind::Unknown {
            name: field.to_string(),
            expected,
            variant: false,
        })
    }

    fn missing_field(field: &'static str) -> Self {
        Refused::new(Kind::Missing(field))
    }
}

/// `text` read into `T`. A syntax error comes back as the `toml` crate's.
pub(crate) fn from_str<T: de::DeserializeOwned>(text: &str) -> Result<T, Error> {
    let doc = DeTable::parse(text).map_err(Error::Syntax)?;
    let span = doc.span();
    let root = Value {
        value: &DeValue::Table(doc.into_inner()),
        span,
        path: &[],
    };
    T::deserialize(root).map_err(Error::Refused)
}

/// Why a TOML text was not read.
#[derive(Debug)]
pub(crate) enum Error {
    /// Not TOML.
    Syntax(toml::de::Error),
    /// TOML, refused by the type.
    Refused(Refused),
}

/// One step of the way to a value: a key, or an element of an array.
#[derive(Debug, Clone)]
enum Step {
    Key(String),
    Index,
}

/// The table header of `path` (`[a.b]`, or `[[a]]` for an array of tables);
/// `None` at the top.
fn header(path: &[Step]) -> Option<String> {
    let keys: Vec<&str> = path
        .iter()
        .filter_map(|s| match s {
            Step::Key(k) => Some(k.as_str()),
            Step::Index => None,
        })
        .collect();
    if keys.is_empty() {
        return None;
    }
    Some(match path.last() {
        Some(Step::Index) => format!("[[{}]]", keys.join(".")),
        _ => format!("[{}]", keys.join(".")),
    })
}

/// Adds where a refusal happened, innermost first: a place already set is
/// kept.
fn at<T>(r: Result<T, Refused>, span: &Range<usize>) -> Result<T, Refused> {
    r.map_err(|mut e| {
        if e.span.is_none() {
            e.span = Some(span.clone());
        }
        e
    })
}

/// A value of the document and where it is.
struct Value<'a, 'i> {
    value: &'a DeValue<'i>,
    span: Range<usize>,
    path: &'a [Step],
}

impl Value<'_, '_> {
    /// The value as serde's `Unexpected` says it ("string \"low\"").
    fn found(&self) -> String {
        match self.value {
            DeValue::String(s) => de::Unexpected::Str(s).to_string(),
            DeValue::Integer(i) => format!("integer `{i}`"),
            DeValue::Float(x) => format!("floating point `{x}`"),
            DeValue::Boolean(b) => de::Unexpected::Bool(*b).to_string(),
            DeValue::Datetime(d) => format!("date-time `{d}`"),
            DeValue::Array(_) => "a list".to_string(),
            DeValue::Table(_) => "a table".to_string(),
        }
    }

    fn wrong(&self, expected: &str) -> Refused {
        Refused {
            span: Some(self.span.clone()),
            ..Refused::new(Kind::Type {
                found: self.found(),
                expected: expected.to_string(),
            })
        }
    }

    fn integer(&self) -> Option<Result<i64, u64>> {
        match self.value {
            DeValue::Integer(i) => match i64::from_str_radix(i.as_str(), i.radix()) {
                Ok(v) => Some(Ok(v)),
                Err(_) => u64::from_str_radix(i.as_str(), i.radix()).ok().map(Err),
            },
            _ => None,
        }
    }
}

macro_rules! whole {
    ($($method:ident)*) => {$(
        fn $method<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Refused> {
            let span = self.span.clone();
            match self.integer() {
                Some(Ok(v)) if v >= 0 => at(visitor.visit_u64(v as u64), &span),
                Some(Err(v)) => at(visitor.visit_u64(v), &span),
                _ => Err(self.wrong("a whole number >= 0")),
            }
        }
    )*};
}

macro_rules! signed {
    ($($method:ident)*) => {$(
        fn $method<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Refused> {
            let span = self.span.clone();
            match self.integer() {
                Some(Ok(v)) => at(visitor.visit_i64(v), &span),
                _ => Err(self.wrong("a whole number")),
            }
        }
    )*};
}

macro_rules! real {
    ($($method:ident)*) => {$(
        fn $method<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Refused> {
            let span = self.span.clone();
            match (self.value, self.integer()) {
                (_, Some(Ok(v))) => at(visitor.visit_i64(v), &span),
                (DeValue::Float(x), _) => match x.as_str().parse::<f64>() {
                    Ok(v) => at(visitor.visit_f64(v), &span),
                    Err(_) => Err(self.wrong("a number")),
                },
                _ => Err(self.wrong("a number")),
            }
        }
    )*};
}

impl<'de> de::Deserializer<'de> for Value<'_, '_> {
    type Error = Refused;

    fn deserialize_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Refused> {
        let span = self.span.clone();
        let r = match self.value {
            DeValue::String(s) => visitor.visit_str(s),
            DeValue::Boolean(b) => visitor.visit_bool(*b),
            DeValue::Datetime(d) => visitor.visit_string(d.to_string()),
            DeValue::Integer(_) => match self.integer() {
                Some(Ok(v)) => visitor.visit_i64(v),
                Some(Err(v)) => visitor.visit_u64(v),
                None => return Err(self.wrong("a whole number that fits in 64 bits")),
            },
            DeValue::Float(x) => match x.as_str().parse::<f64>() {
                Ok(v) => visitor.visit_f64(v),
                Err(_) => return Err(self.wrong("a number")),
            },
            DeValue::Array(items) => visitor.visit_seq(Seq {
                items: items.iter(),
                path: self.path,
            }),
            DeValue::Table(t) => {
                let table = header(self.path);
                let r = visitor.visit_map(Map {
                    entries: t.iter(),
                    path: self.path,
                    pending: None,
                });
                return at(
                    r.map_err(|mut e| {
                        if e.table.is_none() {
                            e.table = table;
                        }
                        e
                    }),
                    &span,
                );
            }
        };
        at(r, &span)
    }

    whole!(deserialize_u8 deserialize_u16 deserialize_u32 deserialize_u64 deserialize_u128);
    signed!(deserialize_i8 deserialize_i16 deserialize_i32 deserialize_i64 deserialize_i128);
    real!(deserialize_f32 deserialize_f64);

    fn deserialize_option<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Refused> {
        visitor.visit_some(self)
    }

    fn deserialize_newtype_struct<V: Visitor<'de>>(
        self,
        _name: &'static str,
        visitor: V,
    ) -> Result<V::Value, Refused> {
        visitor.visit_newtype_struct(self)
    }

    fn deserialize_tuple<V: Visitor<'de>>(
        self,
        len: usize,
        visitor: V,
    ) -> Result<V::Value, Refused> {
        match self.value {
            DeValue::Array(items) if items.len() != len => Err(Refused {
                span: Some(self.span.clone()),
                ..Refused::new(Kind::Length {
                    found: items.len(),
                    expected: len,
                })
            }),
            _ => self.deserialize_any(visitor),
        }
    }

    fn deserialize_enum<V: Visitor<'de>>(
        self,
        _name: &'static str,
        _variants: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Refused> {
        let span = self.span.clone();
        match self.value {
            DeValue::String(s) => {
                let unit: de::value::StrDeserializer<'_, Refused> = s.as_ref().into_deserializer();
                at(visitor.visit_enum(unit), &span)
            }
            DeValue::Table(t) if t.len() == 1 => {
                let (k, v) = t.iter().next().expect("one entry");
                let path: Vec<Step> = self
                    .path
                    .iter()
                    .cloned()
                    .chain([Step::Key(k.get_ref().to_string())])
                    .collect();
                let inner = Value {
                    value: v.get_ref(),
                    span: v.span(),
                    path: &path,
                };
                at(
                    visitor.visit_enum(Enum {
                        name: k.get_ref(),
                        value: inner,
                    }),
                    &span,
                )
            }
            _ => Err(self.wrong("a name in quotes")),
        }
    }

    fn deserialize_ignored_any<V: Visitor<'de>>(self, visitor: V) -> Result<V::Value, Refused> {
        visitor.visit_unit()
    }

    serde::forward_to_deserialize_any! {
        bool char str string bytes byte_buf unit unit_struct seq tuple_struct map struct
        identifier
    }
}

/// The entries of a table.
struct Map<'a, 'i> {
    entries: toml::map::Iter<'a, Spanned<std::borrow::Cow<'i, str>>, Spanned<DeValue<'i>>>,
    path: &'a [Step],
    pending: Option<(String, &'a Spanned<DeValue<'i>>)>,
}

impl<'de> de::MapAccess<'de> for Map<'_, '_> {
    type Error = Refused;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, Refused> {
        let Some((k, v)) = self.entries.next() else {
            return Ok(None);
        };
        let key = k.get_ref().to_string();
        self.pending = Some((key.clone(), v));
        let name: de::value::StrDeserializer<'_, Refused> =
            k.get_ref().as_ref().into_deserializer();
        seed.deserialize(name).map(Some).map_err(|mut e| {
            e.key.get_or_insert(key);
            e.table = e.table.or_else(|| header(self.path));
            e.span.get_or_insert(k.span());
            e
        })
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, Refused> {
        let (key, v) = self
            .pending
            .take()
            .expect("serde asks for a key before its value");
        let path: Vec<Step> = self
            .path
            .iter()
            .cloned()
            .chain([Step::Key(key.clone())])
            .collect();
        let value = Value {
            value: v.get_ref(),
            span: v.span(),
            path: &path,
        };
        seed.deserialize(value).map_err(|mut e| {
            // a refusal of the value itself names its key and table
            if e.key.is_none() && !matches!(v.get_ref(), DeValue::Table(_)) {
                e.key = Some(key);
                e.table = e.table.or_else(|| header(self.path));
            }
            e
        })
    }
}

/// The elements of an array.
struct Seq<'a, 'i> {
    items: std::slice::Iter<'a, Spanned<DeValue<'i>>>,
    path: &'a [Step],
}

impl<'de> de::SeqAccess<'de> for Seq<'_, '_> {
    type Error = Refused;

    fn next_element_seed<T: DeserializeSeed<'de>>(
        &mut self,
        seed: T,
    ) -> Result<Option<T::Value>, Refused> {
        let Some(v) = self.items.next() else {
            return Ok(None);
        };
        let path: Vec<Step> = self.path.iter().cloned().chain([Step::Index]).collect();
        seed.deserialize(Value {
            value: v.get_ref(),
            span: v.span(),
            path: &path,
        })
        .map(Some)
    }

    fn size_hint(&self) -> Option<usize> {
        Some(self.items.len())
    }
}

/// A table of one key naming an enum's variant.
struct Enum<'a, 'i> {
    name: &'a str,
    value: Value<'a, 'i>,
}

impl<'de, 'a, 'i> de::EnumAccess<'de> for Enum<'a, 'i> {
    type Error = Refused;
    type Variant = Value<'a, 'i>;

    fn variant_seed<V: DeserializeSeed<'de>>(
        self,
        seed: V,
    ) -> Result<(V::Value, Self::Variant), Refused> {
        let name: de::value::StrDeserializer<'_, Refused> = self.name.into_deserializer();
        Ok((seed.deserialize(name)?, self.value))
    }
}

impl<'de> de::VariantAccess<'de> for Value<'_, '_> {
    type Error = Refused;

    fn unit_variant(self) -> Result<(), Refused> {
        Err(self.wrong("no value"))
    }

    fn newtype_variant_seed<T: DeserializeSeed<'de>>(self, seed: T) -> Result<T::Value, Refused> {
        seed.deserialize(self)
    }

    fn tuple_variant<V: Visitor<'de>>(self, len: usize, visitor: V) -> Result<V::Value, Refused> {
        de::Deserializer::deserialize_tuple(self, len, visitor)
    }

    fn struct_variant<V: Visitor<'de>>(
        self,
        _fields: &'static [&'static str],
        visitor: V,
    ) -> Result<V::Value, Refused> {
        de::Deserializer::deserialize_any(self, visitor)
    }
}
