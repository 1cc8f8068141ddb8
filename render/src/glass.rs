//! The glass object pass, baseline method: environment-map reflection and refraction blended
//! by a Fresnel term (METHOD.md section 6; shaders/glass.wgsl); refraction to the background
//! plane (eq. 7-8), or through both surfaces of the object (two-surface: a ball's sphere, a
//! convex gem's facet planes, or any closed mesh's triangles).
//!
//! Under 700 lines, one idea: the pass and what its pipelines read (the variant table, the
//! push constants, the globals, the facet planes and triangles it uploads for the exit),
//! built once per scene; its tests check that table against the shaders. What a frame draws
//! with them, and the recording, is `glass/draws.rs`; a ball's triangles in patches, each
//! drawn where it can show, `glass/patches.rs`; the coarse polyhedron a ball's light is drawn
//! on where the shader takes it from the sphere alone, `glass/proxy.rs`; the positions a ball's
//! pixels shade, counted on the device, `glass/counted.rs`; the object as the exit sees it,
//! `glass/object.rs`; a mesh's triangles for the shader's search, `glass/mesh.rs`; the floor
//! under the object as the glass sees it, `glass/floor_light.rs`.

mod counted;
mod draws;
mod floor_light;
mod mesh;
mod object;
mod patches;
mod proxy;

use draws::Proof;
pub use draws::{GlassDraws, Pick};
use floor_light::FloorLight;
use object::{metres_per_model_unit, object_frame, searched_mesh, upload_facet_planes};
use patches::Patches;
use proxy::Proxy;

use ash::vk;
use glam::Vec4;
use vitreous_optics::camera::EyeParams;
use vitreous_optics::optics::{FRESNEL_BIAS, FRESNEL_POWER, FRESNEL_SCALE};
use vitreous_optics::refraction::Refraction;

use crate::compensation::CompensationSet;
use crate::context::GpuContext;
use crate::coverage::{self, PhotoCoverage};
use crate::descriptors;
use crate::error::Result;
use crate::look::{Look, Reflection};
use crate::memory::Buffer;
use crate::owned::Owned;
use crate::parallel;
use crate::pipeline::{self, Blend, Depth, PipelineSpec};
use crate::pose::ScenePose;
use crate::scene::{GpuScene, SceneDesc, VERTEX_STRIDE};
use crate::shaders;
use crate::work::ShaderCost;

/// Phong exponent of the highlight: a sharp highlight, as on polished glass.
const PHONG_EXPONENT: f32 = 200.0;
/// Strength of the Phong highlight relative to the light's radiance.
const PHONG_STRENGTH: f32 = 1.0;

/// Which of the glass pass's pipelines draws a look. Each is its own fragment entry point
/// (shaders/glass.wgsl): a switch read from a uniform at run time costs both of its sides on
/// some devices (lavapipe runs them masked).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GlassVariant {
    /// Refraction reaches the registered background plane (disparity or defocus on); off,
    /// it reaches the environment map.
    pub background: bool,
    /// Phong reflection instead of environment + Fresnel.
    pub phong: bool,
}

impl GlassVariant {
    /// Every variant, in [`GlassVariant::index`] order.
    const ALL: [GlassVariant; 4] = [
        GlassVariant::new(false, false),
        GlassVariant::new(false, true),
        GlassVariant::new(true, false),
        GlassVariant::new(true, true),
    ];

    const fn new(background: bool, phong: bool) -> GlassVariant {
        GlassVariant { background, phong }
    }

    /// The variant that draws `look`.
    pub fn of(look: &Look) -> GlassVariant {
        GlassVariant {
            background: look.disparity || look.defocus.is_some(),
            phong: look.reflection == Reflection::Phong,
        }
    }

    /// Position in [`GlassVariant::ALL`] and in the last index of `shaders::GLASS_FS`.
    fn index(self) -> usize {
        usize::from(self.background) * 2 + usize::from(self.phong)
    }
}

