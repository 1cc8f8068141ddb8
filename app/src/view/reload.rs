//! The scene shown and its hot reload: the scene file and every file it reads are watched
//! (modification time and size, polled), and a change loads the scene anew. A scene that
//! fails to load is reported and the last good one keeps running.

use std::cell::RefCell;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, SystemTime};

use anyhow::{Context, Result, bail};
use vitreous_render::{ContextOptions, GpuContext, Renderer};

use vitreous_frames::blur_stack::DefocusSetup;
use vitreous_frames::render_desc;
use vitreous_scene::effects::EffectSet;
use vitreous_scene::{CausticsMode, DiskFiles, Scene, SceneFiles, load_scene_from};

/// A scene loaded with what its renderer needs.
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// The files it was read from (watched for reload).
    pub(super) files: Vec<PathBuf>,
    /// The effects to start with.
    pub(super) effects: EffectSet,
    /// Whether the caustic bake is loaded (conditions b and c offered).
    pub(super) caustics_loaded: bool,
    /// Why the scene's caustic bake is not used, when it is not.
    pub(super) caustics_note: Option<String>,
    /// Blur stacks and the eq. 13-14 model, when defocus is implemented.
    pub(super) setup: Option<DefocusSetup>,
}

impl Loaded {
    /// Loads the scene at `path`; `effects` overrides the scene's starting effects.
    pub fn load(path: &Path, effects: Option<EffectSet>) -> Result<Loaded> {
        let (scene, files) = load_watched(path);
        let mut scene = scene?;
        let effects = effects.unwrap_or(scene.effects);
        effects.ensure_implemented()?;
        let mut caustics_note = None;
        // A bake to read, or a live map (nothing read; computed for each pose).
        let has_caustics =
            scene.caustics.bake.is_some() || scene.caustics.mode == CausticsMode::Live;
        let caustics_loaded = has_caustics
            && EffectSet::IMPLEMENTED.caustics
            && match scene.load_caustics() {
                Ok(()) => true,
                Err(e) => {
                    let note = format!("caustic bake not used (conditions b, c off): {e}");
                    tracing::warn!("{note}");
                    caustics_note = Some(note);
                    false
                }
            };
        if effects.caustics && !caustics_loaded {
            bail!(
                "effects {effects} need the scene's caustic bake: {}",
                caustics_note.as_deref().unwrap_or("the scene names none")
            );
        }
        let setup = EffectSet::IMPLEMENTED.defocus.then(|| {
            let mut setup = DefocusSetup::new(&scene, scene.viewer.pupil_diameter_m);
            setup.model.pupil_source = scene.gaze.pupil;
            setup
        });
        Ok(Loaded {
            scene,
            files,
            effects,
            caustics_loaded,
            caustics_note,
            setup,
        })
    }

    /// A renderer of this scene with eye images of `size`, on a new device; with the caustics
    /// computed for each pose when the scene asks for them live.
    pub(super) fn renderer(&self, size: (u32, u32), options: &ContextOptions) -> Result<Renderer> {
        let ctx = GpuContext::headless(options).context("setting up the Vulkan device")?;
        let mut renderer = Renderer::new(
            ctx,
            &render_desc::scene_desc(&self.scene, self.setup.as_ref()),
            size.0,
            size.1,
        )
        .context("preparing the renderer")?;
        render_desc::enable_live_caustics(&mut renderer, &self.scene, self.caustics_loaded)
            .context("preparing live caustics")?;
        Ok(renderer)
    }
}

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
pub fn load_watched(path: &Path) -> (Result<Scene, vitreous_scene::SceneError>, Vec<PathBuf>) {
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
