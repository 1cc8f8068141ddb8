//! The frame's glass draws: which of the pass's pipelines draws which rectangles of each eye's
//! image (the look's, and where the frame proved every refracted ray reaches the background
//! photo, the same look without the environment's lookup: `coverage.rs`), and their
//! recording.

use ash::vk;
use vitreous_optics::camera::EyeParams;

use super::{EyePush, GlassPass, GlassVariant};
use crate::compensation::CompensationSet;
use crate::context::GpuContext;
use crate::coverage::Tiles;
use crate::look::Look;
use crate::pose::ScenePose;
use crate::scene::GpuScene;

/// Which of the pass's pipelines draws: the look's, taking away what the eye already sees
/// (`compensated`, where the pass was built with it), and without the environment's lookup
/// (`covered`, where the look has a pipeline for it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pick {
    pub variant: GlassVariant,
    pub compensated: bool,
    pub covered: bool,
}

/// A frame's glass draws: its pipelines, and for each eye the rectangles of its image drawn
/// with the pipeline that keeps the environment's lookup and with the one that leaves it out
/// (where the proof covers them).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GlassDraws {
    /// The pipeline with the lookup; `covered` is false.
    pub pick: Pick,
    /// Per eye: the rectangles with the lookup, then those without.
    pub rects: [[Vec<RectDraw>; 2]; 2],
    /// The eye images' size.
    pub extent: vk::Extent2D,
}

/// One rectangle of an eye's image (x, y, width, height, pixels) and the ranges of the pass's
/// indices drawn in it: the ball's patches (its own triangles', or its proxy's: `proxy.rs`)
/// that can show there (`patches.rs`), or the whole
/// mesh.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RectDraw {
    pub rect: [u32; 4],
    pub ranges: Vec<std::ops::Range<u32>>,
}

/// What a rectangle drawn without the lookup costs beyond its pixels, in pixels drawn with the
/// lookup rather than without it: its patches' draws, and the patches on its edges drawn again
/// beside it. On lavapipe the two-surface study scene at 480 x 540 measured the same with 0 and
/// 2000 (73 and 58 draws a frame); a rectangle that saves less is not worth a GPU's fixed cost
/// per draw.
const RECT_PX: u64 = 2000;

/// What a proof of coverage is made for: the object's transform, the eye, where refraction is
/// seen from, the image's size.
pub(super) type ProofKey = (glam::Mat4, EyeParams, glam::Vec3, (u32, u32));

/// A proof and what it was made for: the tiles it covers, and those the glass shows in.
pub(super) type Proof = (ProofKey, (Tiles, Tiles));

impl GlassPass {
    /// The frame's glass draws with `pick` (`covered` ignored) for `eyes` of `extent` pixels,
    /// the object at `pose`: where the look reaches the background and the scene has the
    /// proof, the largest rectangles of the tiles of each eye's image it covers are drawn
    /// without the environment's lookup (`CoveredTiles::split`); the rest of the image, or all
    /// of it (no proof asked for: `pose` `None`), with it.
    pub fn plan(
        &self,
        pick: Pick,
        (pose, prove): (&ScenePose, bool),
        eyes: &[EyeParams; 2],
        look: &Look,
        (extent, index_count): (vk::Extent2D, u32),
    ) -> GlassDraws {
        let size = (extent.width, extent.height);
        let pick = Pick {
            covered: false,
            ..pick
        };
        let coverage = self
            .coverage
            .as_ref()
            .filter(|_| prove && self.covered_entry(pick.variant, pick.compensated).is_some());
        let rects = [0, 1].map(|index| {
            let (covered, shown) = coverage.map_or((Tiles::NONE, Tiles::ALL), |coverage| {
                let origin = EyePush::new(eyes, index, look).refraction_origin;
                let origin = glam::Vec3::new(origin[0], origin[1], origin[2]);
                let key = (pose.world_from_model, eyes[index], origin, size);
                // A still frame (the same pose, eye and size) has the last one's proof.
                let mut proved = self.proved.get();
                if let Some((_, tiles)) = proved[index].filter(|(last, _)| *last == key) {
                    return tiles;
                }
                let (world_from_model, eye) = (pose.world_from_model, &eyes[index]);
                let tiles = (
                    coverage.covered_tiles(world_from_model, eye, origin, size),
                    coverage.shown_tiles(world_from_model, eye, size),
                );
                proved[index] = Some((key, tiles));
                self.proved.set(proved);
                tiles
            });
            let split = covered.split(shown, size, RECT_PX);
            let patches = match &self.proxy {
                Some(proxy) => Some(&proxy.patches),
                None => self.patches.as_ref().map(|(patches, _)| patches),
            };
            let seen = patches.map(|patches| {
                (
                    patches,
                    patches.seen(pose.world_from_model, &eyes[index], size),
                )
            });
            [split.rest, split.covered].map(|rects| {
                rects
                    .into_iter()
                    .map(|rect| {
                        let ranges = match &seen {
                            Some((patches, seen)) => patches.ranges(seen, rect),
                            None => std::iter::once(0..index_count).collect(),
                        };
                        RectDraw { rect, ranges }
                    })
                    .filter(|draw| !draw.ranges.is_empty())
                    .collect()
            })
        });
        GlassDraws {
            pick,
            rects,
            extent,
        }
    }

