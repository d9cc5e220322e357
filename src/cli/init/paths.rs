//! Paths that `bulge init` writes into the experiment file: relative to the
//! file's folder, and the photo folder's glob.

use super::super::Failure;
use anyhow::anyhow;
use std::path::{Component, Path, PathBuf};

/// `path` relative to the folder `base` (both made absolute), with `/`.
pub(super) fn relative(path: &Path, base: &Path) -> String {
    let abs = |p: &Path| {
        let p = std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
        p.components().fold(PathBuf::new(), |mut acc, c| {
            match c {
                Component::ParentDir => {
                    acc.pop();
                }
                Component::CurDir => {}
                c => acc.push(c),
            }
            acc
        })
    };
    let (p, b) = (abs(path), abs(base));
    let pc: Vec<Component> = p.components().collect();
    let bc: Vec<Component> = b.components().collect();
    let common = pc.iter().zip(&bc).take_while(|(a, b)| a == b).count();
    let mut parts: Vec<String> = vec!["..".to_string(); bc.len() - common];
    parts.extend(
        pc[common..]
            .iter()
            .map(|c| c.as_os_str().to_string_lossy().into_owned()),
    );
    if parts.is_empty() {
        ".".into()
    } else {
        parts.join("/")
    }
}

/// The folder's most common image extension as a glob.
pub(super) fn default_glob(dir: &Path) -> Result<String, Failure> {
    let mut counts: std::collections::BTreeMap<String, usize> = Default::default();
    let rd = std::fs::read_dir(dir).map_err(|e| {
        Failure::BadInput(anyhow!(
            "{}: cannot read the photo folder: {e}",
            dir.display()
        ))
    })?;
    for e in rd.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if let Some((_, ext)) = name.rsplit_once('.') {
            let ext = ext.to_string();
            if ["jpg", "jpeg", "png", "tif", "tiff", "bmp"]
                .contains(&ext.to_ascii_lowercase().as_str())
            {
                *counts.entry(ext).or_default() += 1;
            }
        }
    }
    counts
        .into_iter()
        .max_by_key(|(_, n)| *n)
        .map(|(ext, _)| format!("*.{ext}"))
        .ok_or_else(|| {
            Failure::BadInput(anyhow!(
                "{}: no photos (.jpg, .jpeg, .png, .tif, .tiff, .bmp) in the folder; give the folder of the test's photos, or --glob",
                dir.display()
            ))
        })
}
