//! Eq. 6 over the glass (`[display] compensation = "background"`, shaders/compensation.wgsl):
//! after the glass, each eye's glass pixels lose the light of the real floor or background the
//! eye already sees there, `max(T - B, 0)`, so the display adds only what is missing. Drawn as
//! one triangle at the far plane, scissored to the rectangle around the outline of the object's
//! bounding sphere on screen, that
//! passes the depth test only where the glass (the only depth writer of an additive frame) was
//! drawn.

use ash::vk;
use glam::{Mat4, Vec2, Vec3, Vec4};

use crate::camera::EyeParams;
use crate::context::GpuContext;
use crate::descriptors;
use crate::error::{RenderError, Result};
use crate::memory::{Buffer, Image, upload_texture};
use crate::owned::Owned;
use crate::pipeline::{self, Blend, Depth, PipelineSpec};
use crate::ripmap;
use crate::scene::{GpuScene, PlaneDesc, SceneDesc, TexelData};
use crate::shaders;
use bytemuck::Zeroable as _;

/// What the display takes away from the glass's light (`[display] compensation`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Compensation {
    /// Nothing: the glass's whole light is added (the paper's conditions).
    #[default]
    None,
    /// The real floor or background the eye sees through the glass (eq. 6 over the glass).
    Background,
}

/// Push constants: one eye.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct EyePush {
    world_from_clip: [f32; 16],
    position: [f32; 4],
}

/// The planes and where each photo lies in the packed texture (shaders/shared/seen.wgsl
/// `Planes`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Planes {
    floor_from_world: [f32; 16],
    background_from_world: [f32; 16],
    floor_rect: [f32; 4],
    background_rect: [f32; 4],
}

/// Where each photo's reductions lie in the ripmap atlas (shaders/compensation.wgsl
/// `Levels`).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Levels {
    floor: [[f32; 4]; ripmap::LEVELS],
    background: [[f32; 4]; ripmap::LEVELS],
    sizes: [f32; 4],
}

/// The photos' ripmaps (render/src/ripmap.rs) and where their reductions lie, for B over a
/// pixel's footprint; freed on drop.
struct Ripmaps {
    levels: Buffer,
    /// `None`: the pipeline reads none.
    atlas: Option<Image>,
}

