//! vitreous-android: vitreous on Magic Leap 2 as an Android app (`tools/android/apk` packages it).
//!
//! The APK's `android.app.NativeActivity` loads this library and calls [`android_main`] on a
//! thread of its own. It copies the configuration shipped in the APK's assets (`config/`:
//! scenes, models, photos, maps, bakes, traces) into the app's files folder, where the scene
//! loader reads files as on a desktop, makes that folder the working directory (so `out/` and
//! recordings land there), sends the logs to logcat (tag `vitreous`), and runs `vitreous run` on
//! the scene the launch intent names (`--es scene config/scenes/NAME.toml`; default
//! [`DEFAULT_SCENE`]) with `--out out/run`, through the OpenXR loader initialised for the
//! activity (`vitreous_xr::openxr`: XR_KHR_loader_init_android, XR_KHR_android_create_instance).
//! The session runs on another thread while this one answers the activity's lifecycle events;
//! when the session ends, the activity is finished.
//!
//! On every other target the library is empty.

#[cfg(target_os = "android")]
mod android;
#[cfg(target_os = "android")]
mod assets;
#[cfg(target_os = "android")]
mod intent;
#[cfg(target_os = "android")]
mod logcat;

/// The scene run when the launch intent names none (a path inside the copied `config/`).
pub const DEFAULT_SCENE: &str = "config/scenes/glass-sphere.toml";

/// The file in the APK's assets listing every shipped file, one path per line (relative to the
/// assets' root), written by `tools/android/apk`: Android's asset manager cannot list folders.
pub const ASSET_INDEX: &str = "vitreous-assets.txt";