/// Push constants: one eye.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct EyePush {
    /// World to clip space of this eye.
    pub clip_from_world: [f32; 16],
    /// Eye position (xyz, metres) and eye index (w).
    pub position: [f32; 4],
    /// Where refraction to the background plane is seen from (xyz, metres).
    pub refraction_origin: [f32; 4],
}

impl EyePush {
    /// The push constants of eye `index` of `eyes` drawn with `look` (its blur is in the
    /// images the frame blended, `blur_blend.rs`).
    pub fn new(eyes: &[EyeParams; 2], index: usize, look: &Look) -> EyePush {
        let eye = &eyes[index];
        let refraction_origin = if look.disparity {
            eye.position_m
        } else {
            (eyes[0].position_m + eyes[1].position_m) / 2.0
        };
        EyePush {
            clip_from_world: eye.clip_from_world().to_cols_array(),
            position: eye.position_m.extend(index as f32).to_array(),
            refraction_origin: refraction_origin.extend(1.0).to_array(),
        }
    }
}

/// Uniform block matching `Globals` in glass.wgsl. Every field a pose changes
/// ([`Globals::posed`]) comes before `absorption`: a new pose uploads only that part.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Globals {
    world_from_model: [f32; 16],
    normal_from_model: [f32; 16],
    background_from_world: [f32; 16],
    optics: [f32; 4],
    light: [f32; 4],
    light_colour: [f32; 4],
    shading: [f32; 4],
    model_from_world: [f32; 16],
    radial: [f32; 4],
    /// xyz: the object's centre in the world; w: the floor's lit share (`glass/floor_light.rs`).
    center_world: [f32; 4],
    /// rgb: absorption inside the glass in halvings per model unit (Beer-Lambert, two-surface
    /// refraction: the coefficient per world metre times the model's uniform scale over ln 2,
    /// for the shader's exp2; 0 for clear glass); w: 1 where the object is a ball, whose front
    /// surface the shader takes as the sphere through its vertices, else 0.
    absorption: [f32; 4],
    /// Maps the world into the floor plane's frame (its photo on the unit square at z = 0).
    floor_from_world: [f32; 16],
}

impl Globals {
    /// These globals with the object and light of `pose`.
    fn posed(mut self, pose: &ScenePose, floor_light: &FloorLight) -> Globals {
        self.world_from_model = pose.world_from_model.to_cols_array();
        self.normal_from_model = pose.world_from_model.inverse().transpose().to_cols_array();
        self.model_from_world = pose.world_from_model.inverse().to_cols_array();
        let center = glam::Vec3::new(self.radial[0], self.radial[1], self.radial[2]);
        self.center_world = pose
            .world_from_model
            .transform_point3(center)
            .extend(floor_light.share_at(pose))
            .to_array();
        self.light = pose.light_position_m.extend(1.0).to_array();
        self
    }
}

