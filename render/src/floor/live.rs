//! Caustics computed on the GPU for each pose of the object and the light (docs/caustics.md,
//! eq. 6): photon splatting (shaders/caustics_live.wgsl), then a smoothing by a box filter run
//! three times along each axis (shaders/caustics_smooth.wgsl, planned by [`super::smoothing`]),
//! in compute passes into the caustic gain map the overlay adds, in place of a bake. Recorded with the inducer's fields, so only on frames after
//! a move; timed as the floor's `live caustics` stage ([`super::FieldPassesMs`]) and in
//! wall-clock time.

use ash::vk;
use glam::{Mat4, Vec3, Vec4};
use gpu_allocator::MemoryLocation;
use vitreous_optics::live_caustics::{LiveCausticsDesc, MAX_PHOTONS_PER_SIDE, MAX_SMOOTHING_PX};

use super::fields::{CAUSTIC_PHOTONS_STAMP, FIELD_STAMPS, Stamps};
use super::live_mesh::LiveMesh;
use super::smoothing::{
    FIXED_POINT, SHORT_KERNEL_PX, SmoothPass, SmoothTiles, TILE_PX, record_smoothing, row_pitch,
    shares_fit, smooth_steps,
};
use crate::context::GpuContext;
use crate::descriptors;
use crate::error::{RenderError, Result};
use crate::memory::{Buffer, Image, layout_barrier, subresource_range};
use crate::owned::Owned;
use crate::pipeline;
use crate::pose::ScenePose;
use crate::shaders;
use crate::work::PhotonWork;

/// An error naming the settings unless each is within its range.
pub(super) fn check(desc: &LiveCausticsDesc) -> Result<()> {
    let weight = desc.min_path_weight;
    if !(1..=MAX_PHOTONS_PER_SIDE).contains(&desc.photons_per_side)
        || desc.max_interactions == 0
        || desc.smoothing_px > MAX_SMOOTHING_PX
        || weight.is_nan()
        || weight <= 0.0
        || weight >= 1.0
    {
        return Err(RenderError::InvalidInput(format!(
            "live caustics need 1..={MAX_PHOTONS_PER_SIDE} photons per side, at least \
             one interaction, a smoothing of 0..={MAX_SMOOTHING_PX} texels and a least \
             path weight above 0 and below 1, got {}, {}, {} and {weight}",
            desc.photons_per_side, desc.max_interactions, desc.smoothing_px
        )));
    }
    Ok(())
}

/// Gains below this are stored as 0 (the bake's `MIN_GAIN`).
const MIN_GAIN: f32 = 0.001;

/// The slack on the shell's radii and on a ray's stretches inside it, relative to the mesh's
/// outer radius (f32 rounding of a ray from a light some 40 radii away is about 1e-5 of it).
const SHELL_SLACK: f32 = 1e-3;

/// Uniform block matching `Params` in shaders/shared/caustics_maps.wgsl.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Params {
    model_from_world: [f32; 16],
    world_from_model: [f32; 16],
    world_from_plane: [f32; 16],
    plane_from_world: [f32; 16],
    light: [f32; 4],
    axis: [f32; 4],
    basis_u: [f32; 4],
    basis_v: [f32; 4],
    grid_origin: [f32; 4],
    grid_dims: [u32; 4],
    map: [u32; 4],
    misc: [f32; 4],
    shell: [f32; 4],
    shell_outer: [f32; 4],
    tiles: [u32; 4],
    facets: [u32; 4],
}