impl Ripmaps {
    fn new(ctx: &GpuContext, desc: &SceneDesc) -> Result<Ripmaps> {
        let atlas = ripmap::atlas(&[&desc.floor.photo, &desc.background.photo])?;
        let (w, h) = (atlas.width as f32, atlas.height as f32);
        let table = |p: &ripmap::PhotoLevels| {
            std::array::from_fn(|k| {
                let ((x, cw), (y, rh)) = (p.columns[k], p.rows[k]);
                [x as f32 / w, cw as f32 / w, y as f32 / h, rh as f32 / h]
            })
        };
        let [floor, background] = [&atlas.photos[0], &atlas.photos[1]];
        let levels = Levels {
            floor: table(floor),
            background: table(background),
            sizes: [
                floor.size.0 as f32,
                floor.size.1 as f32,
                background.size.0 as f32,
                background.size.1 as f32,
            ],
        };
        let levels = Buffer::with_data(
            ctx,
            "ripmap levels",
            bytemuck::bytes_of(&levels),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let atlas = upload_texture(
            ctx,
            "ripmaps",
            vk::Format::R8G8B8A8_SRGB,
            vk::Extent2D {
                width: atlas.width,
                height: atlas.height,
            },
            &atlas.texels,
        )?;
        Ok(Ripmaps {
            levels,
            atlas: Some(atlas),
        })
    }
}

/// The pass, freed on drop.
pub struct CompensationPass {
    pipeline: Owned<vk::Pipeline>,
    layout: Owned<vk::PipelineLayout>,
    _pool: Owned<vk::DescriptorPool>,
    _set_layout: Owned<vk::DescriptorSetLayout>,
    set: vk::DescriptorSet,
    _seen: SeenPhotos,
    /// B over a pixel's footprint (with several positions per glass pixel).
    _ripmaps: Ripmaps,
    /// The mesh's bounding sphere in model units: centre and radius.
    bounds: (Vec3, f32),
}

/// The real floor and background as the eye sees them (shaders/shared/seen.wgsl): the planes'
/// transforms and the photos packed side by side; freed on drop.
pub(crate) struct SeenPhotos {
    planes: Buffer,
    photos: Image,
}

impl SeenPhotos {
    /// Uploads `desc`'s floor and background photos and planes.
    pub(crate) fn new(ctx: &GpuContext, desc: &SceneDesc) -> Result<SeenPhotos> {
        let (w, h, packed, [floor_rect, background_rect]) = pack(&desc.floor, &desc.background)?;
        let photos = upload_texture(
            ctx,
            "seen photos",
            vk::Format::R8G8B8A8_SRGB,
            vk::Extent2D {
                width: w,
                height: h,
            },
            &packed,
        )?;
        let planes = Planes {
            floor_from_world: inverse(desc.floor.world_from_plane),
            background_from_world: inverse(desc.background.world_from_plane),
            floor_rect: floor_rect.to_array(),
            background_rect: background_rect.to_array(),
        };
        let planes = Buffer::with_data(
            ctx,
            "seen planes",
            bytemuck::bytes_of(&planes),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        Ok(SeenPhotos { planes, photos })
    }

    /// Writes the planes (binding 0), the photos (1) and the scene's photo sampler (2) into
    /// `set`, which no pending command buffer uses.
    pub(crate) fn write(&self, ctx: &GpuContext, set: vk::DescriptorSet, scene: &GpuScene) {
        descriptors::write_uniform_buffer(ctx, set, 0, self.planes.buffer);
        descriptors::write_texture(ctx, set, 1, 2, self.photos.view, scene.photo_sampler());
    }
}

/// The two photos side by side in one sRGB texture (floor left, background right), and each
/// one's normalised rectangle.
fn pack(floor: &PlaneDesc, background: &PlaneDesc) -> Result<(u32, u32, Vec<u8>, [Vec4; 2])> {
    let photo = |p: &PlaneDesc| -> Result<(u32, u32, Vec<u8>)> {
        match p.photo.data {
            TexelData::Srgb8(bytes) => Ok((p.photo.width, p.photo.height, bytes.to_vec())),
            TexelData::LinearF32(_) => Err(RenderError::Creation(
                "a real plane's photo must be 8-bit sRGB".into(),
            )),
        }
    };
    let (fw, fh, f) = photo(floor)?;
    let (bw, bh, b) = photo(background)?;
    let (w, h) = (fw + bw, fh.max(bh));
    let mut packed = vec![0u8; (w * h * 4) as usize];
    for (x0, pw, ph, pixels) in [(0, fw, fh, &f), (fw, bw, bh, &b)] {
        for y in 0..ph {
            let src = &pixels[(y * pw * 4) as usize..((y + 1) * pw * 4) as usize];
            let at = ((y * w + x0) * 4) as usize;
            packed[at..at + src.len()].copy_from_slice(src);
        }
    }
    let rect = |x0: u32, pw: u32, ph: u32| {
        Vec4::new(
            x0 as f32 / w as f32,
            0.0,
            (x0 + pw) as f32 / w as f32,
            ph as f32 / h as f32,
        )
    };
    Ok((w, h, packed, [rect(0, fw, fh), rect(fw, bw, bh)]))
}

impl CompensationPass {
    /// Builds the pass for `desc`'s floor and background, drawing into `render_pass`.
    pub fn new(
        ctx: &GpuContext,
        render_pass: vk::RenderPass,
        scene: &GpuScene,
        desc: &SceneDesc,
    ) -> Result<CompensationPass> {
        let fragment = vk::ShaderStageFlags::FRAGMENT;
        let set_layout = descriptors::set_layout(
            ctx,
            &[
                (0, vk::DescriptorType::UNIFORM_BUFFER, fragment),
                (1, vk::DescriptorType::SAMPLED_IMAGE, fragment),
                (2, vk::DescriptorType::SAMPLER, fragment),
                (3, vk::DescriptorType::UNIFORM_BUFFER, fragment),
                (4, vk::DescriptorType::SAMPLED_IMAGE, fragment),
            ],
        )?;
        let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let layout = pipeline::layout(
            ctx,
            Some(set_layout.raw()),
            stages,
            size_of::<EyePush>() as u32,
        )?;
        let pipeline = pipeline::create(
            ctx,
            &PipelineSpec {
                render_pass,
                layout: layout.raw(),
                vertex: (shaders::COMPENSATION_VS, c"vs_main"),
                fragment: (
                    shaders::COMPENSATION_FS[usize::from(desc.glass_samples > 1)],
                    c"fs_main",
                ),
                bindings: &[],
                attributes: &[],
                cull: vk::CullModeFlags::NONE,
                depth: Depth::Behind,
                blend: Blend::TakeAway,
            },
        )?;
        let seen = SeenPhotos::new(ctx, desc)?;
        // The footprint's ripmaps only where the pipeline reads them; elsewhere an empty
        // table and the seen photos stand in for them, unread.
        let ripmaps = if desc.glass_samples > 1 {
            Ripmaps::new(ctx, desc)?
        } else {
            Ripmaps {
                levels: Buffer::with_data(
                    ctx,
                    "ripmap levels (unread)",
                    bytemuck::bytes_of(&Levels::zeroed()),
                    vk::BufferUsageFlags::UNIFORM_BUFFER,
                )?,
                atlas: None,
            }
        };
        let pool = descriptors::pool(
            ctx,
            1,
            &[
                (vk::DescriptorType::UNIFORM_BUFFER, 2),
                (vk::DescriptorType::SAMPLED_IMAGE, 2),
                (vk::DescriptorType::SAMPLER, 1),
            ],
        )?;
        let set = descriptors::allocate_set(ctx, pool.raw(), set_layout.raw())?;
        seen.write(ctx, set, scene);
        descriptors::write_uniform_buffer(ctx, set, 3, ripmaps.levels.buffer);
        let atlas = ripmaps.atlas.as_ref().unwrap_or(&seen.photos);
        descriptors::write_image(ctx, set, 4, atlas.view);
        Ok(CompensationPass {
            pipeline,
            layout,
            _pool: pool,
            _set_layout: set_layout,
            set,
            _seen: seen,
            _ripmaps: ripmaps,
            bounds: bounding_sphere(desc.mesh.positions),
        })
    }

