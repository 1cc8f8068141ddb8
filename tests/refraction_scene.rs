//! Refraction at the visual-effects scene's own resolution and field of view (1280 x 960 over
//! 40 x 30 degrees, config/scenes/visual-effects.toml), with the sphere the scene ships: a grid
//! of markers on the background photo, each marker's image in each eye against the CPU ray
//! tracer of the analytic ball, in the paper's model and in two-surface refraction. This is
//! where the mesh's tessellation shows: the markers near the fold, where the refracted image
//! turns over, move fastest with the surface normal.

use glam::{DVec2, Quat, Vec2, Vec3};
use vitreous_optics::camera::{EyeParams, Fov};
use vitreous_optics::refraction::Refraction;
use vitreous_optics::sphere_check::{RefractionSample, refraction_sample};

use crate::refraction::{
    CENTER, DISPARITY, IOR, IPD, RADIUS, Shot, background_plane, reference_scene, render_shot,
    shipped_sphere,
};

/// The scene's eye image size.
const SIZE: (u32, u32) = (1280, 960);
/// Texels per side of the photo (0.6 m): fine enough that the ball, which magnifies the
/// photo about 20 times here, shows many markers.
const PHOTO: u32 = 2048;
/// Markers: squares of `MARKER_TEXELS` texels every `MARKER_PITCH` texels of the photo.
const MARKER_PITCH: u32 = 12;
const MARKER_TEXELS: u32 = 3;
/// Pixels around a marker's reference image that count towards its image on the GPU.
const MARGIN_PX: i32 = 4;
/// Marker images smaller than this are not measured: a marker squeezed to a few pixels, or to
/// a sliver near the fold, is point-sampled by both sides (the reference at pixel centres, the
/// GPU through its bilinear photo filter), and its centroid says more about the sampling than
/// about where the image lies.
const MIN_PIXELS: usize = 30;
/// ... and narrower than this, pixels (the width of the uniform bar with the same second
/// moment across its narrowest direction).
const MIN_WIDTH_PX: f64 = 4.0;

/// The scene's field of view: 40 x 30 degrees, centred.
fn scene_fov() -> Fov {
    let (h, v) = (20f32.to_radians(), 15f32.to_radians());
    Fov {
        left_rad: -h,
        right_rad: h,
        up_rad: v,
        down_rad: -v,
    }
}

/// Both eyes of a head at `head_m` turned by `turn`, with the scene's field of view.
fn scene_eyes(head_m: Vec3, turn: Quat) -> [EyeParams; 2] {
    [-IPD / 2.0, IPD / 2.0]
        .map(|x| EyeParams::new(head_m + turn * Vec3::new(x, 0.0, 0.0), turn, scene_fov()))
}

/// Whether texel `t` (along one axis) is white: inside a marker.
fn marker_texel(t: i64) -> bool {
    let (pitch, per_side) = (i64::from(MARKER_PITCH), i64::from(PHOTO / MARKER_PITCH));
    let t = t.clamp(0, i64::from(PHOTO) - 1);
    t % pitch < i64::from(MARKER_TEXELS) && t / pitch < per_side
}

/// The photo as the GPU samples it (bilinear, clamped to the edge) at photo coordinate `uv`
/// (0..1, v down): the marker whose texels contribute and the sampled value, or `None` on
/// black. The markers are squares, so the filter is the product of one per axis.
fn marker_seen(uv: Vec2) -> Option<(usize, f32)> {
    let mut value = 1.0;
    let mut index = [0i64; 2];
    for (axis, coordinate) in [uv.x, uv.y].into_iter().enumerate() {
        let f = f64::from(coordinate) * f64::from(PHOTO) - 0.5;
        let i0 = f.floor() as i64;
        let a = (f - i0 as f64) as f32;
        let lo = if marker_texel(i0) { 1.0 - a } else { 0.0 };
        let hi = if marker_texel(i0 + 1) { a } else { 0.0 };
        value *= lo + hi;
        // Every texel this sample reads belongs to the marker of the pitch cell around it
        // (the markers are far narrower than their pitch).
        let gap = i64::from(MARKER_PITCH - MARKER_TEXELS) / 2;
        index[axis] = (i0 + gap).div_euclid(i64::from(MARKER_PITCH));
    }
    let per_side = i64::from(PHOTO / MARKER_PITCH);
    (value > 0.0).then(|| ((index[1] * per_side + index[0]) as usize, value))
}

/// The photo: black, with a white square at every marker.
fn marker_grid_photo() -> Vec<u8> {
    let mut px = vec![0u8; (PHOTO * PHOTO * 4) as usize];
    for y in 0..PHOTO {
        for x in 0..PHOTO {
            let i = ((y * PHOTO + x) * 4) as usize;
            px[i + 3] = 255;
            if marker_texel(i64::from(x)) && marker_texel(i64::from(y)) {
                px[i..i + 3].copy_from_slice(&[255, 255, 255]);
            }
        }
    }
    px
}