/// The glass pipelines and their descriptors, freed on drop.
pub struct GlassPass {
    /// One pipeline per variant, in [`GlassVariant::index`] order, for the scene's
    /// refraction model; with compensation, the same four again taking away what the eye
    /// already sees.
    pipelines: Vec<Owned<vk::Pipeline>>,
    /// The static cost of one invocation of each pipeline's fragment shader, as
    /// `pipelines`.
    costs: Vec<ShaderCost>,
    /// Where the scene's refraction towards the background can be proved to reach its photo:
    /// the proof, and the background looks' pipelines that leave out the environment's
    /// lookup (`COVERED`), fresnel then Phong, with compensation the same two again; their
    /// costs as `covered_pipelines`.
    coverage: Option<PhotoCoverage>,
    covered_pipelines: Vec<Owned<vk::Pipeline>>,
    covered_costs: Vec<ShaderCost>,
    /// Each eye's last proof and what it was made for.
    proved: std::cell::Cell<[Option<Proof>; 2]>,
    /// Where the object is a ball drawn on its own triangles: those in patches, each drawn only
    /// where it can show, and the indices in their order.
    patches: Option<(Patches, Buffer)>,
    /// Where the pipelines take a ball from its sphere alone: the polyhedron every look draws
    /// it on (`proxy.rs`).
    proxy: Option<Proxy>,
    /// Pipeline layout (the set, the compensation's set 1 with compensation, eye push
    /// constants).
    layout: Owned<vk::PipelineLayout>,
    /// What the compensated pipelines read (`[display] compensation = "background"`).
    compensation: Option<CompensationSet>,
    /// Pool the set lives in, and the set's layout.
    _pool: Owned<vk::DescriptorPool>,
    _set_layout: Owned<vk::DescriptorSetLayout>,
    /// The descriptor set: globals, environment map, sampler.
    set: vk::DescriptorSet,
    /// The uniform buffer behind `Globals`.
    globals_buffer: Buffer,
    /// What the buffer was created with; [`GlassPass::record_pose`] changes only the pose.
    globals: Globals,
    /// The object's triangles in their hierarchy (two-surface refraction through a mesh), or
    /// one unused element.
    _mesh: Buffer,
    /// The facet planes of a convex faceted object (two-surface refraction), or one plane.
    _planes: Buffer,
    /// The floor under the object as the glass sees it (`glass/floor_light.rs`).
    floor_light: FloorLight,
    /// The render pass, blend and layout the pipelines were made for (the counting ones are
    /// made when the frames start counting).
    render_pass: vk::RenderPass,
    blend: Blend,
    /// Where the glass shades a ball's light in two parts, each over as many positions as it
    /// needs: the row of `shaders::GLASS_FS_COUNTED` of the model; the counting pipelines of the
    /// environment looks, once the frames count (`counted.rs`); and the counters they add to.
    counted_row: Option<usize>,
    /// Where the glass searches a mesh's triangles for the exit: the row of
    /// `shaders::GLASS_FS_MESH_COUNTED` of the model, whose counting pipelines (every look)
    /// `counted_pipelines` holds once the frames count.
    mesh_row: Option<usize>,
    counted_pipelines: Vec<Owned<vk::Pipeline>>,
    counter: counted::PositionCounter,
}