    /// Records the pass for one eye, inside that eye's render pass, after the glass.
    ///
    /// # Safety
    /// `cmd` must be recording inside a render pass compatible with the one given to
    /// [`CompensationPass::new`], after the glass was drawn in it; `self` must outlive the
    /// command buffer's execution.
    pub unsafe fn record(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        eye: &EyeParams,
        world_from_model: Mat4,
        extent: vk::Extent2D,
    ) {
        let Some(area) = screen_rect(eye, world_from_model, self.bounds, extent) else {
            return;
        };
        let d = &ctx.device;
        let push = EyePush {
            world_from_clip: eye.clip_from_world().inverse().to_cols_array(),
            position: eye.position_m.extend(1.0).to_array(),
        };
        // SAFETY: the caller's contract (inside a compatible render pass, `self` outliving
        // the execution); the push constants match the layout's range.
        unsafe {
            pipeline::Binding {
                point: vk::PipelineBindPoint::GRAPHICS,
                pipeline: self.pipeline.raw(),
                layout: self.layout.raw(),
                set: self.set,
                push_stages: vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
            }
            .record(d, cmd, bytemuck::bytes_of(&push));
            d.cmd_set_scissor(cmd, 0, &[area]);
            d.cmd_draw(cmd, 3, 1, 0, 0);
        }
        ctx.work.upload(size_of::<EyePush>());
        ctx.work.draw(3);
    }
}

/// The bounding sphere of `positions` (about their bounding box's centre).
fn bounding_sphere(positions: &[Vec3]) -> (Vec3, f32) {
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let center = (lo + hi) * 0.5;
    let radius = positions
        .iter()
        .map(|p| p.distance(center))
        .fold(0.0f32, f32::max);
    (center, radius)
}

/// Points on the outline of a sphere as the eye sees it: the circle where the sphere's tangent
/// cone from the eye touches it.
const OUTLINE_POINTS: usize = 32;

/// The pixels of an `extent` image that the sphere `bounds` (model units) placed by
/// `world_from_model` can cover in `eye`'s view: the rectangle around its outline (sampled
/// at [`OUTLINE_POINTS`] points on a circle widened so the polygon holds the true one), the
/// whole image when the eye is inside the sphere or a point lies behind it, `None` when off it.
fn screen_rect(
    eye: &EyeParams,
    world_from_model: Mat4,
    (center, radius): (Vec3, f32),
    extent: vk::Extent2D,
) -> Option<vk::Rect2D> {
    let size = Vec2::new(extent.width as f32, extent.height as f32);
    let whole = vk::Rect2D {
        offset: vk::Offset2D { x: 0, y: 0 },
        extent,
    };
    let c = world_from_model.transform_point3(center);
    let r = world_from_model
        .transform_vector3(Vec3::X * radius)
        .length();
    let to_center = c - eye.position_m;
    let d = to_center.length();
    if d <= r * 1.001 {
        return Some(whole);
    }
    // The outline circle: centre r^2 / d nearer the eye than the sphere's, radius
    // r sqrt(d^2 - r^2) / d, in the plane facing the eye; widened by 1 / cos(pi / n) so the
    // n-gon through the sampled points encloses it.
    let axis = to_center / d;
    let circle_center = c - axis * (r * r / d);
    let circle_radius =
        r * (d * d - r * r).sqrt() / d / (std::f32::consts::PI / OUTLINE_POINTS as f32).cos();
    let u = axis.any_orthonormal_vector();
    let v = axis.cross(u);
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for i in 0..OUTLINE_POINTS {
        let a = i as f32 / OUTLINE_POINTS as f32 * std::f32::consts::TAU;
        let point = circle_center + (u * a.cos() + v * a.sin()) * circle_radius;
        let Some(p) = eye.project_to_pixel(point, size) else {
            return Some(whole);
        };
        (lo, hi) = (lo.min(p), hi.max(p));
    }
    // A pixel of margin for rasterisation's rounding.
    let lo = (lo.floor() - Vec2::ONE).max(Vec2::ZERO);
    let hi = (hi.ceil() + Vec2::ONE).min(size);
    (hi.x > lo.x && hi.y > lo.y).then_some(vk::Rect2D {
        offset: vk::Offset2D {
            x: lo.x as i32,
            y: lo.y as i32,
        },
        extent: vk::Extent2D {
            width: (hi.x - lo.x) as u32,
            height: (hi.y - lo.y) as u32,
        },
    })
}

/// A plane's world-to-plane transform, as the shader takes it.
fn inverse(world_from_plane: Mat4) -> [f32; 16] {
    world_from_plane.inverse().to_cols_array()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Fov;
    use crate::scene::TextureDesc;

    #[test]
    fn the_scissor_holds_every_point_of_the_sphere_and_little_else() {
        let fov = Fov {
            left_rad: -0.35,
            right_rad: 0.35,
            up_rad: 0.26,
            down_rad: -0.26,
        };
        let eye = EyeParams::new(Vec3::new(-0.03, 0.0, 0.0), glam::Quat::IDENTITY, fov);
        let extent = vk::Extent2D {
            width: 320,
            height: 240,
        };
        let size = Vec2::new(320.0, 240.0);
        // Off the image: no rectangle.
        let off = Mat4::from_translation(Vec3::new(0.3, 0.0, -0.5));
        assert!(screen_rect(&eye, off, (Vec3::ZERO, 0.04), extent).is_none());
        for center in [Vec3::new(0.0, -0.26, -1.5), Vec3::new(0.1, 0.05, -0.5)] {
            let placed = Mat4::from_translation(center);
            let rect = screen_rect(&eye, placed, (Vec3::ZERO, 0.04), extent).unwrap();
            let (x0, y0) = (rect.offset.x as f32, rect.offset.y as f32);
            let (x1, y1) = (
                x0 + rect.extent.width as f32,
                y0 + rect.extent.height as f32,
            );
            let mut outline = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
            for i in 0..64 {
                for j in 0..=32 {
                    let (a, b) = (
                        i as f32 / 64.0 * std::f32::consts::TAU,
                        j as f32 / 32.0 * std::f32::consts::PI,
                    );
                    let p =
                        center + Vec3::new(b.sin() * a.cos(), b.cos(), b.sin() * a.sin()) * 0.04;
                    let q = eye.project_to_pixel(p, size).unwrap();
                    assert!(
                        q.x >= x0 && q.x <= x1 && q.y >= y0 && q.y <= y1,
                        "{q} outside {rect:?}"
                    );
                    outline = (outline.0.min(q), outline.1.max(q));
                }
            }
            // Within 3 pixels of the outline's own bounds on every side.
            assert!(
                outline.0.x - x0 <= 3.0 && outline.0.y - y0 <= 3.0,
                "{outline:?} {rect:?}"
            );
            assert!(
                x1 - outline.1.x <= 3.0 && y1 - outline.1.y <= 3.0,
                "{outline:?} {rect:?}"
            );
        }
    }

    #[test]
    fn the_photos_are_packed_side_by_side_with_their_rectangles() {
        let floor = [1u8, 2, 3, 4].repeat(2 * 2);
        let wall = [9u8, 9, 9, 9].repeat(3);
        let plane = |width, height, data| PlaneDesc {
            world_from_plane: Mat4::IDENTITY,
            photo: TextureDesc {
                width,
                height,
                data: TexelData::Srgb8(data),
            },
        };
        let (w, h, packed, [f, b]) = pack(&plane(2, 2, &floor), &plane(3, 1, &wall)).unwrap();
        assert_eq!((w, h), (5, 2));
        // Row 0: two floor texels, three wall texels; row 1: two floor texels, then nothing.
        assert_eq!(&packed[..8], &[1, 2, 3, 4, 1, 2, 3, 4]);
        assert_eq!(&packed[8..20], &[9; 12]);
        assert_eq!(&packed[20..28], &[1, 2, 3, 4, 1, 2, 3, 4]);
        assert_eq!(&packed[28..40], &[0; 12]);
        assert_eq!(f, Vec4::new(0.0, 0.0, 0.4, 1.0));
        assert_eq!(b, Vec4::new(0.4, 0.0, 1.0, 0.5));
    }
}
