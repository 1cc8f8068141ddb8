//! The figures of an image against a reference: ꟻLIP (NVIDIA's perceptual difference
//! evaluator; mean over pixels, 0 identical, lower is closer) and PSNR (8-bit sRGB, all three
//! channels), over the whole view and region by region; the additive limit; and the reports
//! that hold them.

use anyhow::Result;
use serde::Serialize;
use vitreous_optics::camera::EyeParams;
use vitreous_scene::{Placement, Scene};

use crate::flip;
use crate::regions::{Labels, Region};

/// The figures of one region.
#[derive(Clone, Debug, Serialize)]
pub struct RegionFigures {
    /// The region (`whole` for the whole view).
    pub region: String,
    /// Pixels in it.
    pub pixels: u64,
    /// Mean ꟻLIP over its pixels (`None` when it has none).
    pub flip_mean: Option<f64>,
    /// PSNR over its pixels, dB (`None` when it has none or the images are equal there).
    pub psnr_db: Option<f64>,
}

/// What `vitreous compare` reports.
#[derive(Clone, Debug, Serialize)]
pub struct Comparison {
    /// The reference image.
    pub reference: String,
    /// The measured image.
    pub test: String,
    /// Image size, pixels.
    pub width_px: u32,
    /// Image size, pixels.
    pub height_px: u32,
    /// Pixels per degree ꟻLIP was run at.
    pub pixels_per_degree: f32,
    /// The scene whose regions split the figures, if any.
    pub scene: Option<String>,
    /// Where the regions were seen from: `neutral head, left eye`, or the frame and eye of
    /// the `reference.json` beside the reference image.
    pub regions_from: Option<String>,
    /// Whether TEST was the display's light, added to the seen image (`--display`).
    pub display_added_to_seen: bool,
    /// With `--shift-deg` or `--roll-deg`: how far the display's light and panel landed from
    /// where they belong, degrees: right, down, and turned.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub misregistration_deg: Option<[f32; 3]>,
    /// The whole view first, then each region of the scene.
    pub regions: Vec<RegionFigures>,
    /// With `--seen`: the same figures for what the eye sees with nothing drawn.
    pub nothing_drawn: Option<Vec<RegionFigures>>,
    /// With `--seen`: the same figures for the additive limit, max(seen, reference) per pixel
    /// and channel.
    pub additive_limit: Option<Vec<RegionFigures>>,
}

/// The closest a display that only adds light can bring `seen` to `reference`: the larger of
/// the two in every channel of every pixel (sRGB encoding keeps the order of linear light).
pub fn additive_limit(seen: &[u8], reference: &[u8]) -> Vec<u8> {
    seen.iter()
        .zip(reference)
        .map(|(&a, &b)| a.max(b))
        .collect()
}

/// PSNR of 8-bit values, dB; `None` when they are equal.
fn psnr(squared_error: f64, values: u64) -> Option<f64> {
    (squared_error > 0.0 && values > 0)
        .then(|| 10.0 * (255.0f64 * 255.0 / (squared_error / values as f64)).log10())
}

/// Compares `test` with `reference`: ꟻLIP's error map and the figures per region (`labels`:
/// each pixel's region and the ring around the object, rows after the whole view's; or none
/// for the whole view only).
pub fn compare(
    reference: &[u8],
    test: &[u8],
    (width, height): (u32, u32),
    ppd: f32,
    labels: Option<&Labels>,
) -> Result<(Vec<f32>, Vec<RegionFigures>)> {
    let error = flip::error_map(reference, test, (width, height), ppd)?;
    let squared: Vec<f64> = reference
        .chunks_exact(3)
        .zip(test.chunks_exact(3))
        .map(|(a, b)| {
            a.iter()
                .zip(b)
                .map(|(&x, &y)| (f64::from(x) - f64::from(y)).powi(2))
                .sum()
        })
        .collect();
    let figures = |name: &str, keep: &dyn Fn(usize) -> bool| {
        let (mut pixels, mut flip, mut se) = (0u64, 0f64, 0f64);
        for i in (0..error.len()).filter(|&i| keep(i)) {
            pixels += 1;
            flip += f64::from(error[i]);
            se += squared[i];
        }
        RegionFigures {
            region: name.to_owned(),
            pixels,
            flip_mean: (pixels > 0).then(|| flip / pixels as f64),
            psnr_db: psnr(se, pixels * 3),
        }
    };
    let mut out = vec![figures("whole", &|_| true)];
    if let Some(labels) = labels {
        for region in Region::ALL {
            out.push(figures(region.name(), &|i| labels.regions[i] == region));
        }
        out.push(figures("around", &|i| labels.around[i]));
    }
    Ok((error, out))
}

