//! Grayscale images: decoding (OpenCV), cropping, encoding, and the
//! structural checks that catch truncated files which the codecs would
//! otherwise decode silently into grey.

use std::path::Path;

use opencv::core::{Mat, MatTraitConst, MatTraitConstManual, Vector};
use opencv::imgcodecs;

use super::TrackError;

/// Sets OpenCV's own thread pool to one thread, once per process, before
/// this crate's first OpenCV call; every OpenCV entry of the crate passes
/// here first.
///
/// bulge runs its OpenCV calls on several threads of its own (rayon decodes
/// the photos in parallel, and a program may track several experiments at
/// once), so OpenCV's pool would only compete with them for the cores. The
/// setting is made once, before any other OpenCV call of the crate, because
/// it is not safe to make concurrently: with OpenCV's TBB back-end,
/// `cv::setNumThreads` tears down and rebuilds a process-wide task arena,
/// and two threads doing so at once crash the process.
pub(crate) fn opencv_serial() -> Result<(), opencv::Error> {
    static SET: std::sync::OnceLock<Result<(), (i32, String)>> = std::sync::OnceLock::new();
    SET.get_or_init(|| opencv::core::set_num_threads(1).map_err(|e| (e.code, e.message)))
        .clone()
        .map_err(|(code, message)| opencv::Error::new(code, message))
}

/// The light of each 8-bit grey level on the same 0-255 scale (the camera's
/// tone curve inverted, [`crate::camera::Response`]), or none when grey
/// levels are light already.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tone(Option<&'static [f32; 256]>);

impl Tone {
    /// Grey levels are light (a linear camera, or a drawn test image).
    pub const LINEAR: Tone = Tone(None);

    /// The table of a tone curve (built once per curve and process).
    pub fn of(r: crate::camera::Response) -> Tone {
        use crate::camera::Response;
        static SRGB: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
        static GAMMAS: std::sync::Mutex<Vec<(u64, &'static [f32; 256])>> =
            std::sync::Mutex::new(Vec::new());
        if r.is_linear() {
            return Tone::LINEAR;
        }
        match r {
            Response::Srgb => Tone(Some(SRGB.get_or_init(|| r.table_8bit()))),
            _ => {
                // A process sees a handful of gammas: each table is kept.
                let key = match r {
                    Response::Gamma(g) => g.to_bits(),
                    _ => 0,
                };
                let mut g = GAMMAS.lock().unwrap_or_else(|e| e.into_inner());
                if let Some((_, t)) = g.iter().find(|(k, _)| *k == key) {
                    return Tone(Some(t));
                }
                let t: &'static [f32; 256] = Box::leak(Box::new(r.table_8bit()));
                g.push((key, t));
                Tone(Some(t))
            }
        }
    }

    /// The light of grey level `v`, 0-255.
    #[inline]
    pub fn light(self, v: u8) -> f64 {
        match self.0 {
            None => f64::from(v),
            Some(t) => f64::from(t[v as usize]),
        }
    }

    /// The grey level, fractional, whose light is `l`: [`Tone::light`]
    /// inverted, linearly between the table's entries (light beyond its
    /// ends gives 0 or 255).
    pub fn encode(self, l: f64) -> f64 {
        match self.0 {
            None => l,
            Some(t) => {
                let i = t.partition_point(|&v| f64::from(v) <= l);
                if i == 0 {
                    return 0.0;
                }
                if i == t.len() {
                    return 255.0;
                }
                let (a, b) = (f64::from(t[i - 1]), f64::from(t[i]));
                (i - 1) as f64 + (l - a) / (b - a)
            }
        }
    }
}

/// An 8-bit grayscale image (or a crop of one), row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct Gray {
    /// Width, px.
    pub width: usize,
    /// Height, px.
    pub height: usize,
    /// `width * height` grey levels, row-major.
    pub data: Vec<u8>,
    /// The camera's tone curve: edges are located on [`Gray::light`].
    pub tone: Tone,
}

impl Gray {
    /// An image whose grey levels are light ([`Tone::LINEAR`]).
    pub fn new(width: usize, height: usize, data: Vec<u8>) -> Gray {
        Gray {
            width,
            height,
            data,
            tone: Tone::LINEAR,
        }
    }

