//! The PNG images `vitreous compare` reads: sRGB pixels with their size, every error naming the
//! file, and how many pixels are not opaque, so that alpha the comparison leaves out is said.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};

/// Most pixels an image may have (as the scene loader's images).
const MAX_PIXELS: u64 = vitreous_scene::MAX_IMAGE_PIXELS;

/// An image as read.
pub struct Png {
    /// The file.
    pub path: PathBuf,
    /// Width, pixels.
    pub width: u32,
    /// Height, pixels.
    pub height: u32,
    /// Tightly packed sRGB RGBA8, opaque where the file has no alpha.
    pub rgba: Vec<u8>,
    /// Pixels whose alpha is below 255.
    pub translucent: u64,
}

impl Png {
    /// Reads `path`, naming it in every error.
    pub fn read(path: &Path) -> Result<Png> {
        let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
        let reader =
            image::ImageReader::with_format(std::io::Cursor::new(&bytes), image::ImageFormat::Png);
        let (w, h) = reader
            .into_dimensions()
            .with_context(|| format!("{}: not a PNG image", path.display()))?;
        if w == 0 || h == 0 || u64::from(w) * u64::from(h) > MAX_PIXELS {
            bail!(
                "{}: {w}x{h} pixels is outside 1..={MAX_PIXELS} pixels",
                path.display()
            );
        }
        let decoded = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
            .with_context(|| format!("{}: not a PNG image", path.display()))?;
        let rgba = decoded.to_rgba8().into_raw();
        let translucent = rgba.chunks_exact(4).filter(|p| p[3] < 255).count() as u64;
        Ok(Png {
            path: path.to_path_buf(),
            width: w,
            height: h,
            rgba,
            translucent,
        })
    }

    /// Reads `path`, which must have `reference`'s size.
    pub fn read_like(path: &Path, reference: &Png) -> Result<Png> {
        let png = Png::read(path)?;
        if (png.width, png.height) != (reference.width, reference.height) {
            bail!(
                "the images differ in size: {} is {}x{}, {} is {}x{}",
                reference.path.display(),
                reference.width,
                reference.height,
                path.display(),
                png.width,
                png.height
            );
        }
        Ok(png)
    }

    /// The pixels without their alpha, sRGB RGB8.
    pub fn rgb(&self) -> Vec<u8> {
        crate::rgb_of(&self.rgba)
    }

    /// Why the comparison leaves this image's alpha out, when some pixel is not opaque
    /// (`None` when all are, or when the caller uses the alpha).
    pub fn alpha_ignored(&self, alpha_used: bool) -> Option<String> {
        (self.translucent > 0 && !alpha_used).then(|| {
            format!(
                "{}: alpha ignored: {} of {} pixels are not opaque, and compare measures the \
                 colour channels as stored; alpha counts only in TEST with --display and a \
                 --scene whose display has a segmented dimmer ([display] model = \"dimmer\"), \
                 as the share of the real world the dimmer takes away",
                self.path.display(),
                self.translucent,
                u64::from(self.width) * u64::from(self.height)
            )
        })
    }
}
