//! The frames `bulge init` reads: a folder's photos or a video's chosen
//! frames, decoded one by one or in parallel.

use super::*;

/// Where the frames of a test come from.
#[derive(Debug, Clone, PartialEq)]
pub enum Frames {
    /// Photo files, in the order taken.
    Photos(Vec<PathBuf>),
    /// A video and the indices of the frames to use, in time order.
    Video {
        /// The video file.
        path: PathBuf,
        /// The frames to use.
        indices: Vec<usize>,
    },
}

impl Frames {
    /// The number of frames.
    pub fn len(&self) -> usize {
        match self {
            Frames::Photos(p) => p.len(),
            Frames::Video { indices, .. } => indices.len(),
        }
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The file that frame `i` is (or is in), for messages.
    pub fn path(&self, i: usize) -> &Path {
        match self {
            Frames::Photos(p) => &p[i],
            Frames::Video { path, .. } => path,
        }
    }

    /// Frame `i`, grayscale.
    pub(super) fn gray(&self, i: usize) -> Result<Gray, TrackError> {
        match self {
            Frames::Photos(p) => Ok(read_gray(&p[i], None)?.crop),
            Frames::Video { path, indices } => {
                let bgr = super::super::video::read_frame_bgr(path, indices[i])?;
                let mut g = opencv::core::Mat::default();
                opencv::imgproc::cvt_color_def(&bgr, &mut g, opencv::imgproc::COLOR_BGR2GRAY)
                    .map_err(|e| TrackError::OpenCv(e.to_string()))?;
                use opencv::core::MatTraitConst;
                let whole = [0, 0, g.cols() as usize, g.rows() as usize];
                Ok(super::super::image::crop_mat(path, &g, whole)?.crop)
            }
        }
    }

    /// `f` of every frame (grayscale), in order: photos decoded in
    /// parallel, a video read once from start to end.
    pub(super) fn map<T: Send>(
        &self,
        f: impl Fn(usize, Gray) -> Result<T, TrackError> + Sync,
    ) -> Result<Vec<T>, TrackError> {
        match self {
            Frames::Photos(p) => (0..p.len())
                .into_par_iter()
                .map(|i| f(i, read_gray(&p[i], None)?.crop))
                .collect(),
            Frames::Video { path, indices } => {
                let wanted: Vec<super::super::video::Wanted> = indices
                    .iter()
                    .enumerate()
                    .map(|(seq, &index)| super::super::video::Wanted {
                        seq,
                        index,
                        crop: None,
                        lenient: false,
                    })
                    .collect();
                let mut out = Vec::with_capacity(indices.len());
                let mut failed = None;
                super::super::video::read_frames(path, &wanted, |i, d| {
                    match d.and_then(|d| f(i, d.crop)) {
                        Ok(v) => out.push(v),
                        Err(e) => failed = Some(e),
                    }
                    failed.is_none()
                });
                match failed {
                    Some(e) => Err(e),
                    None => Ok(out),
                }
            }
        }
    }
}
