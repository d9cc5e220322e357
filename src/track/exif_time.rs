//! Photo times from the camera: the EXIF `DateTimeOriginal` (with
//! `SubSecTimeOriginal` when the camera writes it), read with the
//! `kamadak-exif` crate. Times are seconds after the first photo's, so a
//! pressure log by time is aligned to them with `[pressure] offset_s` (the
//! logger's clock when the first photo was taken).

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

use exif::{In, Reader, Tag, Value};

/// Seconds since 1970-01-01 of an EXIF date and time (the camera's local
/// time; only differences are used).
fn seconds(dt: &exif::DateTime) -> f64 {
    // Days from the civil date (H. Hinnant's algorithm, proleptic Gregorian).
    let (y, m, d) = (dt.year as i64, dt.month as i64, dt.day as i64);
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * ((m + 9) % 12) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    (days * 86_400 + dt.hour as i64 * 3600 + dt.minute as i64 * 60 + dt.second as i64) as f64
        + dt.nanosecond.map_or(0.0, |n| n as f64 * 1e-9)
}

fn ascii(f: &exif::Field) -> Option<&[u8]> {
    match &f.value {
        Value::Ascii(v) => v.first().map(Vec::as_slice),
        _ => None,
    }
}

/// Why a photo has no time.
#[derive(Debug, thiserror::Error)]
pub enum NoTime {
    /// The file cannot be opened.
    #[error("cannot open it: {0}")]
    Open(std::io::Error),
    /// The file holds no EXIF data.
    #[error("no EXIF data ({0})")]
    NoExif(exif::Error),
    /// The EXIF data have no date.
    #[error("its EXIF data have no DateTimeOriginal")]
    NoDate,
    /// The date is not one.
    #[error("its EXIF DateTimeOriginal is not a date and time")]
    BadDate,
}

/// The time a photo was taken, s since 1970 in the camera's clock, or why
/// it has none.
pub fn photo_time(path: &Path) -> Result<f64, NoTime> {
    let file = File::open(path).map_err(NoTime::Open)?;
    let exif = Reader::new()
        .read_from_container(&mut BufReader::new(file))
        .map_err(NoTime::NoExif)?;
    let field = exif
        .get_field(Tag::DateTimeOriginal, In::PRIMARY)
        .ok_or(NoTime::NoDate)?;
    let mut dt = ascii(field)
        .and_then(|a| exif::DateTime::from_ascii(a).ok())
        .ok_or(NoTime::BadDate)?;
    if let Some(sub) = exif
        .get_field(Tag::SubSecTimeOriginal, In::PRIMARY)
        .and_then(ascii)
    {
        dt.parse_subsec(sub).ok();
    }
    Ok(seconds(&dt))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A JPEG's bytes with an EXIF block holding `DateTimeOriginal` (and
    /// `SubSecTimeOriginal`) inserted after its start marker: the TIFF
    /// structure of the EXIF 2.3 standard (CIPA DC-008), little-endian, IFD0
    /// with the Exif IFD pointer, the Exif IFD with the two tags.
    pub(crate) fn with_exif(jpeg: &[u8], date_time: &str, subsec: Option<&str>) -> Vec<u8> {
        let mut t: Vec<u8> = b"II*\0".to_vec();
        t.extend(8u32.to_le_bytes());
        // IFD0 at 8: one entry, then the next-IFD offset 0.
        t.extend(1u16.to_le_bytes());
        let exif_ifd = 8 + 2 + 12 + 4;
        t.extend(0x8769u16.to_le_bytes());
        t.extend(4u16.to_le_bytes()); // LONG
        t.extend(1u32.to_le_bytes());
        t.extend((exif_ifd as u32).to_le_bytes());
        t.extend(0u32.to_le_bytes());
        // Exif IFD: DateTimeOriginal (ASCII 20) and SubSecTimeOriginal.
        let entries: Vec<(u16, Vec<u8>)> = std::iter::once((0x9003u16, date_time))
            .chain(subsec.map(|s| (0x9291u16, s)))
            .map(|(tag, s)| {
                let mut v = s.as_bytes().to_vec();
                v.push(0);
                (tag, v)
            })
            .collect();
        let data_at = exif_ifd + 2 + 12 * entries.len() + 4;
        t.extend((entries.len() as u16).to_le_bytes());
        let mut data: Vec<u8> = Vec::new();
        for (tag, v) in &entries {
            t.extend(tag.to_le_bytes());
            t.extend(2u16.to_le_bytes()); // ASCII
            t.extend((v.len() as u32).to_le_bytes());
            if v.len() <= 4 {
                let mut inline = v.clone();
                inline.resize(4, 0);
                t.extend(inline);
            } else {
                t.extend(((data_at + data.len()) as u32).to_le_bytes());
                data.extend(v);
            }
        }
        t.extend(0u32.to_le_bytes());
        t.extend(data);
        let mut app1 = b"Exif\0\0".to_vec();
        app1.extend(t);
        let mut out = jpeg[..2].to_vec();
        out.extend([0xFF, 0xE1]);
        out.extend(((app1.len() + 2) as u16).to_be_bytes());
        out.extend(app1);
        out.extend(&jpeg[2..]);
        out
    }

    /// Dates read back to the second and to the sub-second, across a month
    /// and a leap day; a photo without EXIF data is named as such.
    #[test]
    fn reads_the_time_a_photo_was_taken() {
        let dir = tempfile::tempdir().unwrap();
        let jpeg = [0xFF, 0xD8, 0xFF, 0xD9];
        let at = |name: &str, dt: &str, sub: Option<&str>| {
            let p = dir.path().join(name);
            std::fs::write(&p, with_exif(&jpeg, dt, sub)).unwrap();
            photo_time(&p).unwrap()
        };
        let a = at("a.jpg", "2024:02:28 23:59:58", None);
        let b = at("b.jpg", "2024:02:29 00:00:01", Some("25"));
        let c = at("c.jpg", "2024:03:01 00:00:01", Some("5"));
        assert!((b - a - 3.25).abs() < 1e-9, "{}", b - a);
        assert!((c - b - 86_400.25).abs() < 1e-9, "{}", c - b);
        let bare = dir.path().join("bare.jpg");
        std::fs::write(&bare, jpeg).unwrap();
        assert!(matches!(photo_time(&bare).unwrap_err(), NoTime::NoExif(_)));
    }
}
