//! What the app submitted, read back (`VITREOUS_SIM_IMAGES`): each projection image the app
//! releases is copied from its swapchain on the app's own Vulkan device and queue (the
//! `XrGraphicsBindingVulkanKHR` it created the session with) before the runtime gets it, and
//! each view `xrEndFrame` submits is measured in its image rectangle: how many pixels carry
//! alpha, its mean and largest value and where they lie (`alpha.csv`). What the wearer would see
//! of them over a picture of the real world: [`crate::wearer`].
//!
//! ```text
//! frame,view,width,height,blend,alpha_px,alpha_mean,alpha_max,alpha_box
//! 12,0,320,240,alpha_blend,1830,0.0312,209,140;96;201;170
//! ```
//!
//! `alpha_mean` is over the whole rectangle (0-1), `alpha_max` 0-255, `alpha_box` the smallest
//! rectangle `x0;y0;x1;y1` (inclusive, in the view's rectangle) holding every pixel with alpha,
//! empty when none has.

use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

use ash::vk;
use openxr::sys;

pub use crate::readback::{Reader, VulkanBinding};

/// The header line of `alpha.csv`.
pub const HEADER: &str = "frame,view,width,height,blend,alpha_px,alpha_mean,alpha_max,alpha_box";

/// A swapchain image's texels as the layer reads them: 4 bytes each, RGBA or BGRA.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TexelLayout {
    /// Blue first (`B8G8R8A8_*`).
    pub bgra: bool,
    /// sRGB-encoded colour (`*_SRGB`); alpha is linear either way.
    pub srgb: bool,
}

impl TexelLayout {
    /// The layout of a `VkFormat`, for the four 8-bit colour formats the layer reads.
    pub fn of(format: i64) -> Option<TexelLayout> {
        let f = vk::Format::from_raw(i32::try_from(format).ok()?);
        Some(match f {
            vk::Format::R8G8B8A8_UNORM => TexelLayout {
                bgra: false,
                srgb: false,
            },
            vk::Format::R8G8B8A8_SRGB => TexelLayout {
                bgra: false,
                srgb: true,
            },
            vk::Format::B8G8R8A8_UNORM => TexelLayout {
                bgra: true,
                srgb: false,
            },
            vk::Format::B8G8R8A8_SRGB => TexelLayout {
                bgra: true,
                srgb: true,
            },
            _ => return None,
        })
    }
}

/// One submitted view's image: its rectangle's texels and how to read them.
#[derive(Clone, Debug)]
pub struct ViewImage {
    /// Width and height of the rectangle, pixels.
    pub size: (u32, u32),
    /// Its texels, row by row, 4 bytes each.
    pub texels: Vec<u8>,
    /// Their layout.
    pub layout: TexelLayout,
    /// The view's field of view across and down, degrees.
    pub fov_deg: [f32; 2],
}

impl ViewImage {
    /// The `rect` of a layer of `width`-wide texels.
    pub fn cut(
        layer: &[u8],
        width: u32,
        rect: sys::Rect2Di,
        layout: TexelLayout,
        fov: sys::Fovf,
    ) -> Option<ViewImage> {
        let (x0, y0) = (
            usize::try_from(rect.offset.x).ok()?,
            usize::try_from(rect.offset.y).ok()?,
        );
        let (w, h) = (
            usize::try_from(rect.extent.width).ok()?,
            usize::try_from(rect.extent.height).ok()?,
        );
        let stride = width as usize * 4;
        let mut texels = Vec::with_capacity(w * h * 4);
        for y in y0..y0 + h {
            let row = layer.get(y * stride + x0 * 4..y * stride + (x0 + w) * 4)?;
            texels.extend_from_slice(row);
        }
        Some(ViewImage {
            size: (w as u32, h as u32),
            texels,
            layout,
            fov_deg: [
                (fov.angle_right - fov.angle_left).to_degrees(),
                (fov.angle_up - fov.angle_down).to_degrees(),
            ],
        })
    }

    /// What its alpha says.
    pub fn alpha(&self) -> AlphaStats {
        let (w, _) = self.size;
        let mut stats = AlphaStats::default();
        let mut sum = 0u64;
        for (i, t) in self.texels.chunks_exact(4).enumerate() {
            let a = t[3];
            sum += u64::from(a);
            if a > 0 {
                stats.pixels += 1;
                stats.max = stats.max.max(a);
                let (x, y) = ((i % w as usize) as u32, (i / w as usize) as u32);
                stats.bounds = Some(match stats.bounds {
                    None => [x, y, x, y],
                    Some([x0, y0, x1, y1]) => [x0.min(x), y0.min(y), x1.max(x), y1.max(y)],
                });
            }
        }
        let n = self.texels.len() / 4;
        stats.mean = if n == 0 {
            0.0
        } else {
            sum as f64 / (255.0 * n as f64)
        };
        stats
    }

    /// The texel at (x, y) as linear RGB and alpha (0-1).
    pub(crate) fn linear(&self, x: usize, y: usize) -> ([f32; 3], f32) {
        let i = (y * self.size.0 as usize + x) * 4;
        let t = &self.texels[i..i + 4];
        let (r, b) = if self.layout.bgra {
            (t[2], t[0])
        } else {
            (t[0], t[2])
        };
        let decode = |v: u8| {
            let v = f32::from(v) / 255.0;
            if self.layout.srgb {
                srgb_to_linear(v)
            } else {
                v
            }
        };
        (
            [decode(r), decode(t[1]), decode(b)],
            f32::from(t[3]) / 255.0,
        )
    }
}

