//! Which frame and eye a reference image is: the `reference.json` that `vitreous reference`
//! (for its `NNNNNN-left.png`) and `replay --compare-reference` (for its
//! `NNNNNN-left-real.png`) write beside their images. One that cannot be read, or that lists
//! the image for another scene than the one compared, is an error naming it: the regions
//! would silently be the wrong ones.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};
use vitreous_reference::{FrameReport, Report};
use vitreous_scene::Scene;

use crate::regions::Eye;

/// The file beside a reference image that lists its frames.
pub const REFERENCE_JSON: &str = "reference.json";

/// A reference image as its `reference.json` lists it.
#[derive(Debug)]
pub struct Listed {
    /// The frame: head pose, eye cameras, object and light.
    pub frame: FrameReport,
    /// The eye, 0 left, 1 right.
    pub eye: usize,
    /// The `reference.json` that lists it.
    pub file: PathBuf,
    /// The scene it was rendered for, as that file names it.
    pub scene: String,
    /// That scene's hash ([`Scene::hash`]).
    pub scene_hash: String,
}

/// The `reference.json` beside `image`.
pub fn reference_json_beside(image: &Path) -> PathBuf {
    image.with_file_name(REFERENCE_JSON)
}

/// The frame and eye of a reference image from the `reference.json` beside it: `None` when
/// there is none, or it does not list the image; an error naming the file when it cannot be
/// read or is not a `reference.json` (corrupt, cut short).
pub fn frame_of_image(image: &Path) -> Result<Option<Listed>> {
    let file = reference_json_beside(image);
    let Some(name) = image.file_name().and_then(|n| n.to_str()) else {
        return Ok(None);
    };
    let bytes = match std::fs::read(&file) {
        Ok(bytes) => bytes,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
        Err(e) => bail!("{}: cannot read it: {e}", file.display()),
    };
    let report: Report = match serde_json::from_slice(&bytes) {
        Ok(report) => report,
        Err(e) => bail!(
            "{}: not a reference.json that says which frame and eye {} is ({e}): write it \
             again (`vitreous reference` or `replay --compare-reference`), or move it away to \
             split the regions at the neutral head",
            file.display(),
            image.display()
        ),
    };
    let (scene, scene_hash) = (report.scene, report.scene_hash);
    Ok(report.frames.into_iter().find_map(|frame| {
        let eye = Eye::ALL.iter().position(|e| {
            let stem = format!("{:06}-{}", frame.frame, e.name());
            name == format!("{stem}.png") || name == format!("{stem}-real.png")
        })?;
        Some(Listed {
            frame,
            eye,
            file: file.clone(),
            scene: scene.clone(),
            scene_hash: scene_hash.clone(),
        })
    }))
}

/// The frame and eye of `image` for comparing it region by region in `scene`: refused when its
/// `reference.json` lists it for another scene (the frame's regions would be that scene's) or
/// for another eye than `eye`, the eye asked for.
pub fn frame_for_scene(image: &Path, scene: &Scene, eye: Option<usize>) -> Result<Option<Listed>> {
    let Some(listed) = frame_of_image(image)? else {
        return Ok(None);
    };
    if listed.scene_hash != scene.hash {
        bail!(
            "{} lists {} as frame {} of {} (scene_hash {}), not of --scene {} (scene_hash {}): \
             its regions would be that scene's; compare with --scene {}, or render the \
             reference again for {}",
            listed.file.display(),
            image.display(),
            listed.frame.frame,
            listed.scene,
            short(&listed.scene_hash),
            scene.path.display(),
            short(&scene.hash),
            listed.scene,
            scene.path.display()
        );
    }
    if let Some(eye) = eye.filter(|&e| e != listed.eye) {
        bail!(
            "--eye {}, but {} lists {} as the {} eye of frame {}: leave --eye out",
            Eye::ALL[eye].name(),
            listed.file.display(),
            image.display(),
            Eye::ALL[listed.eye].name(),
            listed.frame.frame
        );
    }
    Ok(Some(listed))
}

/// The first 12 hex digits of a hash, enough to tell two apart in a message.
fn short(hash: &str) -> &str {
    hash.get(..12).unwrap_or(hash)
}
