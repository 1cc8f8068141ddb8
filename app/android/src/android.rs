//! The activity's main: the copied configuration, logcat, then `vitreous run` on its own thread
//! while this one answers the activity's lifecycle.

use std::path::PathBuf;
use std::sync::mpsc;
use std::time::Duration;

use android_activity::{AndroidApp, MainEvent, PollEvent};
use anyhow::{Context, Result};

use crate::{DEFAULT_SCENE, assets, intent, logcat};

/// Called by the NativeActivity glue on the app's own thread once the activity is created.
#[unsafe(no_mangle)]
fn android_main(app: AndroidApp) {
    logcat::init();
    let (done_tx, done) = mpsc::channel::<Result<()>>();
    let session = prepare(&app).map(|scene| {
        std::thread::spawn(move || {
            let options = vitreous::run::RunOptions {
                scene,
                out: Some(PathBuf::from("out/run")),
                ..Default::default()
            };
            let _ = done_tx.send(vitreous::run::run(&options).map(|summary| {
                tracing::info!("session ended: {} frames", summary.frames_submitted);
            }));
        })
    });
    if let Err(e) = &session {
        tracing::error!("error: {e:#}");
    }
    let mut finished = session.is_err();
    while !finished {
        app.poll_events(Some(Duration::from_millis(100)), |event| {
            if let PollEvent::Main(MainEvent::Destroy) = event {
                finished = true;
            }
        });
        match done.try_recv() {
            Ok(Ok(())) => finished = true,
            Ok(Err(e)) => {
                tracing::error!("error: {e:#}");
                finished = true;
            }
            Err(mpsc::TryRecvError::Empty) => {}
            Err(mpsc::TryRecvError::Disconnected) => finished = true,
        }
    }
    // Returning ends the activity: the glue finishes it once its main returns.
}

/// Copies the configuration into the app's files folder, makes that the working directory, and
/// returns the scene the launch intent names.
fn prepare(app: &AndroidApp) -> Result<PathBuf> {
    let files = app
        .internal_data_path()
        .context("the activity has no files folder")?;
    let written = assets::copy_all(app, &files)?;
    tracing::info!(
        "configuration in {} ({written} files copied)",
        files.display()
    );
    std::env::set_current_dir(&files).with_context(|| format!("entering {}", files.display()))?;
    let scene = intent::string_extra(app, "scene").unwrap_or_else(|| DEFAULT_SCENE.to_owned());
    tracing::info!("scene {scene} (the launch intent's `scene` extra, or the default)");
    Ok(PathBuf::from(scene))
}