    /// A grey level (no bounds check beyond the slice's).
    #[inline]
    pub fn at(&self, x: usize, y: usize) -> u8 {
        self.data[y * self.width + x]
    }

    /// The light at a pixel, on the 0-255 scale of grey levels (the grey
    /// level through the inverted tone curve).
    #[inline]
    pub fn light(&self, x: usize, y: usize) -> f64 {
        self.tone.light(self.data[y * self.width + x])
    }

    /// The same image with grey levels read through `tone`.
    pub fn with_tone(mut self, tone: Tone) -> Gray {
        self.tone = tone;
        self
    }

    /// A copy of the rectangle `[x, y, w, h]`, which must lie inside.
    pub fn crop(&self, x: usize, y: usize, w: usize, h: usize) -> Gray {
        debug_assert!(x + w <= self.width && y + h <= self.height);
        let mut data = Vec::with_capacity(w * h);
        for r in y..y + h {
            let s = r * self.width + x;
            data.extend_from_slice(&self.data[s..s + w]);
        }
        Gray {
            width: w,
            height: h,
            data,
            tone: self.tone,
        }
    }

    /// Borrows the image as an OpenCV `Mat` header (no copy).
    pub(crate) fn as_mat(&self) -> Result<opencv::boxed_ref::BoxedRef<'_, Mat>, opencv::Error> {
        opencv_serial()?;
        Mat::new_rows_cols_with_data(self.height as i32, self.width as i32, &self.data)
    }
}

/// What decoding a file gives: the full image size and the requested crop.
#[derive(Debug, Clone)]
pub struct Decoded {
    /// Full image width, px.
    pub width: usize,
    /// Full image height, px.
    pub height: usize,
    /// The crop (the region of interest, or the whole image).
    pub crop: Gray,
}

/// Checks the container's end marker so that a truncated PNG or JPEG is
/// refused instead of decoded into grey rows (libjpeg and libpng both
/// "recover" silently). Other formats are left to the codec.
pub fn check_complete(path: &Path, bytes: &[u8]) -> Result<(), TrackError> {
    let truncated = |what: &str| TrackError::Truncated {
        path: path.to_path_buf(),
        reason: what.to_string(),
    };
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        // The last chunk must be IEND: length 0, type "IEND", CRC AE426082.
        if bytes.len() < 8 + 12 || &bytes[bytes.len() - 12..] != b"\0\0\0\0IEND\xaeB`\x82" {
            return Err(truncated("the PNG file does not end with its IEND chunk"));
        }
    } else if bytes.starts_with(&[0xFF, 0xD8]) {
        // Some cameras pad after the end-of-image marker: skip trailing zeros.
        let end = bytes.iter().rposition(|&b| b != 0).map_or(0, |i| i + 1);
        if end < 4 || bytes[end - 2..end] != [0xFF, 0xD9] {
            return Err(truncated(
                "the JPEG file does not end with its end-of-image marker FFD9",
            ));
        }
    }
    Ok(())
}

/// Reads and decodes one photo to grayscale; `roi` = `[x, y, w, h]` crops it
/// (checked against the decoded size), `None` keeps the whole image.
pub fn read_gray(path: &Path, roi: Option<[usize; 4]>) -> Result<Decoded, TrackError> {
    let bytes = std::fs::read(path).map_err(|e| TrackError::Unreadable {
        path: path.to_path_buf(),
        reason: e.to_string(),
    })?;
    decode_gray(path, &bytes, roi)
}

/// Decodes encoded bytes (named `path` in errors): a truncated file, bytes
/// OpenCV cannot decode and an empty image are refused.
fn decode_checked(path: &Path, bytes: &[u8]) -> Result<Mat, TrackError> {
    if bytes.is_empty() {
        return Err(TrackError::Unreadable {
            path: path.to_path_buf(),
            reason: "the file is empty (0 bytes)".into(),
        });
    }
    check_complete(path, bytes)?;
    // OpenCV's own message (an assertion in imdecode) says nothing a user can act on.
    let mat = decode_mat(bytes).unwrap_or_default();
    if mat.empty() || mat.rows() <= 0 || mat.cols() <= 0 {
        return Err(TrackError::Unreadable {
            path: path.to_path_buf(),
            reason:
                "OpenCV cannot decode it (not an image, an unsupported format, or a damaged file)"
                    .to_string(),
        });
    }
    Ok(mat)
}

