//! Decoded images: sRGB photos and textures (PNG) and linear HDR environment maps
//! (OpenEXR or Radiance HDR).

use std::io::Cursor;

/// Largest accepted width or height of any image, pixels.
pub const MAX_IMAGE_SIZE_PX: u32 = 16384;

/// Most pixels accepted in one image (2^24, e.g. 4096 x 4096 or 16384 x 1024): 64 MiB decoded
/// as sRGB RGBA8, 256 MiB as float RGBA. The limit is by memory, not by side: with defocus on, a
/// photo's blur stack is `STACK_SLICES` (16) times its decoded size (1 GiB at
/// this limit).
pub const MAX_IMAGE_PIXELS: u64 = 1 << 24;

/// A decoded image, rows top to bottom, RGBA interleaved.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// The pixels, `width * height * 4` values.
    pub data: PixelData,
}

/// Pixel storage. `Debug` prints only the kind and length.
#[derive(Clone, PartialEq)]
pub enum PixelData {
    /// RGBA, 8 bits per channel, sRGB-encoded colour, linear alpha: photos and textures.
    Srgb8(Vec<u8>),
    /// RGBA, 32-bit float, linear light: HDR environment maps.
    LinearF32(Vec<f32>),
}

/// Why an [`Image`] could not be made.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ImageError {
    /// Width or height is zero.
    #[error("image has zero size ({width}x{height} px)")]
    ZeroSize {
        /// Width in pixels.
        width: u64,
        /// Height in pixels.
        height: u64,
    },
    /// Width or height exceeds [`MAX_IMAGE_SIZE_PX`].
    #[error("image is {width}x{height} px; at most {MAX_IMAGE_SIZE_PX} px per side is accepted")]
    TooLarge {
        /// Width in pixels.
        width: u64,
        /// Height in pixels.
        height: u64,
    },
    /// More pixels than [`MAX_IMAGE_PIXELS`].
    #[error(
        "image is {width}x{height} px ({} Mpx, {} MiB decoded as RGBA8); at most {} Mpx is \
         accepted (e.g. 4096x4096): scale the photo down",
        width * height / 1_000_000,
        width * height * 4 / (1 << 20),
        MAX_IMAGE_PIXELS / 1_000_000
    )]
    TooManyPixels {
        /// Width in pixels.
        width: u64,
        /// Height in pixels.
        height: u64,
    },
    /// The pixel buffer does not hold `width * height * 4` values.
    #[error("pixel buffer holds {actual} values, expected {expected}")]
    DataLength {
        /// `width * height * 4`.
        expected: usize,
        /// The buffer's length.
        actual: usize,
    },
}

impl std::fmt::Debug for PixelData {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PixelData::Srgb8(v) => write!(f, "Srgb8({} bytes)", v.len()),
            PixelData::LinearF32(v) => write!(f, "LinearF32({} floats)", v.len()),
        }
    }
}

impl Image {
    /// Checks that a size is usable: neither side zero nor above [`MAX_IMAGE_SIZE_PX`], and
    /// at most [`MAX_IMAGE_PIXELS`] in all.
    pub fn check_dimensions(width: u64, height: u64) -> Result<(), ImageError> {
        if width == 0 || height == 0 {
            Err(ImageError::ZeroSize { width, height })
        } else if width > u64::from(MAX_IMAGE_SIZE_PX) || height > u64::from(MAX_IMAGE_SIZE_PX) {
            Err(ImageError::TooLarge { width, height })
        } else if width * height > MAX_IMAGE_PIXELS {
            Err(ImageError::TooManyPixels { width, height })
        } else {
            Ok(())
        }
    }

    /// Makes an image after checking its size and buffer length.
    pub fn new(width: u32, height: u32, data: PixelData) -> Result<Image, ImageError> {
        Self::check_dimensions(u64::from(width), u64::from(height))?;
        let expected = width as usize * height as usize * 4;
        let actual = match &data {
            PixelData::Srgb8(v) => v.len(),
            PixelData::LinearF32(v) => v.len(),
        };
        if actual != expected {
            return Err(ImageError::DataLength { expected, actual });
        }
        Ok(Image {
            width,
            height,
            data,
        })
    }

    /// `(width, height)` in pixels.
    pub fn dimensions(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Width over height.
    pub fn aspect(&self) -> f32 {
        self.width as f32 / self.height as f32
    }
}

/// Limits handed to the `image` crate so that a hostile header cannot make it allocate
/// without bound.
fn decode_limits() -> image::Limits {
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_IMAGE_SIZE_PX);
    limits.max_image_height = Some(MAX_IMAGE_SIZE_PX);
    // The largest accepted image as float RGBA, plus room for the decoder's own buffers.
    limits.max_alloc = Some(MAX_IMAGE_PIXELS * 16 + (64 << 20));
    limits
}

/// Decodes a PNG photo or texture to sRGB RGBA8 (greyscale and 16-bit inputs are expanded
/// or reduced).
pub(crate) fn decode_photo(bytes: &[u8]) -> Result<Image, String> {
    guard(|| decode_photo_inner(bytes))
}