    /// Records the draws of the object for eye `eye` of `draws`, with the lookup or without it
    /// (`covered`), inside that eye's render pass: one draw per rectangle of its part (none
    /// for none). Leaves the scissor at the whole image.
    ///
    /// # Safety
    /// `cmd` must be recording inside a render pass compatible with this pass, of
    /// `draws.extent`.
    pub unsafe fn record(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        scene: &GpuScene,
        draws: &GlassDraws,
        (eye, covered): (usize, bool),
        push: &EyePush,
    ) {
        let rects = &draws.rects[eye][usize::from(covered)];
        if rects.is_empty() {
            return;
        }
        let pick = Pick {
            covered,
            ..draws.pick
        };
        let covered = self
            .covered_entry(pick.variant, pick.compensated)
            .filter(|_| pick.covered);
        let pipeline = match (covered, self.counted_pipeline(pick)) {
            (Some(entry), _) => self.covered_pipelines[entry].raw(),
            (None, Some(counting)) => counting,
            (None, None) => self.pipelines[self.entry(pick.variant, pick.compensated)].raw(),
        };
        let sets: Vec<_> = std::iter::once(self.set)
            .chain(self.compensation.as_ref().map(CompensationSet::set))
            .collect();
        let d = &ctx.device;
        let rect = |[x, y, width, height]: [u32; 4]| vk::Rect2D {
            offset: vk::Offset2D {
                x: x as i32,
                y: y as i32,
            },
            extent: vk::Extent2D { width, height },
        };
        // SAFETY: the caller's contract (recording inside a compatible render pass); the
        // pipeline, set and scene buffers are live for as long as the renderer that records
        // them, which waits for its frames before dropping them; the pipelines take their
        // scissor dynamically.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
            d.cmd_bind_descriptor_sets(
                cmd,
                vk::PipelineBindPoint::GRAPHICS,
                self.layout.raw(),
                0,
                &sets,
                &[],
            );
            d.cmd_push_constants(
                cmd,
                self.layout.raw(),
                vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT,
                0,
                bytemuck::bytes_of(push),
            );
            let (vertices, indices) = match &self.proxy {
                Some(proxy) => (&proxy.vertices, &proxy.indices),
                None => (
                    &scene.vertices,
                    self.patches.as_ref().map_or(&scene.indices, |(_, b)| b),
                ),
            };
            d.cmd_bind_vertex_buffers(cmd, 0, &[vertices.buffer], &[0]);
            d.cmd_bind_index_buffer(cmd, indices.buffer, 0, vk::IndexType::UINT32);
            for draw in rects {
                d.cmd_set_scissor(cmd, 0, &[rect(draw.rect)]);
                for range in &draw.ranges {
                    d.cmd_draw_indexed(cmd, range.len() as u32, 1, range.start, 0, 0);
                    ctx.work.draw(range.len() as u32);
                }
            }
            let whole = [0, 0, draws.extent.width, draws.extent.height];
            d.cmd_set_scissor(cmd, 0, &[rect(whole)]);
        }
        ctx.work.upload(std::mem::size_of::<EyePush>());
    }
}
