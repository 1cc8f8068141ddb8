//! The configuration shipped in the APK's assets, copied into the app's files folder: the scene
//! loader reads files from a folder, as on a desktop. A file already there with the same size is
//! kept (an updated APK with a changed file of the same size is copied again only after the
//! app's data is cleared).

use std::ffi::CString;
use std::io::Read;
use std::path::Path;

use android_activity::AndroidApp;
use anyhow::{Context, Result, bail};

use crate::ASSET_INDEX;

/// Reads the asset at `path` whole.
fn read_asset(app: &AndroidApp, path: &str) -> Result<Vec<u8>> {
    let name = CString::new(path).with_context(|| format!("asset name {path:?}"))?;
    let mut asset = app
        .asset_manager()
        .open(&name)
        .with_context(|| format!("the APK has no asset {path}"))?;
    let mut bytes = Vec::new();
    asset
        .read_to_end(&mut bytes)
        .with_context(|| format!("reading the asset {path}"))?;
    Ok(bytes)
}

/// Copies every file the asset index lists into `folder`; returns how many were written.
pub fn copy_all(app: &AndroidApp, folder: &Path) -> Result<usize> {
    let index = read_asset(app, ASSET_INDEX)?;
    let index = String::from_utf8(index).context("the asset index is not UTF-8")?;
    let mut written = 0;
    for path in index.lines().map(str::trim).filter(|l| !l.is_empty()) {
        if path.starts_with('/') || path.split('/').any(|p| p == "..") {
            bail!("the asset index names {path:?}, outside the assets");
        }
        let bytes = read_asset(app, path)?;
        let to = folder.join(path);
        if std::fs::metadata(&to).is_ok_and(|m| m.len() == bytes.len() as u64) {
            continue;
        }
        if let Some(parent) = to.parent() {
            std::fs::create_dir_all(parent)
                .with_context(|| format!("creating {}", parent.display()))?;
        }
        // Whole or not at all, as every file vitreous writes.
        let partial = to.with_extension("partial");
        std::fs::write(&partial, &bytes).with_context(|| format!("writing {}", to.display()))?;
        std::fs::rename(&partial, &to).with_context(|| format!("writing {}", to.display()))?;
        written += 1;
    }
    Ok(written)
}
