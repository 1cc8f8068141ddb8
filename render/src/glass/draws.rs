//! The frame's glass draws: which of the pass's pipelines draws which rectangles of each eye's
//! image (the look's, and where the frame proved every refracted ray reaches the background
//! photo, the same look without the environment's lookup: `coverage.rs`), and their
//! recording.

use ash::vk;

use super::{EyePush, GlassPass, GlassVariant};
use crate::camera::{EyeParams, Look};
use crate::compensation::CompensationSet;
use crate::context::GpuContext;
use crate::coverage::CoveredTiles;
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

/// A frame's glass draws: its pipelines, and for each eye the rectangles of its image (x, y,
/// width, height, pixels) drawn with the pipeline that keeps the environment's lookup and
/// with the one that leaves it out (where the proof covers them).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct GlassDraws {
    /// The pipeline with the lookup; `covered` is false.
    pub pick: Pick,
    /// Per eye: the rectangles with the lookup, then those without.
    pub rects: [[Vec<[u32; 4]>; 2]; 2],
    /// The eye images' size.
    pub extent: vk::Extent2D,
}

/// What a proof of coverage is made for: the object's transform, the eye, where refraction is
/// seen from, the image's size.
pub(super) type ProofKey = (glam::Mat4, EyeParams, glam::Vec3, (u32, u32));

impl GlassPass {
    /// The frame's glass draws with `pick` (`covered` ignored) for `eyes` of `extent` pixels,
    /// the object at `pose`: where the look reaches the background and the scene has the
    /// proof, the largest rectangle of the tiles of each eye's image it covers is drawn
    /// without the environment's lookup (`coverage.rs`); the rest of the image, or all of it
    /// (no proof asked for: `pose` `None`), with it.
    pub fn plan(
        &self,
        pick: Pick,
        pose: Option<&ScenePose>,
        eyes: &[EyeParams; 2],
        look: &Look,
        extent: vk::Extent2D,
    ) -> GlassDraws {
        let size = (extent.width, extent.height);
        let pick = Pick {
            covered: false,
            ..pick
        };
        let coverage = pose.zip(
            self.coverage
                .as_ref()
                .filter(|_| self.covered_entry(pick.variant, pick.compensated).is_some()),
        );
        let rects = [0, 1].map(|index| {
            let tiles = coverage.map_or(CoveredTiles::NONE, |(pose, coverage)| {
                let origin = EyePush::new(eyes, index, look).refraction_origin;
                let origin = glam::Vec3::new(origin[0], origin[1], origin[2]);
                let key = (pose.world_from_model, eyes[index], origin, size);
                // A still frame (the same pose, eye and size) has the last one's proof.
                let mut proved = self.proved.get();
                if let Some((_, tiles)) = proved[index].filter(|(last, _)| *last == key) {
                    return tiles;
                }
                let tiles =
                    coverage.covered_tiles(pose.world_from_model, &eyes[index], origin, size);
                proved[index] = Some((key, tiles));
                self.proved.set(proved);
                tiles
            });
            let (covered, rest) = tiles.split(size);
            let covered = [covered]
                .into_iter()
                .filter(|r| r[2] > 0 && r[3] > 0)
                .collect();
            [rest, covered]
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
        let pipeline = match covered {
            Some(entry) => self.covered_pipelines[entry].raw(),
            None => self.pipelines[self.entry(pick.variant, pick.compensated)].raw(),
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
            d.cmd_bind_vertex_buffers(cmd, 0, &[scene.vertices.buffer], &[0]);
            d.cmd_bind_index_buffer(cmd, scene.indices.buffer, 0, vk::IndexType::UINT32);
            for &r in rects {
                d.cmd_set_scissor(cmd, 0, &[rect(r)]);
                d.cmd_draw_indexed(cmd, scene.index_count, 1, 0, 0, 0);
                ctx.work.draw(scene.index_count);
            }
            let whole = [0, 0, draws.extent.width, draws.extent.height];
            d.cmd_set_scissor(cmd, 0, &[rect(whole)]);
        }
        ctx.work.upload(std::mem::size_of::<EyePush>());
    }
}