/// Runs a third-party decoder so that a panic on hostile input becomes an error.
fn guard(decode: impl FnOnce() -> Result<Image, String>) -> Result<Image, String> {
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(decode))
        .unwrap_or_else(|_| Err("the image decoder failed on this file (internal panic)".into()))
}

fn decode_photo_inner(bytes: &[u8]) -> Result<Image, String> {
    let format = image::guess_format(bytes).map_err(|_| {
        "not a recognised image; expected a PNG (8 or 16 bit, grey or colour)".to_owned()
    })?;
    if format != image::ImageFormat::Png {
        return Err(format!(
            "is {format:?}; photos and textures must be PNG in this build"
        ));
    }
    let mut reader = image::ImageReader::with_format(Cursor::new(bytes), format);
    reader.limits(decode_limits());
    let (w, h) = reader
        .into_dimensions()
        .map_err(|e| format!("bad PNG header: {e}"))?;
    Image::check_dimensions(u64::from(w), u64::from(h)).map_err(|e| e.to_string())?;
    let mut reader = image::ImageReader::with_format(Cursor::new(bytes), format);
    reader.limits(decode_limits());
    let decoded = reader
        .decode()
        .map_err(|e| format!("cannot decode PNG: {e}"))?;
    let rgba = decoded.to_rgba8();
    let (w, h) = rgba.dimensions();
    Image::new(w, h, PixelData::Srgb8(rgba.into_raw())).map_err(|e| e.to_string())
}

const EXR_MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];

/// Decodes a latitude-longitude HDR map, OpenEXR (first layer with RGB channels, largest
/// resolution level; alpha 1 when absent) or Radiance HDR, to linear RGBA f32.
pub(crate) fn decode_hdr(bytes: &[u8]) -> Result<Image, String> {
    if bytes.starts_with(&EXR_MAGIC) {
        guard(|| decode_exr(bytes))
    } else if bytes.starts_with(b"#?") {
        guard(|| decode_radiance(bytes))
    } else {
        Err("not an OpenEXR (bad magic number) nor a Radiance HDR file".to_owned())
    }
}

fn decode_exr(bytes: &[u8]) -> Result<Image, String> {
    use exr::prelude::{ReadChannels, ReadLayers, RgbaChannels, Vec2, read};

    let meta = exr::meta::MetaData::read_from_buffered(Cursor::new(bytes), false)
        .map_err(|e| format!("bad OpenEXR header: {e}"))?;
    for header in &meta.headers {
        let size = header.layer_size;
        Image::check_dimensions(size.width() as u64, size.height() as u64)
            .map_err(|e| format!("OpenEXR layer: {e}"))?;
    }

    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |size: Vec2<usize>, _channels: &RgbaChannels| {
                (size.width(), vec![0.0f32; size.width() * size.height() * 4])
            },
            |(width, pixels): &mut (usize, Vec<f32>),
             pos: Vec2<usize>,
             (r, g, b, a): (f32, f32, f32, f32)| {
                let i = (pos.y() * *width + pos.x()) * 4;
                if let Some(px) = pixels.get_mut(i..i + 4) {
                    px.copy_from_slice(&[r, g, b, a]);
                }
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_buffered(Cursor::new(bytes))
        .map_err(|e| format!("cannot decode OpenEXR: {e}"))?;

    let size = image.layer_data.size;
    let (_, pixels) = image.layer_data.channel_data.pixels;
    let (w, h) = (size.width() as u32, size.height() as u32);
    Image::new(w, h, PixelData::LinearF32(pixels)).map_err(|e| e.to_string())
}

fn decode_radiance(bytes: &[u8]) -> Result<Image, String> {
    let mut reader = image::ImageReader::with_format(Cursor::new(bytes), image::ImageFormat::Hdr);
    reader.limits(decode_limits());
    let decoded = reader
        .decode()
        .map_err(|e| format!("cannot decode Radiance HDR: {e}"))?;
    let rgba = decoded.to_rgba32f();
    let (w, h) = rgba.dimensions();
    Image::new(w, h, PixelData::LinearF32(rgba.into_raw())).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dimensions_outside_limits_are_refused() {
        assert!(Image::check_dimensions(0, 5).is_err());
        assert!(Image::check_dimensions(5, 0).is_err());
        assert!(Image::check_dimensions(16385, 1).is_err());
        assert!(Image::check_dimensions(16384, 1024).is_ok());
        assert!(Image::check_dimensions(4096, 4096).is_ok());
        let e = Image::check_dimensions(16384, 16384).unwrap_err();
        assert!(e.to_string().contains("1024 MiB"), "{e}");
        assert!(Image::check_dimensions(4097, 4096).is_err());
    }

    #[test]
    fn new_checks_buffer_length() {
        assert!(Image::new(2, 2, PixelData::Srgb8(vec![0; 16])).is_ok());
        assert!(matches!(
            Image::new(2, 2, PixelData::LinearF32(vec![0.0; 15])),
            Err(ImageError::DataLength { .. })
        ));
    }

    #[test]
    fn garbage_is_refused_by_both_decoders() {
        assert!(decode_photo(b"hello").is_err());
        assert!(decode_hdr(b"hello").is_err());
        assert!(decode_hdr(&EXR_MAGIC).is_err());
        assert!(decode_hdr(b"#?RADIANCE\n").is_err());
    }
}