/// Decodes encoded bytes (named `path` in errors) to grayscale.
pub fn decode_gray(
    path: &Path,
    bytes: &[u8],
    roi: Option<[usize; 4]>,
) -> Result<Decoded, TrackError> {
    let mat = decode_checked(path, bytes)?;
    let roi = roi.unwrap_or([0, 0, mat.cols() as usize, mat.rows() as usize]);
    crop_mat(path, &mat, roi)
}

/// Decodes a photo of a sequence and crops the region `roi`; when the region
/// does not fit (or is `None`), the crop is empty and only the size counts.
pub fn decode_gray_lenient(
    path: &Path,
    bytes: &[u8],
    roi: Option<[usize; 4]>,
) -> Result<Decoded, TrackError> {
    let mat = decode_checked(path, bytes)?;
    crop_lenient(path, &mat, roi)
}

/// Crops the region `roi` of a decoded 8-bit grayscale image; when the region
/// does not fit (or is `None`), the crop is empty and only the size counts.
pub(crate) fn crop_lenient(
    path: &Path,
    mat: &Mat,
    roi: Option<[usize; 4]>,
) -> Result<Decoded, TrackError> {
    let (width, height) = (mat.cols() as usize, mat.rows() as usize);
    match roi {
        Some([x, y, w, h]) if x + w <= width && y + h <= height => {
            crop_mat(path, mat, [x, y, w, h])
        }
        _ => Ok(Decoded {
            width,
            height,
            crop: Gray {
                width: 0,
                height: 0,
                data: Vec::new(),
                tone: Tone::LINEAR,
            },
        }),
    }
}

/// Crops the rectangle `roi` of an 8-bit grayscale image (refused when it
/// does not fit).
pub(crate) fn crop_mat(path: &Path, mat: &Mat, roi: [usize; 4]) -> Result<Decoded, TrackError> {
    let (width, height) = (mat.cols() as usize, mat.rows() as usize);
    let [x, y, w, h] = roi;
    if x + w > width || y + h > height {
        return Err(TrackError::RegionOutside {
            path: path.to_path_buf(),
            roi: [x as i64, y as i64, w as i64, h as i64],
            width,
            height,
        });
    }
    let mut data = Vec::with_capacity(w * h);
    for r in y..y + h {
        let row: &[u8] = mat
            .at_row::<u8>(r as i32)
            .map_err(|e| TrackError::OpenCv(e.to_string()))?;
        data.extend_from_slice(&row[x..x + w]);
    }
    Ok(Decoded {
        width,
        height,
        crop: Gray {
            width: w,
            height: h,
            data,
            tone: Tone::LINEAR,
        },
    })
}

/// The bare decode (what the benchmark calls "decoding alone").
pub fn decode_mat(bytes: &[u8]) -> Result<Mat, opencv::Error> {
    opencv_serial()?;
    imgcodecs::imdecode(&bytes, imgcodecs::IMREAD_GRAYSCALE)
}

/// Encoding of synthetic photos.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Encoding {
    /// Lossless PNG (compression level 3).
    Png,
    /// JPEG with the given quality (1..=100).
    Jpeg(u8),
}

impl Encoding {
    /// File extension without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Encoding::Png => "png",
            Encoding::Jpeg(_) => "jpg",
        }
    }
}

/// Encodes a grayscale image.
pub fn encode(img: &Gray, enc: Encoding) -> Result<Vec<u8>, TrackError> {
    let mat = img
        .as_mat()
        .map_err(|e| TrackError::OpenCv(e.to_string()))?;
    let mut buf = Vector::<u8>::new();
    let (ext, params) = match enc {
        Encoding::Png => (".png", vec![imgcodecs::IMWRITE_PNG_COMPRESSION, 3]),
        Encoding::Jpeg(q) => (".jpg", vec![imgcodecs::IMWRITE_JPEG_QUALITY, i32::from(q)]),
    };
    let ok = imgcodecs::imencode(ext, &mat, &mut buf, &Vector::from_slice(&params))
        .map_err(|e| TrackError::OpenCv(e.to_string()))?;
    if !ok {
        return Err(TrackError::OpenCv(format!(
            "OpenCV could not encode a {ext} image"
        )));
    }
    Ok(buf.as_slice().to_vec())
}
