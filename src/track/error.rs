//! Why tracking refused its input or failed, and which of those are the
//! user's input.

use std::path::PathBuf;

/// Why tracking refused its input or failed.
#[derive(Debug, thiserror::Error)]
pub enum TrackError {
    /// The file cannot be read or decoded.
    #[error("{}: cannot read the image: {reason}; replace the file or remove it from the folder", path.display())]
    Unreadable {
        /// The photo.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// Something `bulge init` looks for is not in the photos.
    #[error(
        "{what} not found in the photos: {detail}; set {keys} in the experiment file by hand (docs/track.md, \"The experiment file\")"
    )]
    NotFound {
        /// What was looked for.
        what: String,
        /// Why it was not found.
        detail: String,
        /// The keys of the experiment file to set instead.
        keys: &'static str,
        /// Whether what was not found is the clamp plane's (its row, the
        /// ring's ellipse, the camera's elevation, the opening at it),
        /// which init can be given instead (`--clamp-row-px`); not the
        /// bubble, nor a rolled camera, which a row given would hide.
        clamp_plane: bool,
    },
    /// The video cannot be opened or read.
    #[error("{}: cannot read the video: {reason}; fix `video` in [photos] (a file, relative to the experiment file), or convert the video to Motion JPEG in AVI or H.264 in MP4", path.display())]
    Video {
        /// The video.
        path: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// The file ends early.
    #[error("{}: the image is truncated: {reason}; copy it again from the camera or remove it", path.display())]
    Truncated {
        /// The photo.
        path: PathBuf,
        /// What is missing.
        reason: String,
    },
    /// Photos of different sizes.
    #[error(
        "{}: the photo is {width}x{height} px but the reference photo {} is {ref_width}x{ref_height} px; all photos of an experiment must have the same size (remove or re-export the odd ones)",
        path.display(), reference.display()
    )]
    MixedSizes {
        /// The odd photo.
        path: PathBuf,
        /// Its size.
        width: usize,
        /// Its size.
        height: usize,
        /// The reference photo.
        reference: PathBuf,
        /// The reference size.
        ref_width: usize,
        /// The reference size.
        ref_height: usize,
    },
    /// The region (or the template rectangle) is not inside the image.
    #[error(
        "{}: the rectangle [x, y, width, height] = {roi:?} px is not inside the {width}x{height} px image; fix `roi_px` (or `template_rect_px`) in [photos] so that x >= 0, y >= 0, x + width <= {width} and y + height <= {height}",
        path.display()
    )]
    RegionOutside {
        /// The photo it was checked against.
        path: PathBuf,
        /// The rectangle.
        roi: [i64; 4],
        /// Image width.
        width: usize,
        /// Image height.
        height: usize,
    },
    /// The template does not fit in the region.
    #[error(
        "{}: the template is {tw}x{th} px but the region roi_px = {roi:?} is only {rw}x{rh} px; the template must fit inside the region: enlarge `roi_px` or use a smaller template",
        experiment.display(), rw = roi[2], rh = roi[3]
    )]
    TemplateLargerThanRegion {
        /// The experiment file.
        experiment: PathBuf,
        /// Template width.
        tw: usize,
        /// Template height.
        th: usize,
        /// The region.
        roi: [i64; 4],
    },
    /// A photo has no row in the pressure log.
    #[error(
        "{}: no pressure for photo `{file}`; add a row `{file},<pressure in Pa>` (columns file,pressure_pa) or remove the photo",
        csv.display()
    )]
    NoPressure {
        /// The photo's file name.
        file: String,
        /// The pressure log.
        csv: PathBuf,
    },
    /// A frame's time falls outside the span of the pressure log by time.
    #[error("{}: {message}", csv.display())]
    OutsideLog {
        /// The pressure log.
        csv: PathBuf,
        /// The frame, its time on both clocks, both spans and the fix.
        message: String,
    },
    /// The photo folder does not exist or cannot be listed.
    #[error("{}: cannot list the photo folder: {reason}; fix `dir` in [photos] (a folder, relative to the experiment file) or put the photos there", dir.display())]
    PhotoFolder {
        /// The folder.
        dir: PathBuf,
        /// What went wrong.
        reason: String,
    },
    /// The photo folder is empty.
    #[error("{}: the photo folder is empty; put the photos there or fix `dir` in [photos]", dir.display())]
    EmptyFolder {
        /// The folder.
        dir: PathBuf,
    },
    /// The glob is not a valid pattern.
    #[error(
        "{}: glob = \"{glob}\" is not a valid pattern ({reason}); fix `glob` in [photos] (`*`, `?`, `[a-z]`, `[!a-z]`)",
        dir.display()
    )]
    BadGlob {
        /// The folder.
        dir: PathBuf,
        /// The pattern.
        glob: String,
        /// What is wrong with it.
        reason: String,
    },
    /// The glob matches no file.
    #[error(
        "{}: no file matches glob = \"{glob}\" (the folder holds {count} files, e.g. {examples}); fix `glob` in [photos]",
        dir.display()
    )]
    GlobNoMatch {
        /// The folder.
        dir: PathBuf,
        /// The pattern.
        glob: String,
        /// How many files the folder holds.
        count: usize,
        /// A few of them.
        examples: String,
    },
    /// The template was not found well enough in a frame.
    #[error(
        "{}: frame {frame}: the best template match scores {score:.3} < {min_score} {min:.3}; the apex is not where the template says, or the photo is damaged (open it to check), or lower {min_score}, or use {skip} to leave such frames out",
        path.display(),
        min_score = crate::setting::Setting::MinScore,
        skip = crate::setting::Setting::SkipBadFrames
    )]
    LowScore {
        /// The photo.
        path: PathBuf,
        /// Frame index.
        frame: usize,
        /// Best score.
        score: f64,
        /// The threshold.
        min: f64,
    },
    /// The apex found in a frame is not plausible, even when searched again
    /// near the position predicted from the frames before.
    #[error(
        "{}: frame {frame}: {why}; or use {} to leave such frames out",
        path.display(),
        crate::setting::Setting::SkipBadFrames
    )]
    Implausible {
        /// The photo.
        path: PathBuf,
        /// Frame index.
        frame: usize,
        /// What is implausible.
        why: String,
    },
    /// The experiment file lacks or contradicts a setting.
    #[error("{}: {message}", path.display())]
    Config {
        /// The experiment file.
        path: PathBuf,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// The pressure log itself is malformed.
    #[error(transparent)]
    Input(#[from] crate::io::InputError),
    /// An output file could not be written.
    #[error("{}: cannot write: {reason}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// OpenCV failed on valid input.
    #[error("OpenCV failed: {0}")]
    OpenCv(String),
}

impl crate::Refusal for TrackError {
    fn is_bad_input(&self) -> bool {
        !matches!(self, TrackError::OpenCv(_) | TrackError::Write { .. })
    }
}
