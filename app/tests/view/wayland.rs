//! `vitreous view` as a native Wayland client (the `wayland` feature, which `tools/test` turns
//! on) in a headless weston compositor, with validation on: the glass is shown, a resize
//! gets a new swapchain, and a minimised window (which the compositor no longer asks to draw)
//! does not block the session.

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use super::shots::{WINDOW, assert_glass_shown_alone, scene};
use super::{assert_resized, resize_session, summary};

/// How long a session may take before the test calls it blocked.
const SESSION_LIMIT: Duration = Duration::from_secs(180);

/// A headless weston compositor with its own runtime folder, stopped on drop.
struct Weston {
    /// The compositor.
    child: Child,
    /// `XDG_RUNTIME_DIR` of the compositor and its clients (removed on drop).
    runtime: tempfile::TempDir,
    /// The socket name (`WAYLAND_DISPLAY`).
    socket: String,
}

impl Weston {
    /// Starts weston's headless backend; None outside CI when weston is missing (in CI a
    /// missing one fails the test: `tools/ensure-vulkan --wayland` installs it).
    fn start() -> Option<Weston> {
        let weston =
            super::shots::program("weston", "tools/ensure-vulkan --wayland (Debian: weston)")?;
        // A private runtime folder (mode 0700, as Wayland requires) per compositor, so tests
        // running at once never share a socket.
        let runtime = tempfile::tempdir().expect("a runtime folder");
        let socket = "vitreous-test".to_string();
        let child = Command::new(weston)
            .args([
                "--backend=headless-backend.so",
                &format!("--socket={socket}"),
                // Never blank the output: a blank output asks no client to draw.
                "--idle-time=0",
                "--width=640",
                "--height=480",
            ])
            .env("XDG_RUNTIME_DIR", runtime.path())
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("starting weston");
        let weston = Weston {
            child,
            runtime,
            socket,
        };
        let started = Instant::now();
        while !weston.runtime.path().join(&weston.socket).exists() {
            assert!(
                started.elapsed() < Duration::from_secs(20),
                "weston made no socket within 20 s"
            );
            std::thread::sleep(Duration::from_millis(20));
        }
        Some(weston)
    }

    /// Runs `vitreous view` on this compositor (no X display) with validation on, failing the
    /// test when it fails or has not ended within [`SESSION_LIMIT`].
    fn view(&self, scene: &Path, args: &[&str], cwd: &Path) -> Output {
        let size = format!("{}x{}", WINDOW.0, WINDOW.1);
        let mut child = Command::new(env!("CARGO_BIN_EXE_vitreous"))
            .arg("view")
            .arg(scene)
            .args(["--window", &size, "--validate", "--no-overlay"])
            .args(args)
            .current_dir(cwd)
            .env_remove("DISPLAY")
            .env("WAYLAND_DISPLAY", &self.socket)
            .env("XDG_RUNTIME_DIR", self.runtime.path())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("running vitreous view");
        let started = Instant::now();
        while child
            .try_wait()
            .expect("waiting for vitreous view")
            .is_none()
        {
            if started.elapsed() > SESSION_LIMIT {
                let _ = child.kill();
                let out = child.wait_with_output().expect("its output");
                panic!(
                    "vitreous view did not end within {SESSION_LIMIT:?} (blocked presenting?)\n{}",
                    String::from_utf8_lossy(&out.stderr)
                );
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        super::shots::succeeded(child.wait_with_output().expect("its output"))
    }
}

impl Drop for Weston {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Paths as arguments.
fn arg(path: &Path) -> &str {
    path.to_str().expect("a UTF-8 path")
}

#[test]
fn a_wayland_window_shows_the_glass_where_it_projects() {
    let Some(weston) = Weston::start() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let scene = scene("glass-sphere.toml");
    let (shot, out_dir) = (dir.path().join("shot.png"), dir.path().join("out"));
    weston.view(
        &scene,
        &[
            "--frames",
            "8",
            "--screenshot",
            arg(&shot),
            "--out",
            arg(&out_dir),
        ],
        dir.path(),
    );
    let s = summary(&out_dir);
    assert_eq!(s["frames"], 8, "{s:#}");
    assert!(
        s["frames_not_shown"].as_u64().unwrap() < 8,
        "no frame reached the compositor: {s:#}"
    );
    assert_glass_shown_alone(&shot, &scene);
}

#[test]
fn a_resized_wayland_window_gets_a_new_swapchain() {
    let Some(weston) = Weston::start() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let args = resize_session(dir.path());
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    weston.view(&scene("glass-sphere.toml"), &args, dir.path());
    assert_resized(dir.path());
}

#[test]
fn a_minimised_wayland_window_is_not_drawn_and_the_session_still_ends() {
    let Some(weston) = Weston::start() else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    // Minimised, the window gets no frame callbacks: a FIFO present would wait for one for
    // as long as the window stays minimised.
    std::fs::write(dir.path().join("minimise.script"), "3 minimise\n").unwrap();
    let out_dir: PathBuf = dir.path().join("out");
    weston.view(
        &scene("glass-sphere.toml"),
        &[
            "--frames",
            "30",
            "--script",
            "minimise.script",
            "--out",
            arg(&out_dir),
        ],
        dir.path(),
    );
    let s = summary(&out_dir);
    assert_eq!(s["frames"], 30, "{s:#}");
    let not_shown = s["frames_not_shown"].as_u64().unwrap();
    assert!(
        (20..30).contains(&not_shown),
        "shown before the minimise, not after it: {not_shown} of 30 frames not shown\n{s:#}"
    );
}
