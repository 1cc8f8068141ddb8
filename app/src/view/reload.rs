//! Hot reload: the scene file and every file it reads are watched (modification time and
//! size, polled), and a change loads the scene anew. A scene that fails to load is reported
//! and the last good one keeps running.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use crate::scene::{DiskFiles, Scene, SceneFiles, load_scene_from};

/// How often the files are looked at.
const POLL: Duration = Duration::from_millis(250);

/// Reads from disk and remembers which files were read.
#[derive(Default)]
struct Recorder {
    /// Files read, in order.
    read: RefCell<Vec<PathBuf>>,
}

impl SceneFiles for Recorder {
    fn read_bounded(&self, path: &Path, limit: u64, what: &str) -> std::io::Result<Vec<u8>> {
        self.read.borrow_mut().push(path.to_path_buf());
        DiskFiles.read_bounded(path, limit, what)
    }
}

/// What identifies a file's version: modification time and size (None: missing).
type Stamp = Option<(SystemTime, u64)>;

fn stamp(path: &Path) -> Stamp {
    let meta = std::fs::metadata(path).ok()?;
    Some((meta.modified().ok()?, meta.len()))
}

/// Loads a scene and lists the files it read (the scene file, its assets, its caustic bake).
pub fn load_watched(path: &Path) -> (Result<Scene, crate::scene::SceneError>, Vec<PathBuf>) {
    let recorder = Recorder::default();
    let scene = load_scene_from(path, &recorder);
    let mut files = recorder.read.into_inner();
    if !files.iter().any(|f| f == path) {
        files.insert(0, path.to_path_buf());
    }
    if let Ok(scene) = &scene
        && let Some(bake) = &scene.caustics.bake
    {
        files.push(bake.clone());
    }
    files.dedup();
    (scene, files)
}

/// Watches a scene's files.
pub struct Watcher {
    /// Each file and its version when last loaded.
    files: Vec<(PathBuf, Stamp)>,
    /// When the files were last looked at.
    polled: Instant,
}

impl Watcher {
    /// Watches `files` as they are now.
    pub fn new(files: Vec<PathBuf>) -> Watcher {
        Watcher {
            files: files.into_iter().map(|f| (f.clone(), stamp(&f))).collect(),
            polled: Instant::now(),
        }
    }

    /// The first file changed since the last call that saw a change (looked at no more often
    /// than every 250 ms unless `now` is set).
    pub fn changed(&mut self, now: bool) -> Option<PathBuf> {
        if !now && self.polled.elapsed() < POLL {
            return None;
        }
        self.polled = Instant::now();
        let mut first = None;
        for (path, old) in &mut self.files {
            let new = stamp(path);
            if new != *old {
                *old = new;
                first.get_or_insert_with(|| path.clone());
            }
        }
        first
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_scene_watches_its_assets_and_an_edit_is_seen() {
        let scene =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../config/scenes/visual-effects.toml");
        let (loaded, files) = load_watched(&scene);
        loaded.unwrap();
        assert!(files.len() > 2, "the scene file and its assets: {files:?}");
        assert_eq!(files[0], scene);

        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("a.toml");
        std::fs::write(&file, "x = 1\n").unwrap();
        let mut w = Watcher::new(vec![file.clone()]);
        assert_eq!(w.changed(true), None);
        std::fs::write(&file, "x = 12\n").unwrap();
        assert_eq!(w.changed(true), Some(file.clone()));
        assert_eq!(w.changed(true), None, "reported once");
    }
}
