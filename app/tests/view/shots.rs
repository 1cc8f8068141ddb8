//! What the view tests share: the window size, the scenes, screenshots and where the glass
//! lies in them.

use std::path::{Path, PathBuf};

use glam::Vec3;

/// `out` of a `vitreous view` run, which must have succeeded (its output in the message if
/// not).
pub fn succeeded(out: std::process::Output) -> std::process::Output {
    assert!(
        out.status.success(),
        "vitreous view failed: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The program `name` on PATH; None outside CI when it is missing (in CI a missing one fails
/// the test), with `install` saying what installs it.
pub fn program(name: &str, install: &str) -> Option<PathBuf> {
    let found = std::env::var_os("PATH").and_then(|paths| {
        std::env::split_paths(&paths)
            .map(|p| p.join(name))
            .find(|p| p.is_file())
    });
    if found.is_none() {
        assert!(
            std::env::var_os("CI").is_none(),
            "{name} is missing: {install} installs it"
        );
        eprintln!("skipped: no {name} here ({install} installs it)");
    }
    found
}

/// Window size of every test: small, so each run takes a few seconds on a CPU device.
pub const WINDOW: (u32, u32) = (320, 240);

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// An RGBA8 screenshot.
pub struct Shot {
    pub width: u32,
    pub pixels: Vec<u8>,
}

impl Shot {
    pub fn read(path: &Path) -> Shot {
        Shot::read_sized(path, WINDOW)
    }

    pub fn read_sized(path: &Path, size: (u32, u32)) -> Shot {
        let img = image::open(path).expect("a PNG screenshot").to_rgba8();
        assert_eq!(img.dimensions(), size, "the screenshot is the window");
        Shot {
            width: img.width(),
            pixels: img.into_raw(),
        }
    }

    pub fn luma(&self, x: u32, y: u32) -> f32 {
        let i = ((y * self.width + x) * 4) as usize;
        let p = &self.pixels[i..i + 3];
        0.2126 * f32::from(p[0]) + 0.7152 * f32::from(p[1]) + 0.0722 * f32::from(p[2])
    }
}

/// Where the scene's glass (its bounding sphere) lies in each half of the window, as the
/// viewer projects it from the starting pose: centre and radius in window pixels.
pub fn glass_discs(scene_path: &Path) -> [(f32, f32, f32); 2] {
    let scene = vitreous_scene::load_scene(scene_path).expect("scene loads");
    let g = scene.viewing_geometry();
    let fov = scene.output.fov;
    let tan_v = ((fov.angle_up_rad - fov.angle_down_rad) / 2.0).tan();
    let (eye_w, eye_h) = ((WINDOW.0 / 2) as f32, WINDOW.1 as f32);
    let tan_h = tan_v * eye_w / eye_h;
    let head = scene.viewer.head_position_m;
    [-1.0f32, 1.0].map(|side| {
        let eye = head + Vec3::X * side * scene.viewer.ipd_m / 2.0;
        let p = g.center_m - eye;
        let u = 0.5 + p.x / -p.z / (2.0 * tan_h);
        let v = 0.5 - p.y / -p.z / (2.0 * tan_v);
        let r = g.radius_m / p.length() / (2.0 * tan_v) * eye_h;
        let x0 = if side < 0.0 { 0.0 } else { eye_w };
        (x0 + u * eye_w, v * eye_h, r)
    })
}

/// Window pixels, (x, y).
pub type Pixels = Vec<(u32, u32)>;

/// Pixels inside 0.7 of the discs and outside 1.6 of them.
pub fn regions(discs: &[(f32, f32, f32); 2]) -> (Pixels, Pixels) {
    let (mut inside, mut outside) = (Vec::new(), Vec::new());
    for y in 0..WINDOW.1 {
        for x in 0..WINDOW.0 {
            let d = |&(cx, cy, r): &(f32, f32, f32)| {
                ((x as f32 + 0.5 - cx).hypot(y as f32 + 0.5 - cy)) / r
            };
            let nearest = discs.iter().map(d).fold(f32::INFINITY, f32::min);
            if nearest < 0.7 {
                inside.push((x, y));
            } else if nearest > 1.6 {
                outside.push((x, y));
            }
        }
    }
    (inside, outside)
}

pub fn scene(name: &str) -> PathBuf {
    root().join("config/scenes").join(name)
}

/// Checks the screenshot at `shot` (of the starting pose of `scene`, display light only): the
/// glass is lit where it projects and the window black away from it.
pub fn assert_glass_shown_alone(shot: &Path, scene: &Path) {
    let img = Shot::read(shot);
    let (inside, outside) = regions(&glass_discs(scene));
    assert!(inside.len() > 50, "the glass covers {} px", inside.len());
    let mean =
        |px: &[(u32, u32)]| px.iter().map(|&(x, y)| img.luma(x, y)).sum::<f32>() / px.len() as f32;
    let lit_outside = outside
        .iter()
        .filter(|&&(x, y)| img.luma(x, y) > 8.0)
        .count();
    assert!(mean(&inside) > 20.0, "glass mean luma {}", mean(&inside));
    assert!(
        (lit_outside as f32) < 0.01 * outside.len() as f32,
        "{lit_outside} of {} px lit away from the glass (display light only)",
        outside.len()
    );
}
