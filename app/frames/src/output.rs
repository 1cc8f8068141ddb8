//! What a replay writes: per-eye PNGs, see-through previews and `summary.json`.
//!
//! Every file is written to a temporary name in its folder and renamed into place, so an
//! interrupted run never leaves a half-written file under the final name.

use std::path::Path;

use anyhow::{Context, Result};
use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder};
use vitreous_render::Readback;

/// Eye names in output file names, left then right.
pub const EYE_NAMES: [&str; 2] = ["left", "right"];

/// Writes `bytes` to `path` through a temporary file in the same folder, renamed into place
/// once complete and synced ([`vitreous_trace::atomic_file::write`]): an interrupted write leaves
/// either the old file or none, never a half-written one.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    vitreous_trace::atomic_file::write(path, bytes)
        .with_context(|| format!("writing {}", path.display()))
}

/// Encodes RGBA8 pixels as PNG with fast compression (the default level costs ~0.7 s per
/// 1280x960 eye on a CPU device; fast costs ~30 ms).
pub fn encode_png(rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>> {
    let mut out = Vec::with_capacity(rgba.len() / 2);
    PngEncoder::new_with_quality(&mut out, CompressionType::Fast, FilterType::Adaptive)
        .write_image(rgba, width, height, ExtendedColorType::Rgba8)
        .context("encoding PNG")?;
    Ok(out)
}

/// Linear light to sRGB bytes, and the additive display's see-through (in `wearer`, with the
/// dimmers).
pub use crate::wearer::see_through;

/// The files of one saved frame.
pub fn frame_file_names(frame: u64) -> [String; 4] {
    [
        format!("{frame:06}-left.png"),
        format!("{frame:06}-right.png"),
        format!("{frame:06}-left-preview.png"),
        format!("{frame:06}-right-preview.png"),
    ]
}

/// Whether `name` is a file a replay or `vitreous reference` writes among its frame images:
/// `NNNNNN-left.png`, `NNNNNN-right-preview.png`, `NNNNNN-left-sphere-check.png`,
/// `NNNNNN-left-real.png`, `NNNNNN-left-seen.png`, ..., the reference's images as OpenEXR
/// (`NNNNNN-left.exr`, `NNNNNN-left-seen.exr`: `vitreous reference --exr`), `reference.json`, or a
/// temporary file of an atomic write.
pub fn is_frame_file_name(name: &str) -> bool {
    if (name.starts_with(".vitreous-") && name.ends_with(".partial")) || name == "reference.json" {
        return true;
    }
    let (stem, kinds): (&str, &[&str]) = if let Some(stem) = name.strip_suffix(".png") {
        (stem, &["", "-preview", "-sphere-check", "-real", "-seen"])
    } else if let Some(stem) = name.strip_suffix(".exr") {
        (stem, &["", "-seen"])
    } else {
        return false;
    };
    let Some((digits, rest)) = stem.split_once('-') else {
        return false;
    };
    digits.len() >= 6
        && digits.bytes().all(|b| b.is_ascii_digit())
        && EYE_NAMES
            .iter()
            .any(|eye| kinds.iter().any(|k| rest == format!("{eye}{k}")))
}

/// Writes a saved frame's eye images and, when the world was read back, its previews (what the
/// wearer sees through `display`) into `dir`. Returns the file names written.
pub fn write_frame(
    dir: &Path,
    frame: u64,
    readback: &Readback,
    display: &crate::wearer::WearerView,
) -> Result<Vec<String>> {
    let names = frame_file_names(frame);
    let (w, h) = (readback.width, readback.height);
    let mut jobs: Vec<(String, Vec<u8>)> = Vec::new();
    for eye in 0..2 {
        jobs.push((names[eye].clone(), readback.eyes[eye].clone()));
        if let Some(world) = &readback.world {
            jobs.push((
                names[eye + 2].clone(),
                display.see(&readback.eyes[eye], &world[eye], [w, h]),
            ));
        }
    }
    // PNG encoding dominates saving; one thread per image.
    let encoded: Vec<Result<(String, Vec<u8>)>> = std::thread::scope(|s| {
        let handles: Vec<_> = jobs
            .iter()
            .map(|(name, rgba)| s.spawn(move || Ok((name.clone(), encode_png(rgba, w, h)?))))
            .collect();
        handles
            .into_iter()
            .map(|h| {
                h.join()
                    .unwrap_or_else(|_| Err(anyhow::anyhow!("PNG encoder panicked")))
            })
            .collect()
    });
    let mut written = Vec::new();
    for item in encoded {
        let (name, png) = item?;
        write_atomic(&dir.join(&name), &png)?;
        written.push(name);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs;

    #[test]
    fn see_through_adds_light_and_black_adds_nothing() {
        let world = [100u8, 150, 200, 255];
        let black = [0u8, 0, 0, 255];
        assert_eq!(see_through(&black, &world), vec![100, 150, 200, 255]);
        let grey = [128u8, 128, 128, 255];
        let sum = see_through(&grey, &grey);
        // Two equal linear halves of ~0.216 add to ~0.43, i.e. sRGB ~175: brighter, never darker.
        assert!(sum[0] > 170 && sum[0] < 180, "{sum:?}");
    }

    #[test]
    fn only_frame_image_names_are_frame_files() {
        for name in [
            "000000-left.png",
            "000030-right-preview.png",
            "000060-left-sphere-check.png",
            "000060-left-real.png",
            "000060-right-seen.png",
            "000000-left.exr",
            "000060-right-seen.exr",
            "1234567-right.png",
            "reference.json",
            ".vitreous-abc123.partial",
        ] {
            assert!(is_frame_file_name(name), "{name}");
        }
        for name in [
            "notes.txt",
            "left.png",
            "00003-left.png",
            "000030-middle.png",
            "x-left.png",
            "000000-left.jpg",
            "000000-left-preview.exr",
        ] {
            assert!(!is_frame_file_name(name), "{name}");
        }
    }

    #[test]
    fn atomic_write_leaves_no_partial_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.bin");
        write_atomic(&path, b"hello").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"hello");
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
        use std::os::unix::fs::PermissionsExt;
        let mode = fs::metadata(&path).unwrap().permissions().mode();
        assert_ne!(
            mode & 0o044,
            0,
            "written files are readable by others as a plain create makes them: {mode:o}"
        );
    }
}