impl GlassPass {
    /// Builds the pass for `scene` drawing into `render_pass`; with `compensation`, also the
    /// pipelines that take away what the eye already sees.
    pub fn new(
        ctx: &GpuContext,
        render_pass: vk::RenderPass,
        scene: &GpuScene,
        desc: &SceneDesc,
        blurred: [vk::ImageView; 2],
        compensation: Option<CompensationSet>,
    ) -> Result<GlassPass> {
        let stages = vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT;
        let fragment = vk::ShaderStageFlags::FRAGMENT;
        let (image, sampler) = (
            vk::DescriptorType::SAMPLED_IMAGE,
            vk::DescriptorType::SAMPLER,
        );
        let set_layout = descriptors::set_layout(
            ctx,
            &[
                (0, vk::DescriptorType::UNIFORM_BUFFER, stages),
                (1, image, fragment),
                (2, sampler, fragment),
                (3, image, fragment),
                (4, sampler, fragment),
                (5, image, fragment),
                (6, vk::DescriptorType::STORAGE_BUFFER, fragment),
                (7, vk::DescriptorType::STORAGE_BUFFER, fragment),
                (8, image, fragment),
                (9, vk::DescriptorType::STORAGE_BUFFER, fragment),
                (10, image, fragment),
            ],
        )?;
        let set_layouts: Vec<_> = std::iter::once(set_layout.raw())
            .chain(compensation.as_ref().map(CompensationSet::set_layout))
            .collect();
        let layout =
            pipeline::layout_of_sets(ctx, &set_layouts, stages, size_of::<EyePush>() as u32)?;
        let (radial, ball) = object_frame(desc);
        let (planes, convex) = upload_facet_planes(ctx, desc, radial)?;
        let mesh = mesh::upload(ctx, searched_mesh(desc, radial, ball || convex)?)?;
        let floor_light = FloorLight::new(ctx, desc)?;
        // Clear glass gets the two-surface pipelines without the absorption's exponentials, a
        // ball the ones that take its sphere, a convex faceted object the ones that
        // leave it through its facet planes; a scene whose photos are the room the ones that
        // trace it.
        let clear = desc.attenuation.is_clear();
        let model = match (desc.refraction, ball, convex) {
            (Refraction::Paper, ..) => 0,
            (Refraction::TwoSurface, true, _) => 4 - usize::from(clear),
            (Refraction::TwoSurface, false, true) => 6 - usize::from(clear),
            (Refraction::TwoSurface, false, false) => 2 - usize::from(clear),
        } + if desc.room { shaders::GLASS_MODELS } else { 0 };
        // Several positions per pixel: the same model's pipelines compiled with `SUPERSAMPLED`.
        let samples = desc.glass_samples.max(1);
        let shaded = model
            + if samples > 1 {
                2 * shaders::GLASS_MODELS
            } else {
                0
            };
        let compensated: &[usize] = if compensation.is_some() {
            &[0, 1]
        } else {
            &[0]
        };
        let entries: Vec<_> = compensated
            .iter()
            .flat_map(|&c| GlassVariant::ALL.iter().map(move |v| (c, v.index())))
            .collect();
        // Where the shader takes a ball from its sphere alone (through both surfaces, over
        // several positions per pixel), every look draws it on a proxy (`proxy.rs`); not where
        // a surface texture needs the model's own coordinates.
        let proxy = (desc.refraction == Refraction::TwoSurface
            && ball
            && samples > 1
            && desc.surface.is_none())
        .then(|| Proxy::new(ctx, glam::Vec3::from_slice(&radial[..3]), radial[3]))
        .transpose()?;
        let proxied = proxy.is_some();
        // Drawn for a segmented dimmer, the glass's alpha is the share of a pixel it covers
        // over the floor's (render/src/dimmer); otherwise the eye passes' alpha is kept.
        let blend = match desc.dimmer {
            Some(_) => Blend::ReplaceColorCoverAlpha,
            None => Blend::ReplaceColor,
        };
        let create = |fragment, proxied| {
            create_pipeline(ctx, (render_pass, blend), layout.raw(), (fragment, proxied))
        };
        let pipelines = parallel::in_parallel(&entries, |&(c, v)| {
            create(shaders::GLASS_FS[c][shaded][v], proxied)
        })?;
        // The proof and its pipelines where the model has them compiled and the object is a
        // ball.
        let coverage = shaders::covered_row(shaded).and_then(|_| PhotoCoverage::of(desc, ball));
        let covered_row = shaders::covered_row(shaded).filter(|_| coverage.is_some());
        let covered = || {
            compensated.iter().flat_map(move |&c| {
                covered_row
                    .into_iter()
                    .flat_map(move |row| (0..2).map(move |phong| (c, row, phong)))
            })
        };
        let covered_pipelines = covered()
            .map(|(c, row, phong)| create(shaders::GLASS_FS_COVERED[c][row][phong], proxied))
            .collect::<Result<Vec<_>>>()?;
        // The model's triangles in patches, where they are drawn (a ball not on its proxy).
        let patches = match coverage::ball(&desc.mesh).filter(|_| !proxied) {
            Some((center, _)) => {
                let patches = Patches::new(desc.mesh.positions, desc.mesh.indices, center);
                let bytes = bytemuck::cast_slice(&patches.indices);
                let usage = vk::BufferUsageFlags::INDEX_BUFFER;
                let buffer = Buffer::with_data(ctx, "glass patches' indices", bytes, usage)?;
                Some((patches, buffer))
            }
            None => None,
        };
        let unsampled_row = shaders::covered_row(model);
        let pool = descriptors::pool(
            ctx,
            1,
            &[
                (vk::DescriptorType::UNIFORM_BUFFER, 1),
                (vk::DescriptorType::SAMPLED_IMAGE, 5),
                (vk::DescriptorType::SAMPLER, 2),
                (vk::DescriptorType::STORAGE_BUFFER, 3),
            ],
        )?;
        let set = descriptors::allocate_set(ctx, pool.raw(), set_layout.raw())?;
        let surface_opacity = if desc.surface.is_some() {
            1.0 - desc.surface_transmittance
        } else {
            0.0
        };
        let globals = Globals {
            world_from_model: [0.0; 16],
            normal_from_model: [0.0; 16],
            background_from_world: desc.background.world_from_plane.inverse().to_cols_array(),
            optics: [desc.ior, FRESNEL_BIAS, FRESNEL_SCALE, FRESNEL_POWER],
            light: [0.0; 4],
            light_colour: desc.light.radiance.extend(PHONG_EXPONENT).to_array(),
            shading: Vec4::new(
                desc.exposure,
                surface_opacity,
                PHONG_STRENGTH,
                samples as f32,
            )
            .to_array(),
            model_from_world: [0.0; 16],
            radial,
            center_world: [0.0; 4],
            absorption: (desc.attenuation.coefficient_per_m()
                * (metres_per_model_unit(desc) * std::f32::consts::LOG2_E))
                .extend(if ball { 1.0 } else { 0.0 })
                .to_array(),
            floor_from_world: desc.floor.world_from_plane.inverse().to_cols_array(),
        }
        .posed(&ScenePose::of(desc), &floor_light);
        let globals_buffer = Buffer::with_data(
            ctx,
            "glass globals",
            bytemuck::bytes_of(&globals),
            vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
        )?;
        descriptors::write_uniform_buffer(ctx, set, 0, globals_buffer.buffer);
        descriptors::write_texture(ctx, set, 1, 2, scene.environment.view, scene.env_sampler());
        let [background, surface] = blurred;
        descriptors::write_texture(ctx, set, 3, 4, background, scene.photo_sampler());
        descriptors::write_image(ctx, set, 5, surface);
        descriptors::write_storage_buffer(ctx, set, 6, mesh.buffer);
        descriptors::write_storage_buffer(ctx, set, 7, planes.buffer);
        let counter = counted::PositionCounter::new(ctx)?;
        descriptors::write_storage_buffer(ctx, set, 9, counter.buffer());
        descriptors::write_image(ctx, set, 8, scene.photos[0].view);
        descriptors::write_image(ctx, set, 10, floor_light.image.view);
        Ok(GlassPass {
            pipelines,
            // The loop over a pixel's positions counts once in the static cost: each further
            // position is charged as one more one-position shader (its surface fetch, which the
            // loop does not repeat, included).
            costs: entries
                .iter()
                .map(|&(c, v)| {
                    shaders::GLASS_FS_COST[c][shaded][v]
                        .with_runs(shaders::GLASS_FS_COST[0][model][v], samples * samples)
                })
                .collect(),
            coverage,
            proved: std::cell::Cell::new([None; 2]),
            patches,
            proxy,
            covered_pipelines,
            covered_costs: covered()
                .map(|(c, row, phong)| {
                    let one = unsampled_row.map_or(ShaderCost::default(), |r| {
                        shaders::GLASS_FS_COVERED_COST[0][r][phong]
                    });
                    shaders::GLASS_FS_COVERED_COST[c][row][phong].with_runs(one, samples * samples)
                })
                .collect(),
            layout,
            compensation,
            _pool: pool,
            _set_layout: set_layout,
            set,
            globals_buffer,
            globals,
            _mesh: mesh,
            _planes: planes,
            floor_light,
            render_pass,
            blend,
            counted_row: shaders::counted_row(shaded),
            mesh_row: shaders::mesh_counted_row(shaded),
            counted_pipelines: Vec::new(),
            counter,
        })
    }