/// The compute passes, their buffers and what they need of the mesh; freed on drop.
pub(crate) struct LiveCaustics {
    /// Photon tracing and splatting; the same counting its work (`COUNTED`).
    trace: Owned<vk::Pipeline>,
    trace_counted: Owned<vk::Pipeline>,
    /// What the counting trace counts: photons traced, deposits on the map.
    counts: Buffer,
    /// The smoothing's passes ([`SmoothPass`]; the first along the rows also clamps, the
    /// last zeroes small gains and bounds).
    smooth: [Owned<vk::Pipeline>; 4],
    /// Layout of both (one set; the smoothing step as push constant).
    layout: Owned<vk::PipelineLayout>,
    /// Pool of the set.
    _pool: Owned<vk::DescriptorPool>,
    /// Layout of the set.
    _set_layout: Owned<vk::DescriptorSetLayout>,
    /// The set: parameters, mesh, grid, sums, gain, bounds, row-smoothed gains.
    set: vk::DescriptorSet,
    /// `Params`, rewritten before each computation.
    params: Buffer,
    /// What the trace reads of the mesh.
    mesh: LiveMesh,
    /// Fixed-point sums per texel.
    sums: Buffer,
    /// The fixed-point map smoothed along the rows.
    _scratch: Buffer,
    /// The smoothing's cell masses and tile bits.
    tiles: SmoothTiles,
    /// The smoothed gain map, host-visible (for tests).
    gain: Buffer,
    /// The box of the non-zero gains (`[x0, y0, x1, y1]`, ends included; empty when
    /// x0 > x1): the overlay's buffer ([`super::overlay::OverlayPass::live_bounds`]), which
    /// its vertex stage reads on the frames that compute a map.
    bounds: vk::Buffer,
    /// Map width and height, texels.
    size: [u32; 2],
    /// Photons and path length.
    desc: LiveCausticsDesc,
    /// Floor unit square to world.
    world_from_plane: Mat4,
    /// Relative index of refraction.
    ior: f32,
}

