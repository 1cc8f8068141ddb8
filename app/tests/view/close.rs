//! Closing the window as a window manager does: `WM_DELETE_WINDOW` sent to the viewer's window
//! in a virtual X server ends the session with exit status 0 and its summary written.

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use x11rb::connection::Connection;
use x11rb::protocol::xproto::{
    AtomEnum, ClientMessageEvent, ConnectionExt, EventMask, Window as XWindow,
};

use super::scene;
use super::shots::WINDOW;

/// A virtual X server on its own display, stopped on drop.
struct Xvfb {
    /// The server.
    child: Child,
    /// Its display, `:N`.
    display: String,
}

impl Xvfb {
    /// Starts `Xvfb` on the first free display from `:900` (the other tests' xvfb-run searches
    /// from `:100` up); None outside CI when there is none (in CI a missing one fails the
    /// test).
    fn start() -> Option<Xvfb> {
        let xvfb = super::shots::program("Xvfb", "tools/ensure-vulkan --window (Debian: xvfb)")?;
        for n in 900..930 {
            if display_in_use(n) {
                continue;
            }
            let display = format!(":{n}");
            let mut child = Command::new(&xvfb)
                .args([
                    display.as_str(),
                    "-screen",
                    "0",
                    "640x480x24",
                    "-nolisten",
                    "tcp",
                    // An X server resets when its last client leaves (as the probe below
                    // does), and a connection made while it resets is refused.
                    "-noreset",
                ])
                .stdout(Stdio::null())
                .stderr(Stdio::null())
                .spawn()
                .expect("starting Xvfb");
            let started = Instant::now();
            while started.elapsed() < Duration::from_secs(10) {
                // Ours only while it runs: a server that lost the race for the display exits.
                if child.try_wait().ok().flatten().is_some() {
                    break;
                }
                if x11rb::connect(Some(&display)).is_ok() {
                    return Some(Xvfb { child, display });
                }
                std::thread::sleep(Duration::from_millis(50));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        panic!("no display from :900 to :929 could be started");
    }
}

/// Whether a live X server holds display `:n`: its lock file names a running process. A lock
/// left by a server that was killed is stale (Xvfb removes it when it starts).
fn display_in_use(n: u32) -> bool {
    let Ok(lock) = std::fs::read_to_string(format!("/tmp/.X{n}-lock")) else {
        return false;
    };
    lock.trim().parse::<u32>().map_or(true, |pid| {
        std::path::Path::new(&format!("/proc/{pid}")).exists()
    })
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        // Terminated, not killed, so that it removes its lock file and socket (killed, it
        // would leave them and the display would look taken to the next run).
        let terminated = Command::new("kill")
            .arg(self.child.id().to_string())
            .status()
            .is_ok_and(|s| s.success());
        let asked = Instant::now();
        while terminated && asked.elapsed() < Duration::from_secs(5) {
            if self.child.try_wait().ok().flatten().is_some() {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The top-level windows of the display that take `WM_DELETE_WINDOW`.
fn closable_windows(
    conn: &impl Connection,
    root: XWindow,
    protocols: u32,
    delete: u32,
) -> Vec<XWindow> {
    let Some(tree) = conn.query_tree(root).ok().and_then(|c| c.reply().ok()) else {
        return Vec::new();
    };
    tree.children
        .into_iter()
        .filter(|&w| {
            conn.get_property(false, w, protocols, AtomEnum::ATOM, 0, 16)
                .ok()
                .and_then(|c| c.reply().ok())
                .and_then(|r| r.value32().map(|mut v| v.any(|a| a == delete)))
                .unwrap_or(false)
        })
        .collect()
}

#[test]
fn closing_the_window_ends_the_session_with_status_0_and_its_summary() {
    let Some(x) = Xvfb::start() else { return };
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("out");
    let size = format!("{}x{}", WINDOW.0, WINDOW.1);
    // No frame limit: only the close ends it.
    let mut app = Command::new(env!("CARGO_BIN_EXE_vitreous"))
        .arg("view")
        .arg(scene("glass-sphere.toml"))
        .args(["--window", &size, "--validate", "--no-overlay", "--out"])
        .arg(&out_dir)
        .env("DISPLAY", &x.display)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::null())
        // A file, not a pipe nobody reads while it runs.
        .stderr(std::fs::File::create(dir.path().join("stderr.log")).unwrap())
        .spawn()
        .expect("running vitreous view");
    let (conn, screen) = x11rb::connect(Some(&x.display)).expect("the display");
    let root = conn.setup().roots[screen].root;
    let atom = |name: &[u8]| {
        conn.intern_atom(false, name)
            .expect("intern_atom")
            .reply()
            .expect("an atom")
            .atom
    };
    let (protocols, delete) = (atom(b"WM_PROTOCOLS"), atom(b"WM_DELETE_WINDOW"));
    // Wait for the window, and a few frames drawn in it.
    let started = Instant::now();
    let window = loop {
        if let Some(&w) = closable_windows(&conn, root, protocols, delete).first() {
            break w;
        }
        assert!(
            app.try_wait().unwrap().is_none(),
            "vitreous view ended before its window appeared"
        );
        assert!(
            started.elapsed() < Duration::from_secs(60),
            "no window within 60 s"
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    std::thread::sleep(Duration::from_millis(1500));
    let event = ClientMessageEvent::new(32, window, protocols, [delete, 0, 0, 0, 0]);
    conn.send_event(false, window, EventMask::NO_EVENT, event)
        .expect("send_event");
    conn.flush().expect("flush");
    let closed = Instant::now();
    let status = loop {
        if let Some(status) = app.try_wait().unwrap() {
            break status;
        }
        if closed.elapsed() > Duration::from_secs(60) {
            let _ = app.kill();
            panic!("vitreous view did not end within 60 s of WM_DELETE_WINDOW");
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(
        status.success(),
        "closing the window: {status}\n{}",
        std::fs::read_to_string(dir.path().join("stderr.log")).unwrap_or_default()
    );
    let summary = super::summary(&out_dir);
    assert!(summary["frames"].as_u64().unwrap() > 0, "{summary:#}");
}