    /// One of the pass's pipelines: its vertex shader and `fragment`.
    fn create_pipeline(
        &self,
        ctx: &GpuContext,
        fragment: shaders::GlassEntry,
        proxied: bool,
    ) -> Result<Owned<vk::Pipeline>> {
        create_pipeline(
            ctx,
            (self.render_pass, self.blend),
            self.layout.raw(),
            (fragment, proxied),
        )
    }

    /// Records the update of the object's transform and the light's position to `pose`, for
    /// this and later draws: the copy waits for earlier draws' reads of the uniform block
    /// (also those of frames submitted before), and later draws wait for the copy.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass; `self` must outlive its execution.
    pub unsafe fn record_pose(&self, ctx: &GpuContext, cmd: vk::CommandBuffer, pose: &ScenePose) {
        let d = &ctx.device;
        let shaders =
            vk::PipelineStageFlags::VERTEX_SHADER | vk::PipelineStageFlags::FRAGMENT_SHADER;
        let barrier = |src, dst| {
            vk::BufferMemoryBarrier::default()
                .src_access_mask(src)
                .dst_access_mask(dst)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(self.globals_buffer.buffer)
                .offset(0)
                .size(vk::WHOLE_SIZE)
        };
        let globals = self.globals.posed(pose, &self.floor_light);
        // The fields a pose changes all come before the absorption; the rest stays as made.
        let posed = &bytemuck::bytes_of(&globals)[..std::mem::offset_of!(Globals, absorption)];
        // SAFETY: the caller's contract (outside a render pass; the buffer outlives the
        // execution); the data is a multiple of 4 bytes and under 65536, as
        // vkCmdUpdateBuffer requires, and the buffer was made with TRANSFER_DST.
        unsafe {
            d.cmd_pipeline_barrier(
                cmd,
                shaders,
                vk::PipelineStageFlags::TRANSFER,
                vk::DependencyFlags::empty(),
                &[],
                &[barrier(
                    vk::AccessFlags::UNIFORM_READ,
                    vk::AccessFlags::TRANSFER_WRITE,
                )],
                &[],
            );
            d.cmd_update_buffer(cmd, self.globals_buffer.buffer, 0, posed);
            ctx.work.upload(posed.len());
            d.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TRANSFER,
                shaders,
                vk::DependencyFlags::empty(),
                &[],
                &[barrier(
                    vk::AccessFlags::TRANSFER_WRITE,
                    vk::AccessFlags::UNIFORM_READ,
                )],
                &[],
            );
        }
    }

    /// The position in `pipelines` and `costs` of `variant`, compensated if asked and built.
    fn entry(&self, variant: GlassVariant, compensated: bool) -> usize {
        let compensated = compensated && self.compensation.is_some();
        usize::from(compensated) * GlassVariant::ALL.len() + variant.index()
    }

    /// The position in `covered_pipelines` and `covered_costs` of `variant`, compensated if
    /// asked and built; `None` where it has no covered pipeline (a look that does not reach
    /// the background, or a scene without the proof).
    fn covered_entry(&self, variant: GlassVariant, compensated: bool) -> Option<usize> {
        let compensated = compensated && self.compensation.is_some();
        (variant.background && !self.covered_pipelines.is_empty())
            .then(|| usize::from(compensated) * 2 + usize::from(variant.phong))
    }

    /// The static cost of one fragment drawn with the pipeline `pick` names (with `covered`,
    /// the one without the environment's lookup where the look has it).
    pub fn cost(&self, pick: Pick) -> ShaderCost {
        if let (Some(row), Some(_)) = (self.counted_row, self.counted_pipeline(pick)) {
            // What each pixel shades beyond one position of each part is counted on the device
            // (`GlassPass::read_positions`).
            let compensated = usize::from(pick.compensated && self.compensation.is_some());
            return shaders::GLASS_FS_COUNTED_COST[compensated][row]
                [usize::from(pick.variant.phong)];
        }
        if let (Some(row), Some(_)) = (self.mesh_row, self.counted_pipeline(pick)) {
            // The nodes and triangles each fragment's searches visit and test are counted on
            // the device (`GlassPass::read_mesh`).
            let compensated = usize::from(pick.compensated && self.compensation.is_some());
            return shaders::GLASS_FS_MESH_COUNTED_COST[compensated][row][pick.variant.index()];
        }
        match self
            .covered_entry(pick.variant, pick.compensated)
            .filter(|_| pick.covered)
        {
            Some(entry) => self.covered_costs[entry],
            None => self.costs[self.entry(pick.variant, pick.compensated)],
        }
    }
}