/// One connected image of a marker in the reference (a marker near the fold is seen twice):
/// its pixels and their centroid weighted by the light they show (the transmission times the
/// photo's filtered value, as on the GPU).
#[derive(Default)]
struct MarkerImage {
    /// The marker's index in the grid.
    marker: usize,
    /// Pixels (x, y) whose ray reaches the marker, 8-connected.
    pixels: Vec<(i32, i32)>,
    /// Sum of pixel centre times light.
    sum: DVec2,
    /// Sum of light.
    weight: f64,
}

/// The reference's marker images of one eye, and which pixels miss the ball.
fn reference_markers(eye: &EyeParams, refraction: Refraction) -> (Vec<MarkerImage>, Vec<bool>) {
    let (w, h) = (SIZE.0 as i32, SIZE.1 as i32);
    let dims = Vec2::new(SIZE.0 as f32, SIZE.1 as f32);
    let scene = reference_scene(refraction);
    let mut miss = vec![false; (w * h) as usize];
    // Per pixel: the marker its ray reaches and the transmission.
    let mut seen: Vec<Option<(usize, f32)>> = vec![None; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            let i = (y * w + x) as usize;
            match refraction_sample(eye, p, dims, &scene) {
                RefractionSample::Miss => miss[i] = true,
                RefractionSample::Hit {
                    uv: Some(uv),
                    transmission,
                    ..
                } => seen[i] = marker_seen(uv).map(|(k, value)| (k, transmission * value)),
                RefractionSample::Hit { uv: None, .. } => {}
            }
        }
    }
    // Connected images: flood fill over pixels of the same marker.
    let mut images = Vec::new();
    let mut done = vec![false; seen.len()];
    for start in 0..seen.len() {
        let Some((marker, _)) = seen[start] else {
            continue;
        };
        if done[start] {
            continue;
        }
        done[start] = true;
        let mut image = MarkerImage {
            marker,
            ..MarkerImage::default()
        };
        let mut stack = vec![start];
        while let Some(i) = stack.pop() {
            let (x, y) = ((i as i32) % w, (i as i32) / w);
            let transmission = f64::from(seen[i].map_or(0.0, |s| s.1));
            image.pixels.push((x, y));
            image.sum += DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5) * transmission;
            image.weight += transmission;
            for (dx, dy) in [
                (-1, -1),
                (0, -1),
                (1, -1),
                (-1, 0),
                (1, 0),
                (-1, 1),
                (0, 1),
                (1, 1),
            ] {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || ny < 0 || nx >= w || ny >= h {
                    continue;
                }
                let j = (ny * w + nx) as usize;
                if !done[j] && seen[j].is_some_and(|s| s.0 == marker) {
                    done[j] = true;
                    stack.push(j);
                }
            }
        }
        images.push(image);
    }
    (images, miss)
}

/// The pixels within `MARGIN_PX` of a marker's reference image (inside the image), and
/// whether that region is whole: it neither leaves the image nor reaches a pixel that misses
/// the ball (where the silhouette would cut the marker).
fn region(marker: &MarkerImage, miss: &[bool]) -> (Vec<(i32, i32)>, bool) {
    let (w, h) = (SIZE.0 as i32, SIZE.1 as i32);
    let mut inside = std::collections::HashSet::new();
    let mut whole = true;
    for &(x, y) in &marker.pixels {
        for dy in -MARGIN_PX..=MARGIN_PX {
            for dx in -MARGIN_PX..=MARGIN_PX {
                let (px, py) = (x + dx, y + dy);
                if px < 0 || py < 0 || px >= w || py >= h {
                    whole = false;
                    continue;
                }
                whole &= !miss[(py * w + px) as usize];
                inside.insert((px, py));
            }
        }
    }
    let mut pixels: Vec<_> = inside.into_iter().collect();
    pixels.sort_unstable();
    (pixels, whole)
}

/// The width of a set of pixels across its narrowest direction: that of the uniform bar with
/// the same second moment, sqrt(12 lambda_min) with lambda_min the covariance's smaller
/// eigenvalue.
fn narrowest_width(pixels: &[(i32, i32)]) -> f64 {
    let n = pixels.len() as f64;
    let mean = pixels.iter().fold(DVec2::ZERO, |s, &(x, y)| {
        s + DVec2::new(f64::from(x), f64::from(y))
    }) / n;
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for &(x, y) in pixels {
        let d = DVec2::new(f64::from(x), f64::from(y)) - mean;
        xx += d.x * d.x / n;
        xy += d.x * d.y / n;
        yy += d.y * d.y / n;
    }
    let half_trace = (xx + yy) / 2.0;
    let lambda_min = half_trace
        - (half_trace * half_trace - (xx * yy - xy * xy))
            .max(0.0)
            .sqrt();
    // A one-pixel-wide line has second moment 1/12 across from its pixel centres' spread of 0:
    // add the pixel's own extent.
    (12.0 * lambda_min.max(0.0) + 1.0).sqrt()
}