impl LiveCaustics {
    /// Prepares the passes for `live_mesh` over a floor mapped by `world_from_plane`, writing
    /// a `size` gain map and the box of its non-zero texels into `bounds` (16 bytes, a storage
    /// buffer that outlives the passes); `desc` must pass [`check`].
    pub fn new(
        ctx: &GpuContext,
        live_mesh: LiveMesh,
        ior: f32,
        world_from_plane: Mat4,
        size: [u32; 2],
        desc: LiveCausticsDesc,
        bounds: vk::Buffer,
    ) -> Result<LiveCaustics> {
        debug_assert!(check(&desc).is_ok(), "{desc:?}");
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let texels = u64::from(row_pitch(size[0])) * u64::from(size[1]);
        let sums = Buffer::new(
            ctx,
            "caustics sums",
            texels * 4,
            storage | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let scratch = Buffer::new(
            ctx,
            "caustics smoothing",
            texels * 4,
            storage,
            MemoryLocation::GpuOnly,
        )?;
        let gain = Buffer::new(
            ctx,
            "caustics gain",
            texels * 4,
            storage | vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let tiles = SmoothTiles::new(ctx, size)?;
        let params = Buffer::new(
            ctx,
            "caustics parameters",
            size_of::<Params>() as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuOnly,
        )?;
        let counts = Buffer::new(
            ctx,
            "caustics photon counts",
            8,
            storage | vk::BufferUsageFlags::TRANSFER_DST | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        let compute = vk::ShaderStageFlags::COMPUTE;
        // The parameters in a storage buffer, not a uniform one: on lavapipe, which can inline
        // uniform values into a shader's loops and compile it again when they change, that
        // took about 1 ms off a moved frame's stage at the defaults and 6 ms with one photon.
        let bindings: Vec<_> = (0..=14)
            .map(|b| (b, vk::DescriptorType::STORAGE_BUFFER, compute))
            .collect();
        let set_layout = descriptors::set_layout(ctx, &bindings)?;
        // The smoothing step; the trace pass reads none.
        let layout = pipeline::layout(ctx, Some(set_layout.raw()), compute, 4)?;
        let trace = pipeline::compute(ctx, layout.raw(), shaders::CAUSTICS_TRACE_CS, c"cs_trace")?;
        let counted = shaders::CAUSTICS_TRACE_COUNTED_CS;
        let trace_counted = pipeline::compute(ctx, layout.raw(), counted, c"cs_trace")?;
        let smooth = SmoothPass::pipelines(ctx, layout.raw())?;
        let pool = descriptors::pool(ctx, 1, &[(vk::DescriptorType::STORAGE_BUFFER, 15)])?;
        let set = descriptors::allocate_set(ctx, pool.raw(), set_layout.raw())?;
        let mut buffers = vec![params.buffer];
        buffers.extend(live_mesh.buffers[..3].iter().map(|b| b.buffer));
        buffers.extend([sums.buffer, gain.buffer, bounds, scratch.buffer]);
        buffers.push(live_mesh.buffers[3].buffer);
        // The sums again, read four texels at a time by the smoothing.
        buffers.push(sums.buffer);
        // The cells' masses, then again four at a time.
        let [cell_mass, tile_bits] = tiles.buffers();
        buffers.extend([cell_mass, tile_bits, cell_mass]);
        buffers.push(live_mesh.facets.buffer);
        buffers.push(counts.buffer);
        let infos: Vec<[vk::DescriptorBufferInfo; 1]> = buffers
            .iter()
            .map(|&buffer| {
                [vk::DescriptorBufferInfo {
                    buffer,
                    offset: 0,
                    range: vk::WHOLE_SIZE,
                }]
            })
            .collect();
        let writes: Vec<_> = infos
            .iter()
            .enumerate()
            .map(|(binding, info)| {
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(binding as u32)
                    .descriptor_type(vk::DescriptorType::STORAGE_BUFFER)
                    .buffer_info(info)
            })
            .collect();
        // SAFETY: the set was just allocated and no GPU work uses it; the buffers are live.
        unsafe { ctx.device.update_descriptor_sets(&writes, &[]) };
        Ok(LiveCaustics {
            trace,
            trace_counted,
            counts,
            smooth,
            layout,
            _pool: pool,
            _set_layout: set_layout,
            set,
            params,
            mesh: live_mesh,
            sums,
            _scratch: scratch,
            tiles,
            gain,
            bounds,
            size,
            desc,
            world_from_plane,
            ior,
        })
    }

    /// The shader's parameters for `pose`.
    fn params(&self, pose: &ScenePose) -> Params {
        let m = pose.world_from_model;
        let mesh = &self.mesh;
        let center = m.transform_point3(mesh.center);
        let radius = mesh.radius * m.x_axis.truncate().length();
        let light = pose.light_position_m;
        let to_center = center - light;
        let dist = to_center.length();
        let axis = if dist > 0.0 {
            to_center / dist
        } else {
            Vec3::NEG_Y
        };
        let one_minus_cos = if dist <= radius {
            2.0
        } else {
            2.0 * (0.5 * (radius / dist).asin()).sin().powi(2)
        };
        let helper = if axis.x.abs() < 0.6 { Vec3::X } else { Vec3::Y };
        let u = helper.cross(axis).normalize();
        let v = axis.cross(u);
        let n = self.desc.photons_per_side;
        let solid_angle = 2.0 * std::f32::consts::PI * one_minus_cos / (n as f32 * n as f32);
        let floor_area = self
            .world_from_plane
            .x_axis
            .truncate()
            .cross(self.world_from_plane.y_axis.truncate())
            .length();
        let texel_area = floor_area / (self.size[0] as f32 * self.size[1] as f32);
        let [gx, gy, gz] = mesh.grid_dims;
        let [across, down, words] = self.tiles.layout();
        let skip_tiles = self.desc.skip_tiles
            && self.desc.smoothing_px <= SHORT_KERNEL_PX
            && shares_fit(
                self.world_from_plane,
                light,
                solid_angle * (n * n) as f32,
                texel_area,
                n,
                self.desc.min_path_weight,
            );
        // Rounding room for the shell's radii and the stretches of a ray inside it.
        let slack = mesh.radius * SHELL_SLACK;
        Params {
            model_from_world: m.inverse().to_cols_array(),
            world_from_model: m.to_cols_array(),
            world_from_plane: self.world_from_plane.to_cols_array(),
            plane_from_world: self.world_from_plane.inverse().to_cols_array(),
            light: light.extend(solid_angle).to_array(),
            axis: axis.extend(one_minus_cos).to_array(),
            basis_u: u.extend(self.ior).to_array(),
            basis_v: v.extend(texel_area).to_array(),
            grid_origin: mesh.grid_origin.extend(mesh.grid_side).to_array(),
            grid_dims: [gx, gy, gz, n],
            map: [
                self.size[0],
                self.size[1],
                self.desc.max_interactions,
                self.desc.smoothing_px,
            ],
            misc: Vec4::new(
                mesh.radius * 2e-5,
                FIXED_POINT,
                self.desc.min_path_weight,
                MIN_GAIN,
            )
            .to_array(),
            shell: mesh
                .center
                .extend((mesh.inner_radius - slack).max(0.0))
                .to_array(),
            shell_outer: [
                mesh.radius + slack,
                slack,
                if mesh.convex { 1.0 } else { 0.0 },
                if mesh.inner_ball_inside { 1.0 } else { 0.0 },
            ],
            tiles: [across, down, words, u32::from(skip_tiles)],
            facets: [mesh.facet_count, 0, 0, 0],
        }
    }

    /// Records the computation of the gain map for `pose` and its copy into `caustic` (an
    /// R32F image of the map's size in SHADER_READ_ONLY_OPTIMAL, left there), ordered after
    /// earlier work's reads of both and before later fragment reads of `caustic`. With
    /// `stamps`, writes the floor's two caustic stamps: after the photons, after the rest.
    ///
    /// # Safety
    /// `cmd` must be recording outside any render pass; `self` and `caustic` must outlive its
    /// execution; the stamps' pool must hold their queries, reset.
    pub unsafe fn record(
        &self,
        ctx: &GpuContext,
        cmd: vk::CommandBuffer,
        pose: &ScenePose,
        caustic: &Image,
        stamps: Option<Stamps>,
    ) {
        let d = &ctx.device;
        let params = self.params(pose);
        let memory = |src, dst| {
            [vk::MemoryBarrier::default()
                .src_access_mask(src)
                .dst_access_mask(dst)]
        };
        let image_barrier = |old, new, src, dst| {
            let range = subresource_range(vk::ImageAspectFlags::COLOR, 0, 1);
            [layout_barrier(caustic.image, range, (old, src), (new, dst))]
        };
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let groups = |n: u32| n.div_ceil(8);
        let vertex = vk::PipelineStageFlags::VERTEX_SHADER;
        // SAFETY: the caller's contract (outside a render pass, everything outlives the
        // execution); the barriers order every access to the parameters, the sums, the gain,
        // the bounds (read by earlier and later overlays' vertex stage) and the image against
        // earlier and later work on the queue; the image is moved from and back to the layout
        // it is in.
        unsafe {
            d.cmd_pipeline_barrier(
                cmd,
                compute | transfer | vertex | vk::PipelineStageFlags::HOST,
                transfer,
                vk::DependencyFlags::empty(),
                &memory(
                    vk::AccessFlags::SHADER_READ
                        | vk::AccessFlags::SHADER_WRITE
                        | vk::AccessFlags::TRANSFER_READ
                        | vk::AccessFlags::HOST_READ,
                    vk::AccessFlags::TRANSFER_WRITE,
                ),
                &[],
                &[],
            );
            d.cmd_update_buffer(cmd, self.params.buffer, 0, bytemuck::bytes_of(&params));
            d.cmd_fill_buffer(cmd, self.sums.buffer, 0, vk::WHOLE_SIZE, 0);
            let photons = stamps.and_then(|s| s.photons);
            if photons.is_some() {
                d.cmd_fill_buffer(cmd, self.counts.buffer, 0, vk::WHOLE_SIZE, 0);
            }
            let skipping = params.tiles[3] != 0;
            self.tiles.record_clear(d, cmd, skipping);
            if skipping {
                // The smoothing writes the live tiles only.
                d.cmd_fill_buffer(cmd, self.gain.buffer, 0, vk::WHOLE_SIZE, 0);
            }
            let empty: [u32; 4] = [u32::MAX, u32::MAX, 0, 0];
            d.cmd_update_buffer(cmd, self.bounds, 0, bytemuck::bytes_of(&empty));
            ctx.work
                .upload(std::mem::size_of_val(&params) + std::mem::size_of_val(&empty));
            d.cmd_pipeline_barrier(
                cmd,
                transfer,
                compute,
                vk::DependencyFlags::empty(),
                &memory(
                    vk::AccessFlags::TRANSFER_WRITE,
                    vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
                ),
                &[],
                &[],
            );
            let bind = vk::PipelineBindPoint::COMPUTE;
            d.cmd_bind_descriptor_sets(cmd, bind, self.layout.raw(), 0, &[self.set], &[]);
            let n = self.desc.photons_per_side;
            let trace = if photons.is_some() {
                &self.trace_counted
            } else {
                &self.trace
            };
            d.cmd_bind_pipeline(cmd, bind, trace.raw());
            d.cmd_dispatch(cmd, groups(n), groups(n), 1);
            ctx.work.dispatch(groups(n), groups(n), 1);
            if let Some(stamps) = stamps {
                stamps.write(d, cmd, CAUSTIC_PHOTONS_STAMP..CAUSTIC_PHOTONS_STAMP + 1);
            }
            record_smoothing(
                ctx,
                cmd,
                self.layout.raw(),
                &self.smooth,
                &smooth_steps(self.desc.smoothing_px, params.tiles[3] != 0),
                self.size,
            );
            d.cmd_pipeline_barrier(
                cmd,
                compute | vk::PipelineStageFlags::FRAGMENT_SHADER,
                transfer,
                vk::DependencyFlags::empty(),
                &memory(
                    vk::AccessFlags::SHADER_WRITE,
                    vk::AccessFlags::TRANSFER_READ,
                ),
                &[],
                &image_barrier(
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    vk::AccessFlags::SHADER_READ,
                    vk::AccessFlags::TRANSFER_WRITE,
                ),
            );
            if let Some(photons) = photons {
                let [_, tile_bits] = self.tiles.buffers();
                let copies = [
                    (self.counts.buffer, 0, 8),
                    (tile_bits, 8, self.tiles.bits_bytes()),
                ];
                for (src, dst_offset, size) in copies {
                    let region = vk::BufferCopy {
                        src_offset: 0,
                        dst_offset,
                        size,
                    };
                    d.cmd_copy_buffer(cmd, src, photons, &[region]);
                }
            }
            let region = crate::memory::color_copy_region(0, self.size[0], self.size[1], 1, 1)
                .buffer_row_length(row_pitch(self.size[0]));
            d.cmd_copy_buffer_to_image(
                cmd,
                self.gain.buffer,
                caustic.image,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &[region],
            );
            d.cmd_pipeline_barrier(
                cmd,
                transfer | compute,
                vertex | vk::PipelineStageFlags::FRAGMENT_SHADER | vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &memory(
                    vk::AccessFlags::SHADER_WRITE | vk::AccessFlags::TRANSFER_WRITE,
                    vk::AccessFlags::HOST_READ | vk::AccessFlags::SHADER_READ,
                ),
                &[],
                &image_barrier(
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
                    vk::AccessFlags::TRANSFER_WRITE,
                    vk::AccessFlags::SHADER_READ,
                ),
            );
            if let Some(stamps) = stamps {
                stamps.write(d, cmd, CAUSTIC_PHOTONS_STAMP + 1..FIELD_STAMPS);
            }
        }
    }

    /// The bytes a computation that counts its work copies into its frame's buffer
    /// ([`Stamps::photons`]): the two counts, then the smoothing's tile bits.
    pub fn photon_readback_bytes(&self) -> u64 {
        8 + self.tiles.bits_bytes()
    }

    /// What a computation counted, from the bytes it copied into its frame's buffer.
    pub fn photon_work(&self, bytes: &[u8]) -> PhotonWork {
        let word = |at: usize| {
            u32::from_le_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]])
        };
        let mut texels = 0u64;
        self.tiles.each_written(&bytes[8..], |x, row| {
            let along = |t: u32, size: u32| (size - (t * TILE_PX).min(size)).min(TILE_PX);
            texels += u64::from(along(x, self.size[0]) * along(row, self.size[1]));
        });
        PhotonWork {
            traced: u64::from(word(0)),
            splatted: u64::from(word(4)),
            smoothed_texels: texels,
        }
    }

    /// How many of the smoothing's tiles the last computation that finished wrote, and how
    /// many the map has (wait for the frame first).
    pub fn tiles_written(&self) -> Result<[u32; 2]> {
        self.tiles.written()
    }

    /// The gain map of the last computation that finished, row 0 at the photo's top (wait
    /// for the frame first).
    pub fn gain(&self) -> Result<Vec<f32>> {
        let [w, h] = self.size.map(|n| n as usize);
        let pitch = row_pitch(self.size[0]) as usize;
        let texels: Vec<f32> = self
            .gain
            .mapped()?
            .chunks_exact(4)
            .map(|b| f32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect();
        Ok(texels
            .chunks_exact(pitch)
            .take(h)
            .flat_map(|row| &row[..w])
            .copied()
            .collect())
    }
}