/// A glass pipeline drawing into `render_pass` with `blend` and `layout`: the vertex shader (a
/// ball's proxy's where `proxied`) and `fragment`.
fn create_pipeline(
    ctx: &GpuContext,
    (render_pass, blend): (vk::RenderPass, Blend),
    layout: vk::PipelineLayout,
    (fragment, proxied): (shaders::GlassEntry, bool),
) -> Result<Owned<vk::Pipeline>> {
    let f = 4;
    let attributes = [
        vk::VertexInputAttributeDescription {
            location: 0,
            binding: 0,
            format: vk::Format::R32G32B32_SFLOAT,
            offset: 0,
        },
        vk::VertexInputAttributeDescription {
            location: 1,
            binding: 0,
            format: vk::Format::R32G32B32_SFLOAT,
            offset: 3 * f,
        },
        vk::VertexInputAttributeDescription {
            location: 2,
            binding: 0,
            format: vk::Format::R32G32_SFLOAT,
            offset: 6 * f,
        },
    ];
    let bindings = [vk::VertexInputBindingDescription {
        binding: 0,
        stride: VERTEX_STRIDE,
        input_rate: vk::VertexInputRate::VERTEX,
    }];
    pipeline::create(
        ctx,
        &PipelineSpec {
            render_pass,
            layout,
            vertex: if proxied {
                (shaders::GLASS_VS_BALL_PROXY, c"vs_ball_proxy")
            } else {
                (shaders::GLASS_VS, c"vs_main")
            },
            fragment,
            bindings: &bindings,
            attributes: &attributes,
            cull: vk::CullModeFlags::BACK,
            depth: Depth::Nearest,
            blend,
        },
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::look::Defocus;

    #[test]
    fn each_variant_draws_with_the_entry_point_named_for_it() {
        for (position, variant) in GlassVariant::ALL.iter().enumerate() {
            assert_eq!(variant.index(), position);
            for (model, compensated) in
                (0..shaders::GLASS_FS[0].len()).flat_map(|m| [(m, 0), (m, 1)])
            {
                let prefix = if model % shaders::GLASS_MODELS == 0 {
                    "fs_paper_"
                } else {
                    "fs_two_surface_"
                };
                let name = shaders::GLASS_FS[compensated][model][position]
                    .1
                    .to_str()
                    .unwrap();
                let background = if variant.background {
                    "background"
                } else {
                    "environment"
                };
                let reflection = if variant.phong { "phong" } else { "fresnel" };
                assert_eq!(name, format!("{prefix}{background}_{reflection}"));
            }
        }
    }

    #[test]
    fn disparity_or_defocus_refracts_to_the_background_plane() {
        let baseline = Look::default();
        assert_eq!(GlassVariant::of(&baseline), GlassVariant::new(false, false));
        let disparity = Look {
            disparity: true,
            reflection: Reflection::Phong,
            ..Look::default()
        };
        assert_eq!(GlassVariant::of(&disparity), GlassVariant::new(true, true));
        let defocus = Look {
            defocus: Some(Defocus::default()),
            ..Look::default()
        };
        assert_eq!(GlassVariant::of(&defocus), GlassVariant::new(true, false));
    }
}