/// Alpha statistics of one view.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AlphaStats {
    /// Pixels whose alpha is above 0.
    pub pixels: u64,
    /// Mean alpha over the rectangle, 0-1.
    pub mean: f64,
    /// Largest alpha, 0-255.
    pub max: u8,
    /// The smallest rectangle (x0, y0, x1, y1, inclusive) holding every pixel with alpha.
    pub bounds: Option<[u32; 4]>,
}

/// An sRGB-encoded value (0-1) as linear light.
pub(crate) fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

/// A session's record, shared between its calls.
pub type SharedImages = std::sync::Arc<std::sync::Mutex<SessionImages>>;

/// A session's record of what the app submits.
pub struct SessionImages {
    /// Reads the app's images (`None`: not a Vulkan session, or the reader could not be made,
    /// said once).
    pub reader: Option<Reader>,
    /// `alpha.csv`.
    pub log: AlphaLog,
    /// The folder it and the wearer's views go to.
    pub dir: PathBuf,
    /// The last submitted frame's views, and its blend mode.
    pub last: Vec<ViewImage>,
    /// The blend mode the last frame was submitted with.
    pub last_blend: sys::EnvironmentBlendMode,
}

impl Drop for SessionImages {
    /// A record dropped without its session ending (the instance destroyed with the session
    /// still there) leaves its reader's Vulkan objects to the device: the app may have destroyed
    /// that already. `xrDestroySession` frees them first (the reader taken out and dropped).
    fn drop(&mut self) {
        if let Some(reader) = self.reader.take() {
            std::mem::forget(reader);
        }
    }
}

impl std::fmt::Debug for SessionImages {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SessionImages")
            .field("reads", &self.reader.is_some())
            .field("dir", &self.dir)
            .field("last_views", &self.last.len())
            .finish()
    }
}

/// A short name for a blend mode.
pub fn blend_name(mode: sys::EnvironmentBlendMode) -> &'static str {
    match mode {
        sys::EnvironmentBlendMode::OPAQUE => "opaque",
        sys::EnvironmentBlendMode::ADDITIVE => "additive",
        sys::EnvironmentBlendMode::ALPHA_BLEND => "alpha_blend",
        _ => "other",
    }
}

/// The `alpha.csv` writer: the header at creation, one flushed line per submitted view.
pub struct AlphaLog {
    file: File,
}

impl AlphaLog {
    /// Creates `dir` if needed and `dir/alpha.csv` with its header.
    pub fn create(dir: &Path) -> io::Result<AlphaLog> {
        std::fs::create_dir_all(dir)?;
        let mut file = File::create(dir.join("alpha.csv"))?;
        writeln!(file, "{HEADER}")?;
        file.flush()?;
        Ok(AlphaLog { file })
    }

    /// Writes one view's line.
    pub fn write(
        &mut self,
        frame: u64,
        view: usize,
        size: (u32, u32),
        blend: sys::EnvironmentBlendMode,
        stats: &AlphaStats,
    ) -> io::Result<()> {
        let bounds = stats
            .bounds
            .map(|b| format!("{};{};{};{}", b[0], b[1], b[2], b[3]))
            .unwrap_or_default();
        writeln!(
            self.file,
            "{frame},{view},{},{},{},{},{:.6},{},{bounds}",
            size.0,
            size.1,
            blend_name(blend),
            stats.pixels,
            stats.mean,
            stats.max,
        )?;
        self.file.flush()
    }
}

#[cfg(test)]
impl ViewImage {
    /// A 64 x 48 view over 40 x 30 degrees, linear RGBA8, every texel `light` with `alpha(x, y)`.
    pub(crate) fn test_view(alpha: impl Fn(u32, u32) -> u8, light: u8) -> ViewImage {
        let (w, h) = (64, 48);
        let mut texels = Vec::new();
        for y in 0..h {
            for x in 0..w {
                texels.extend_from_slice(&[light, light, light, alpha(x, y)]);
            }
        }
        ViewImage {
            size: (w, h),
            texels,
            layout: TexelLayout {
                bgra: false,
                srgb: false,
            },
            fov_deg: [40.0, 30.0],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alpha_statistics_count_bound_and_average_the_alpha() {
        let v = ViewImage::test_view(
            |x, y| {
                if (10..20).contains(&x) && (5..8).contains(&y) {
                    255
                } else {
                    0
                }
            },
            0,
        );
        let s = v.alpha();
        assert_eq!(s.pixels, 30);
        assert_eq!(s.max, 255);
        assert_eq!(s.bounds, Some([10, 5, 19, 7]));
        assert!((s.mean - 30.0 / (64.0 * 48.0)).abs() < 1e-9);
        assert_eq!(ViewImage::test_view(|_, _| 0, 9).alpha().bounds, None);
    }

    #[test]
    fn the_four_eight_bit_colour_formats_are_read_and_others_not() {
        assert_eq!(
            TexelLayout::of(vk::Format::B8G8R8A8_SRGB.as_raw() as i64),
            Some(TexelLayout {
                bgra: true,
                srgb: true
            })
        );
        assert_eq!(
            TexelLayout::of(vk::Format::R16G16B16A16_SFLOAT.as_raw() as i64),
            None
        );
    }
}