/// Every marker image seen whole through the shipped sphere (at least `MIN_PIXELS` pixels,
/// clear of the silhouette, the image's edge and other markers' images) lands within `bar_px`
/// of the reference in each eye; returns the largest distance.
fn markers_land_within(eyes: [EyeParams; 2], refraction: Refraction, bar_px: f64) -> f64 {
    let photo = marker_grid_photo();
    let shot = Shot {
        look: DISPARITY,
        surface_dot: false,
        env_marker: false,
        refraction,
        eyes,
        ior: IOR,
        size: SIZE,
        photo: &photo,
        photo_texels: PHOTO,
    };
    let images = render_shot(&shot, shipped_sphere());
    let mut worst: f64 = 0.0;
    let mut failures = Vec::new();
    for (e, eye) in eyes.iter().enumerate() {
        let (markers, miss) = reference_markers(eye, refraction);
        let regions: Vec<(Vec<(i32, i32)>, bool)> =
            markers.iter().map(|m| region(m, &miss)).collect();
        // A pixel near two markers' images would mix their light: such images are left out.
        let mut owners = std::collections::HashMap::new();
        for (pixels, _) in &regions {
            for &p in pixels {
                *owners.entry(p).or_insert(0u32) += 1;
            }
        }
        let mut checked = 0;
        for (k, (r, whole)) in regions.iter().enumerate() {
            let m = &markers[k];
            let measurable = *whole
                && m.pixels.len() >= MIN_PIXELS
                && narrowest_width(&m.pixels) >= MIN_WIDTH_PX
                && r.iter().all(|p| owners[p] == 1);
            if !measurable {
                continue;
            }
            let reference = markers[k].sum / markers[k].weight;
            let (mut sum, mut weight) = (DVec2::ZERO, 0.0);
            for &(x, y) in r {
                let l = f64::from(vitreous_optics::srgb::to_linear(
                    images[e][((y as u32 * SIZE.0 + x as u32) * 4) as usize],
                ));
                sum += DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5) * l;
                weight += l;
            }
            let marker = markers[k].marker;
            assert!(weight > 0.0, "eye {e}: marker {marker} is dark on the GPU");
            let gpu = sum / weight;
            let distance = (gpu - reference).length();
            worst = worst.max(distance);
            checked += 1;
            if std::env::var_os("VITREOUS_MARKER_LOG").is_some() {
                let m = &markers[k];
                eprintln!(
                    "{} eye {e} marker {} ({} px): {distance:.3} px",
                    refraction.name(),
                    m.marker,
                    m.pixels.len()
                );
            }
            if distance > bar_px {
                failures.push(format!(
                    "{} eye {e}: marker {marker} ({} px) at {gpu} on the GPU, {reference} in the \
                     reference: {distance:.2} px",
                    refraction.name(),
                    markers[k].pixels.len()
                ));
            }
        }
        eprintln!(
            "{} eye {e}: {checked} marker images measured, worst so far {worst:.2} px",
            refraction.name()
        );
        assert!(
            checked >= 50,
            "eye {e}: only {checked} marker images seen whole"
        );
    }
    assert!(
        failures.is_empty(),
        "{} marker images beyond {bar_px} px:\n{}",
        failures.len(),
        failures.join("\n")
    );
    worst
}

#[test]
fn markers_land_within_a_pixel_at_the_scene_resolution_for_a_neutral_head() {
    for refraction in [Refraction::Paper, Refraction::TwoSurface] {
        markers_land_within(scene_eyes(Vec3::ZERO, Quat::IDENTITY), refraction, 1.0);
    }
}

#[test]
fn markers_land_within_two_pixels_at_the_scene_resolution_for_a_turned_and_moved_head() {
    let turn = Quat::from_euler(glam::EulerRot::YXZ, 0.08, -0.05, 0.02);
    let eyes = scene_eyes(Vec3::new(0.015, -0.01, 0.02), turn);
    for refraction in [Refraction::Paper, Refraction::TwoSurface] {
        markers_land_within(eyes, refraction, 2.0);
    }
}

/// The test's geometry is the scene's: the sphere, the background plane, the image.
#[test]
fn the_scene_geometry_is_the_tests_geometry() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../config/scenes/visual-effects.toml");
    let scene = vitreous_scene::load_scene(&path).expect("the visual-effects scene");
    assert!(scene.object.center_m.abs_diff_eq(CENTER, 1e-6));
    assert!((scene.object.radius_m - RADIUS).abs() < 1e-6);
    assert!((scene.object.ior - IOR).abs() < 1e-6);
    assert!(
        scene
            .background
            .world_from_plane()
            .abs_diff_eq(background_plane(), 1e-6)
    );
    assert_eq!((scene.output.width_px, scene.output.height_px), SIZE);
    let (fov, expected) = (scene.output.fov, scene_fov());
    for (a, b) in [
        (fov.angle_left_rad, expected.left_rad),
        (fov.angle_right_rad, expected.right_rad),
        (fov.angle_up_rad, expected.up_rad),
        (fov.angle_down_rad, expected.down_rad),
    ] {
        assert!((a - b).abs() < 1e-6, "{fov:?}");
    }
}