/// The figures of one eye of one frame against the physical reference: what the eye sees with
/// the display's light over the seen image, the seen image itself, and the additive limit.
#[derive(Clone, Debug, Serialize)]
pub struct ReferenceFigures {
    /// Frame index.
    pub frame: u64,
    /// `left` or `right`.
    pub eye: &'static str,
    /// The display's light over the seen image, whole view then each region.
    pub regions: Vec<RegionFigures>,
    /// The seen image (nothing drawn).
    pub nothing_drawn: Vec<RegionFigures>,
    /// The additive limit, max(seen, reference).
    pub additive_limit: Vec<RegionFigures>,
    /// The display's light over the seen image with the display misregistered, one entry per
    /// registration error asked for (`replay --compare-shift-deg`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub misregistered: Vec<ShiftedFigures>,
}

/// The figures of what the eye sees with the display's light and panel misregistered.
#[derive(Clone, Debug, Serialize)]
pub struct ShiftedFigures {
    /// How far the display's image lands from where it belongs, degrees, right and down.
    pub shift_deg: [f32; 2],
    /// How far it is turned about the view's centre, degrees.
    pub roll_deg: f32,
    /// Whole view, each region, the ring.
    pub regions: Vec<RegionFigures>,
}

/// Measures `shown` (RGB8, what the eye sees: the display's light over the seen image) and
/// `seen` (RGB8, what the eye sees with nothing drawn) against `real` (RGB8, the physical
/// reference), region by region for `camera` with the object and light at `placement`, at the
/// scene's pixels per degree.
pub fn against_reference(
    scene: &Scene,
    camera: &EyeParams,
    placement: &Placement,
    images: [&[u8]; 3],
    (w, h): (u32, u32),
) -> Result<[Vec<RegionFigures>; 3]> {
    let [real, seen, shown] = images;
    let against = Against::new(scene, camera, placement, real, (w, h));
    Ok([
        against.rows(shown)?,
        against.rows(seen)?,
        against.rows(&additive_limit(seen, real))?,
    ])
}

/// One eye's physical reference with its regions, to measure several images against.
pub struct Against<'a> {
    /// The reference, RGB8.
    real: &'a [u8],
    /// Its regions and the ring around the object.
    labels: Labels,
    /// Its size, pixels.
    size: (u32, u32),
    /// The scene's pixels per degree at that size.
    ppd: f32,
}

impl<'a> Against<'a> {
    /// `real` (RGB8, `size`) seen by `camera`, with the object and light at `placement`.
    pub fn new(
        scene: &Scene,
        camera: &EyeParams,
        placement: &Placement,
        real: &'a [u8],
        size: (u32, u32),
    ) -> Against<'a> {
        Against {
            real,
            labels: Labels::of(scene, camera, placement, size.0, size.1),
            size,
            ppd: scene_pixels_per_degree(scene, size.0),
        }
    }

    /// The figures of `image` (RGB8) against the reference: the whole view, each region, the
    /// ring.
    pub fn rows(&self, image: &[u8]) -> Result<Vec<RegionFigures>> {
        compare(self.real, image, self.size, self.ppd, Some(&self.labels)).map(|r| r.1)
    }

    /// The pixels per degree the figures are measured at.
    pub fn pixels_per_degree(&self) -> f32 {
        self.ppd
    }
}

/// The pixels per degree of a `width`-pixel image across the scene's horizontal field of view.
pub fn scene_pixels_per_degree(scene: &Scene, width: u32) -> f32 {
    let fov = scene.output.fov;
    width as f32 / (fov.angle_right_rad - fov.angle_left_rad).to_degrees()
}

/// RGBA8 pixels without their alpha.
pub fn rgb_of(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}
