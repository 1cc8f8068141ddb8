//! Recording one frame: every pass in order, with its queries, into a slot's command buffer.

use ash::vk;

use super::{Composition, FrameSlot, QUERIES, Renderer, Want, convert, copy, external};
use crate::blur_blend;
use crate::floor::{FIELD_STAMPS, Prepared, Stamps};
use crate::glass::{EyePush, GlassDraws};
use crate::look::FrameParams;
use crate::owned::Owned;
use crate::pipeline;
use crate::statistics::{self, Statistics};

impl Renderer {
    /// Whether a frame composed as `composition` takes away from the glass what the eye
    /// already sees (eq. 6 over the glass, where the scene asks for it): not where the display
    /// shows the world itself, nor where the dimmer's resolve takes it away.
    pub(super) fn compensates(&self, composition: Composition) -> bool {
        let dimmed = self.dimmer.is_some() && composition == Composition::AlphaBlend;
        !composition.world_behind() && !dimmed
    }

    /// Records one frame into the slot's command buffer; returns the floor fields' work it
    /// recorded.
    ///
    /// # Safety
    /// The slot's command buffer must be recording and its previous use finished; it must be
    /// submitted (or dropped unsubmitted) before the renderer is.
    pub(super) unsafe fn record(
        &self,
        slot: &FrameSlot,
        params: &FrameParams,
        want: Want,
        draw: Option<external::ExternalDraw>,
        glass: Option<&GlassDraws>,
    ) -> Prepared {
        let d = &self.ctx.device;
        let cmd = slot.cmd;
        // Where the eyes go: the renderer's own target, or an attached external image (left in
        // COLOR_ATTACHMENT_OPTIMAL by its render pass), with the real world drawn behind when
        // the display shows no real world of its own.
        let composition = draw.map_or(self.own_composition(), |d| d.composition);
        // The dimmer takes the eye passes' images, makes its panel and writes the eyes.
        let dimmer = self
            .dimmer
            .as_ref()
            .filter(|_| composition == Composition::AlphaBlend);
        let external = draw.filter(|d| d.image != external::OWN_TARGET);
        let (eye_framebuffers, eye_image, eye_pass) = match (external, self.external.as_ref()) {
            (Some(draw), Some(ext)) => (
                ext.framebuffers(draw.image),
                ext.images[draw.image],
                ext.render_pass(),
            ),
            _ => (
                self.eye_target.framebuffers(),
                self.eye_target.color.image,
                self.render_pass.raw(),
            ),
        };
        // An external image of another format: the passes draw into the renderer's own eye
        // image (the external framebuffers' views), blitted into it at the end.
        let blit_into = external
            .zip(self.external.as_ref())
            .filter(|(_, ext)| ext.blitted())
            .map(|_| eye_image);
        let world_behind = composition.world_behind();
        let external_image = external.is_some() && self.external.is_some();
        let mut prepared = Prepared::default();
        // SAFETY: the caller's contract (recording, previous use finished); every pass is
        // given a command buffer in the state its `record`/`prepare` requires: `prepare`
        // outside a render pass, the others inside the eye pass begun just before, whose
        // framebuffers belong to the render pass they are begun with. The images copied are
        // in TRANSFER_SRC_OPTIMAL (the render pass's final layout, or the transition before).
        unsafe {
            if self.pose != self.glass_pose {
                self.glass.record_pose(&self.ctx, cmd, &self.pose);
            }
            let queries = slot.queries.as_ref().map(Owned::raw);
            if let Some(pool) = queries {
                d.cmd_reset_query_pool(cmd, pool, 0, QUERIES);
                d.cmd_write_timestamp(cmd, vk::PipelineStageFlags::TOP_OF_PIPE, pool, 0);
            }
            let statistics = Statistics(slot.statistics.as_ref().map(Owned::raw));
            statistics.start(d, cmd);
            let blank = params.look.blank;
            let (inducer, caustics) = (
                params.look.inducer && !blank,
                params.look.caustics && !blank,
            );
            // The shadow's share of the floor's light, for the dimmer to take away.
            let shadow = dimmer.is_some() && !blank && self.inducer.light_share() > 0.0;
            let stamps = (queries.is_some() || statistics.0.is_some()).then_some(Stamps {
                pool: queries,
                first: 3,
                statistics: statistics.0,
                photons: slot.photons.as_ref().map(|(b, _)| b.buffer),
            });
            if inducer || caustics || shadow {
                // Once per pose, timed on its own.
                prepared = self.inducer.prepare(&self.ctx, cmd, &self.scene, stamps);
            } else if let Some(stamps) = stamps {
                stamps.write(d, cmd, 0..FIELD_STAMPS);
            }
            // Every query is begun and ended each frame, so all have results.
            statistics.around(d, cmd, statistics::BLUR_QUERY, || {
                if !blank {
                    let (look, scene) = (&params.look, &self.scene);
                    let depths = blur_blend::depths(look, scene.stack_slices, scene.stack_steps);
                    self.blur.record(&self.ctx, cmd, depths);
                }
            });
            if let Some(pool) = queries {
                d.cmd_write_timestamp(cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, pool, 1);
            }
            if statistics.0.is_some() {
                self.glass.record_clear(&self.ctx, cmd, slot.index);
            }
            let (drawn_pass, drawn_framebuffers) = match dimmer {
                Some(dimmer) => {
                    dimmer.record_before_drawing(&self.ctx, cmd);
                    dimmer.drawn_target()
                }
                None => (eye_pass, eye_framebuffers),
            };
            for (index, eye) in params.eyes.iter().enumerate() {
                self.begin_pass(
                    cmd,
                    drawn_pass,
                    drawn_framebuffers[index],
                    composition.clear_alpha(),
                );
                let query = statistics::eye_query(index);
                statistics.around(d, cmd, query, || {
                    if world_behind {
                        self.world.record(&self.ctx, cmd, eye);
                    }
                    if inducer || caustics || shadow {
                        // Added before the glass, which covers it where the object is.
                        self.inducer
                            .record(&self.ctx, cmd, eye, [inducer, caustics, shadow]);
                    }
                });
                // The glass with the environment's lookup, then where the proof leaves it out,
                // each counted on its own.
                let mut push = EyePush::new(&params.eyes, index, &params.look);
                // Where the glass counts the positions it shades (the frames that count).
                push.refraction_origin[3] = slot.index as f32;
                for covered in [false, true] {
                    statistics.around(d, cmd, query + 1 + u32::from(covered), || {
                        if let Some(glass) = glass {
                            let part = (index, covered);
                            self.glass
                                .record(&self.ctx, cmd, &self.scene, glass, part, &push);
                        }
                    });
                }
                d.cmd_end_render_pass(cmd);
            }
            if statistics.0.is_some() {
                self.glass.record_counted(&self.ctx, cmd);
            }
            if let Some(dimmer) = dimmer {
                dimmer.record_panel(&self.ctx, cmd, &params.eyes);
                for (index, eye) in params.eyes.iter().enumerate() {
                    self.begin_pass(cmd, eye_pass, eye_framebuffers[index], 0.0);
                    dimmer.record_resolve(&self.ctx, cmd, eye, index);
                    d.cmd_end_render_pass(cmd);
                }
            }
            if let Some(to) = blit_into {
                // The eye render pass left the own image in TRANSFER_SRC_OPTIMAL, its writes
                // visible to transfer reads; `to` is an attached image of a checked format.
                convert::record_blit(d, cmd, self.eye_target.color.image, to, self.extent);
            }
            if let Some(pool) = queries {
                d.cmd_write_timestamp(cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, pool, 2);
            }
            if want.eyes && want.world {
                for (index, eye) in params.eyes.iter().enumerate() {
                    self.begin_pass(
                        cmd,
                        self.render_pass.raw(),
                        self.world_target.framebuffers()[index],
                        1.0,
                    );
                    self.world.record(&self.ctx, cmd, eye);
                    d.cmd_end_render_pass(cmd);
                }
            }
            if want.eyes {
                let layer_bytes = u64::from(self.extent.width) * u64::from(self.extent.height) * 4;
                if external_image {
                    external::transition(
                        d,
                        cmd,
                        eye_image,
                        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                    );
                }
                let mut copies = vec![(eye_image, 0)];
                if want.world {
                    copies.push((self.world_target.color.image, 2 * layer_bytes));
                }
                copy::record_readback(d, cmd, &copies, self.extent, slot.readback.buffer);
                if external_image {
                    external::transition(
                        d,
                        cmd,
                        eye_image,
                        vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                        vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
                    );
                }
            }
        }
        prepared
    }

    /// Begins `render_pass` on `framebuffer`, clearing to black (no light) with alpha `alpha`
    /// (which the eye passes keep) and far depth.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass; the framebuffer must belong to a
    /// render pass compatible with `render_pass` and outlive the command buffer's execution.
    unsafe fn begin_pass(
        &self,
        cmd: vk::CommandBuffer,
        render_pass: vk::RenderPass,
        framebuffer: vk::Framebuffer,
        alpha: f32,
    ) {
        let clear = [
            vk::ClearValue {
                color: vk::ClearColorValue {
                    float32: [0.0, 0.0, 0.0, alpha],
                },
            },
            vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 1.0,
                    stencil: 0,
                },
            },
        ];
        // SAFETY: the caller's contract.
        unsafe {
            pipeline::begin_render_pass(
                &self.ctx,
                cmd,
                render_pass,
                framebuffer,
                self.extent,
                &clear,
            );
        }
    }
}
