//! The camera's tone curve: how a photo's pixel values relate to the light
//! that reached the sensor.
//!
//! A lens blurs light, not pixel values. The sensor integrates the blurred
//! irradiance linearly; the camera then encodes it for display through a
//! non-linear tone curve (sRGB for nearly every 8-bit JPEG or PNG). A
//! symmetric blur of a step in light is symmetric about the edge, so the
//! edge lies where the light is halfway between the two sides; after the
//! tone curve the encoded step is no longer symmetric, and its halfway
//! value lies off the edge by a fraction of the blur (about a quarter of a
//! pixel for a blur of 1.5 px between a dark dome and a light wall).
//! Edges are therefore located on values mapped back to linear light.
//!
//! The sRGB curve is that of IEC 61966-2-1:1999 (Multimedia systems and
//! equipment, colour measurement and management, part 2-1: default RGB
//! colour space, sRGB): linear below 0.04045 (encoded) and a 2.4 power with
//! an offset above.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// The camera's tone curve (`[camera] response` in the experiment file).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Response {
    /// The sRGB curve (the default for 8-bit photos: JPEG and PNG from
    /// cameras and phones are encoded so).
    #[default]
    Srgb,
    /// Pixel values proportional to light (raw, 16-bit scientific cameras,
    /// or photos already linearised).
    Linear,
    /// A pure power law: value = light^(1/gamma), `gamma` > 0.
    Gamma(f64),
}

impl Response {
    /// Light (0 to 1) of an encoded value (0 to 1).
    pub fn to_linear(self, v: f64) -> f64 {
        match self {
            Response::Linear => v,
            Response::Srgb => {
                if v <= 0.04045 {
                    v / 12.92
                } else {
                    ((v + 0.055) / 1.055).powf(2.4)
                }
            }
            Response::Gamma(g) => v.max(0.0).powf(g),
        }
    }

    /// Encoded value (0 to 1) of light (0 to 1): the inverse of
    /// [`Response::to_linear`].
    pub fn encode(self, l: f64) -> f64 {
        match self {
            Response::Linear => l,
            Response::Srgb => {
                if l <= 0.0031308 {
                    12.92 * l
                } else {
                    1.055 * l.powf(1.0 / 2.4) - 0.055
                }
            }
            Response::Gamma(g) => l.max(0.0).powf(1.0 / g),
        }
    }

    /// The light of each 8-bit value, on the same 0-255 scale (so that
    /// grey-level thresholds keep their size near the top of the range):
    /// `255 to_linear(v / 255)`.
    pub fn table_8bit(self) -> [f32; 256] {
        let mut t = [0.0f32; 256];
        for (v, out) in t.iter_mut().enumerate() {
            *out = (255.0 * self.to_linear(v as f64 / 255.0)) as f32;
        }
        t
    }

    /// Whether the curve is the identity.
    pub fn is_linear(self) -> bool {
        matches!(self, Response::Linear) || matches!(self, Response::Gamma(g) if g == 1.0)
    }

    /// The name as written in the experiment file: `"srgb"`, `"linear"`, or
    /// the gamma as a number.
    pub fn name(self) -> String {
        match self {
            Response::Srgb => "srgb".into(),
            Response::Linear => "linear".into(),
            Response::Gamma(g) => format!("gamma {g}"),
        }
    }

    /// Checks a gamma (finite, 0.2 to 5).
    pub fn validate(self) -> Result<(), ResponseError> {
        match self {
            Response::Gamma(g) if !(g.is_finite() && (0.2..=5.0).contains(&g)) => {
                Err(ResponseError::Gamma(g))
            }
            _ => Ok(()),
        }
    }
}

/// A tone curve that is not one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ResponseError {
    /// Neither a name nor a number.
    #[error("camera response {0:?} is not \"srgb\", \"linear\" or a gamma such as 2.2")]
    Unknown(String),
    /// A gamma out of range.
    #[error(
        "response = {0}: a camera's gamma lies between 0.2 and 5 (2.2 for most displays); write \"srgb\" for an ordinary 8-bit photo, \"linear\" for a raw or 16-bit one"
    )]
    Gamma(f64),
}

impl std::str::FromStr for Response {
    type Err = ResponseError;

    /// `srgb`, `linear`, or a gamma (`2.2`, `gamma:2.2`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim().to_ascii_lowercase();
        let r = match t.as_str() {
            "srgb" => Response::Srgb,
            "linear" => Response::Linear,
            _ => {
                let num = t.strip_prefix("gamma:").unwrap_or(&t);
                let g: f64 = num
                    .parse()
                    .map_err(|_| ResponseError::Unknown(s.to_string()))?;
                Response::Gamma(g)
            }
        };
        r.validate()?;
        Ok(r)
    }
}

impl Serialize for Response {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            Response::Srgb => s.serialize_str("srgb"),
            Response::Linear => s.serialize_str("linear"),
            Response::Gamma(g) => s.serialize_f64(*g),
        }
    }
}

impl<'de> Deserialize<'de> for Response {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Name(String),
            Gamma(f64),
        }
        let r = match Raw::deserialize(d)? {
            Raw::Name(s) => s.parse().map_err(serde::de::Error::custom)?,
            Raw::Gamma(g) => Response::Gamma(g),
        };
        r.validate().map_err(serde::de::Error::custom)?;
        Ok(r)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_matches_the_standards_table_and_inverts() {
        // IEC 61966-2-1: encoded 0.5 is light 0.21404; light 0.5 encodes to
        // 0.73536; the two pieces meet at 0.04045 / 0.0031308.
        assert!((Response::Srgb.to_linear(0.5) - 0.214_041).abs() < 1e-6);
        assert!((Response::Srgb.encode(0.5) - 0.735_357).abs() < 1e-6);
        assert!((Response::Srgb.to_linear(0.04045) - 0.0031308).abs() < 1e-6);
        for r in [Response::Srgb, Response::Linear, Response::Gamma(2.2)] {
            for k in 0..=100 {
                let v = k as f64 / 100.0;
                assert!((r.encode(r.to_linear(v)) - v).abs() < 1e-12, "{r:?} {v}");
            }
        }
        let t = Response::Srgb.table_8bit();
        assert_eq!(t[0], 0.0);
        assert_eq!(t[255], 255.0);
        assert!(t.windows(2).all(|w| w[1] > w[0]));
    }

    #[test]
    fn the_file_spells_it_as_a_name_or_a_gamma() {
        #[derive(Deserialize)]
        struct C {
            response: Response,
        }
        let r = |s: &str| toml::from_str::<C>(s).map(|c| c.response);
        assert_eq!(r("response = \"srgb\"").unwrap(), Response::Srgb);
        assert_eq!(r("response = \"LINEAR\"").unwrap(), Response::Linear);
        assert_eq!(r("response = 2.2").unwrap(), Response::Gamma(2.2));
        assert_eq!(r("response = \"gamma:1.8\"").unwrap(), Response::Gamma(1.8));
        assert!(r("response = 0.0").is_err());
        assert!(r("response = \"log\"").is_err());
    }
}
