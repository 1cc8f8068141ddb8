//! What the app submitted, read back (`VITREOUS_SIM_IMAGES`): each projection image the app
//! releases is copied from its swapchain on the app's own Vulkan device and queue (the
//! `XrGraphicsBindingVulkanKHR` it created the session with) before the runtime gets it, and
//! each view `xrEndFrame` submits is measured in its image rectangle: how many pixels carry
//! alpha, its mean and largest value and where they lie (`alpha.csv`). With a picture of the
//! real world (`VITREOUS_SIM_WORLD`), the session's last frame is written as the wearer would
//! see it (`wearer-left.png`, `wearer-right.png`): on `ALPHA_BLEND` the world dimmed by a
//! segmented dimmer panel ([`crate::config::SimPanel`]: each cell takes away the mean alpha
//! of its pixels, seen through a Gaussian blur) and the image's premultiplied light added; on
//! `ADDITIVE` the light added to the world; on `OPAQUE` the image alone.
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

use ash::vk::{self, Handle};
use openxr::sys;

use crate::config::SimPanel;

/// The header line of `alpha.csv`.
pub const HEADER: &str = "frame,view,width,height,blend,alpha_px,alpha_mean,alpha_max,alpha_box";

/// The Vulkan objects of a session, as the app gave them in `XrGraphicsBindingVulkanKHR`.
#[derive(Clone, Copy, Debug)]
pub struct VulkanBinding {
    /// `VkInstance`.
    pub instance: u64,
    /// `VkPhysicalDevice`.
    pub physical_device: u64,
    /// `VkDevice`.
    pub device: u64,
    /// The queue the app submits on.
    pub queue_family: u32,
    /// Its index in the family.
    pub queue_index: u32,
}

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

/// Copies swapchain images into host memory on the app's device and queue; its objects are
/// freed on drop.
pub struct Reader {
    device: ash::Device,
    queue: vk::Queue,
    memory_types: vk::PhysicalDeviceMemoryProperties,
    pool: vk::CommandPool,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    /// The host-visible buffer the copies go to, and its memory and size.
    staging: Option<(vk::Buffer, vk::DeviceMemory, u64)>,
    /// Keeps the Vulkan library loaded while the function pointers above are used.
    _entry: ash::Entry,
}

impl Reader {
    /// Makes the reader's command pool, command buffer and fence on `binding`'s device.
    ///
    /// # Safety
    /// `binding` must hold the live instance, physical device and device the app created the
    /// session with, the device made with a queue of that family and index.
    pub unsafe fn new(binding: &VulkanBinding) -> Result<Reader, String> {
        // SAFETY: loading the system's Vulkan loader, already loaded by the app.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| format!("loading Vulkan: {e}"))?;
        let instance_handle = vk::Instance::from_raw(binding.instance);
        // SAFETY: the caller's guarantee: a live instance of this loader.
        let instance = unsafe { ash::Instance::load(entry.static_fn(), instance_handle) };
        // SAFETY: a live device of that instance (caller's guarantee).
        let device =
            unsafe { ash::Device::load(instance.fp_v1_0(), vk::Device::from_raw(binding.device)) };
        let physical = vk::PhysicalDevice::from_raw(binding.physical_device);
        // SAFETY: the app's physical device of that instance.
        let memory_types = unsafe { instance.get_physical_device_memory_properties(physical) };
        // SAFETY: the device was created with this queue (caller's guarantee).
        let queue = unsafe { device.get_device_queue(binding.queue_family, binding.queue_index) };
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(binding.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: a valid create info on a live device.
        let pool = unsafe { device.create_command_pool(&pool_info, None) }
            .map_err(|e| format!("vkCreateCommandPool: {e}"))?;
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool just made; one buffer asked for.
        let cmd = match unsafe { device.allocate_command_buffers(&alloc) } {
            Ok(b) => b[0],
            Err(e) => {
                // SAFETY: the pool just made, unused.
                unsafe { device.destroy_command_pool(pool, None) };
                return Err(format!("vkAllocateCommandBuffers: {e}"));
            }
        };
        // SAFETY: a valid create info on a live device.
        let fence = match unsafe { device.create_fence(&vk::FenceCreateInfo::default(), None) } {
            Ok(f) => f,
            Err(e) => {
                // SAFETY: the pool just made, its buffer never submitted.
                unsafe { device.destroy_command_pool(pool, None) };
                return Err(format!("vkCreateFence: {e}"));
            }
        };
        Ok(Reader {
            device,
            queue,
            memory_types,
            pool,
            cmd,
            fence,
            staging: None,
            _entry: entry,
        })
    }

    /// A host-visible, coherent buffer of at least `size` bytes.
    fn staging(&mut self, size: u64) -> Result<(vk::Buffer, vk::DeviceMemory), String> {
        if let Some((buffer, memory, have)) = self.staging
            && have >= size
        {
            return Ok((buffer, memory));
        }
        self.free_staging();
        let d = &self.device;
        let info = vk::BufferCreateInfo::default()
            .size(size)
            .usage(vk::BufferUsageFlags::TRANSFER_DST)
            .sharing_mode(vk::SharingMode::EXCLUSIVE);
        // SAFETY: a valid create info on the live device.
        let buffer =
            unsafe { d.create_buffer(&info, None) }.map_err(|e| format!("vkCreateBuffer: {e}"))?;
        // SAFETY: the buffer just made.
        let needs = unsafe { d.get_buffer_memory_requirements(buffer) };
        let wanted = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let types = &self.memory_types;
        let Some(index) = (0..types.memory_type_count).find(|&i| {
            needs.memory_type_bits & (1 << i) != 0
                && types.memory_types[i as usize]
                    .property_flags
                    .contains(wanted)
        }) else {
            // SAFETY: the buffer just made, unbound.
            unsafe { d.destroy_buffer(buffer, None) };
            return Err("no host-visible coherent memory for the readback".into());
        };
        let alloc = vk::MemoryAllocateInfo::default()
            .allocation_size(needs.size)
            .memory_type_index(index);
        // SAFETY: a valid allocation on the live device.
        let memory = match unsafe { d.allocate_memory(&alloc, None) } {
            Ok(m) => m,
            Err(e) => {
                // SAFETY: the buffer just made, unbound.
                unsafe { d.destroy_buffer(buffer, None) };
                return Err(format!("vkAllocateMemory: {e}"));
            }
        };
        // SAFETY: the memory fits the buffer's requirements; neither is bound yet.
        if let Err(e) = unsafe { d.bind_buffer_memory(buffer, memory, 0) } {
            // SAFETY: both just made and unused.
            unsafe {
                d.destroy_buffer(buffer, None);
                d.free_memory(memory, None);
            }
            return Err(format!("vkBindBufferMemory: {e}"));
        }
        self.staging = Some((buffer, memory, size));
        Ok((buffer, memory))
    }

    fn free_staging(&mut self) {
        if let Some((buffer, memory, _)) = self.staging.take() {
            // SAFETY: every copy into it was waited for (`read` waits on its fence).
            unsafe {
                self.device.destroy_buffer(buffer, None);
                self.device.free_memory(memory, None);
            }
        }
    }

    /// Every array layer of `image` (`width` x `height`, 4 bytes a texel), row by row.
    ///
    /// # Safety
    /// `image` must be a live image of the app's device with `layers` array layers, made with
    /// transfer-source usage, in `COLOR_ATTACHMENT_OPTIMAL` (as the app releases it) with the
    /// commands writing it submitted to the binding's queue, which no other thread uses during
    /// the call.
    pub unsafe fn read(
        &mut self,
        image: vk::Image,
        width: u32,
        height: u32,
        layers: u32,
    ) -> Result<Vec<Vec<u8>>, String> {
        let layer_bytes = u64::from(width) * u64::from(height) * 4;
        let (buffer, memory) = self.staging(layer_bytes * u64::from(layers))?;
        let d = &self.device;
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::COLOR,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: layers,
        };
        let to_source = vk::ImageMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
            .dst_access_mask(vk::AccessFlags::TRANSFER_READ)
            .old_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .new_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image)
            .subresource_range(range);
        let back = vk::ImageMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::TRANSFER_READ)
            .dst_access_mask(
                vk::AccessFlags::COLOR_ATTACHMENT_READ | vk::AccessFlags::COLOR_ATTACHMENT_WRITE,
            )
            .old_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)
            .new_layout(vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(image)
            .subresource_range(range);
        let to_host = vk::BufferMemoryBarrier::default()
            .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
            .dst_access_mask(vk::AccessFlags::HOST_READ)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .buffer(buffer)
            .offset(0)
            .size(vk::WHOLE_SIZE);
        let regions: Vec<vk::BufferImageCopy> = (0..layers)
            .map(|layer| vk::BufferImageCopy {
                buffer_offset: layer_bytes * u64::from(layer),
                buffer_row_length: 0,
                buffer_image_height: 0,
                image_subresource: vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: layer,
                    layer_count: 1,
                },
                image_offset: vk::Offset3D::default(),
                image_extent: vk::Extent3D {
                    width,
                    height,
                    depth: 1,
                },
            })
            .collect();
        // SAFETY: the command buffer is not pending (every submission of it was waited for);
        // the image is as the caller guarantees, the buffer large enough for every region;
        // the queue is used by this thread alone during the call (caller's guarantee).
        unsafe {
            d.begin_command_buffer(
                self.cmd,
                &vk::CommandBufferBeginInfo::default()
                    .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
            )
            .map_err(|e| format!("vkBeginCommandBuffer: {e}"))?;
            d.cmd_pipeline_barrier(
                self.cmd,
                vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT,
                vk::PipelineStageFlags::TRANSFER,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[to_source],
            );
            d.cmd_copy_image_to_buffer(
                self.cmd,
                image,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                buffer,
                &regions,
            );
            d.cmd_pipeline_barrier(
                self.cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT | vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[],
                &[to_host],
                &[back],
            );
            d.end_command_buffer(self.cmd)
                .map_err(|e| format!("vkEndCommandBuffer: {e}"))?;
            let cmds = [self.cmd];
            let submit = vk::SubmitInfo::default().command_buffers(&cmds);
            d.queue_submit(self.queue, &[submit], self.fence)
                .map_err(|e| format!("vkQueueSubmit: {e}"))?;
            d.wait_for_fences(&[self.fence], true, u64::MAX)
                .map_err(|e| format!("vkWaitForFences: {e}"))?;
            d.reset_fences(&[self.fence])
                .map_err(|e| format!("vkResetFences: {e}"))?;
        }
        let total = usize::try_from(layer_bytes * u64::from(layers)).map_err(|e| e.to_string())?;
        // SAFETY: host-visible memory bound to the buffer, not mapped elsewhere; the copy into
        // it finished (fence) and was made visible to the host (barrier).
        let bytes = unsafe {
            let p = d
                .map_memory(memory, 0, vk::WHOLE_SIZE, vk::MemoryMapFlags::empty())
                .map_err(|e| format!("vkMapMemory: {e}"))?;
            let copied = std::slice::from_raw_parts(p as *const u8, total).to_vec();
            d.unmap_memory(memory);
            copied
        };
        Ok(bytes
            .chunks_exact(layer_bytes as usize)
            .map(<[u8]>::to_vec)
            .collect())
    }
}

impl Drop for Reader {
    fn drop(&mut self) {
        self.free_staging();
        // SAFETY: the command buffer's submissions were all waited for; the pool and fence are
        // the reader's own.
        unsafe {
            self.device.destroy_fence(self.fence, None);
            self.device.destroy_command_pool(self.pool, None);
        }
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
    fn linear(&self, x: usize, y: usize) -> ([f32; 3], f32) {
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

fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_to_srgb(v: f32) -> f32 {
    let v = v.clamp(0.0, 1.0);
    if v <= 0.003_130_8 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The share of the world's light the panel takes away at each pixel of a `view`-sized image:
/// each cell's mean alpha, blurred by a Gaussian of the panel's blur over the cells, read
/// between cell centres.
pub fn panel_darkening(view: &ViewImage, panel: &SimPanel) -> Vec<f32> {
    let (w, h) = (view.size.0 as usize, view.size.1 as usize);
    let [cx, cy] = panel.cells.map(|c| c as usize);
    let mut cells = vec![0f32; cx * cy];
    let mut counts = vec![0u32; cx * cy];
    for y in 0..h {
        for x in 0..w {
            let c = (y * cy / h) * cx + x * cx / w;
            cells[c] += view.linear(x, y).1;
            counts[c] += 1;
        }
    }
    for (v, n) in cells.iter_mut().zip(&counts) {
        *v /= (*n).max(1) as f32;
    }
    // The blur in cells, across and down.
    let sigma = [0, 1].map(|a| panel.blur_deg * panel.cells[a] as f32 / view.fov_deg[a].max(1e-3));
    let blur = |values: &[f32], along_x: bool| -> Vec<f32> {
        let (n_along, n_other, s) = if along_x {
            (cx, cy, sigma[0])
        } else {
            (cy, cx, sigma[1])
        };
        if s < 1e-3 {
            return values.to_vec();
        }
        let reach = (3.0 * s).ceil() as isize;
        let weights: Vec<f32> = (-reach..=reach)
            .map(|k| (-(k as f32).powi(2) / (2.0 * s * s)).exp())
            .collect();
        let mut out = vec![0f32; values.len()];
        for o in 0..n_other {
            for i in 0..n_along {
                let (mut sum, mut total) = (0f32, 0f32);
                for (k, wgt) in (-reach..=reach).zip(&weights) {
                    let j = i as isize + k;
                    if j < 0 || j >= n_along as isize {
                        continue;
                    }
                    let idx = if along_x {
                        o * cx + j as usize
                    } else {
                        j as usize * cx + o
                    };
                    sum += values[idx] * wgt;
                    total += wgt;
                }
                let idx = if along_x { o * cx + i } else { i * cx + o };
                out[idx] = sum / total;
            }
        }
        out
    };
    let cells = blur(&blur(&cells, true), false);
    let at = |x: isize, y: isize| {
        cells[y.clamp(0, cy as isize - 1) as usize * cx + x.clamp(0, cx as isize - 1) as usize]
    };
    let mut out = Vec::with_capacity(w * h);
    for y in 0..h {
        let fy = (y as f32 + 0.5) * cy as f32 / h as f32 - 0.5;
        let (y0, ty) = (fy.floor() as isize, fy - fy.floor());
        for x in 0..w {
            let fx = (x as f32 + 0.5) * cx as f32 / w as f32 - 0.5;
            let (x0, tx) = (fx.floor() as isize, fx - fx.floor());
            let top = at(x0, y0) * (1.0 - tx) + at(x0 + 1, y0) * tx;
            let bottom = at(x0, y0 + 1) * (1.0 - tx) + at(x0 + 1, y0 + 1) * tx;
            out.push(top * (1.0 - ty) + bottom * ty);
        }
    }
    out
}

/// What the wearer sees of `view` over `world` (8-bit sRGB RGB, any size, scaled to the
/// view's): 8-bit sRGB RGB of the view's size.
pub fn wearer_view(
    view: &ViewImage,
    blend: sys::EnvironmentBlendMode,
    world: &image::RgbImage,
    panel: &SimPanel,
) -> Vec<u8> {
    let (w, h) = (view.size.0 as usize, view.size.1 as usize);
    let darkening =
        (blend == sys::EnvironmentBlendMode::ALPHA_BLEND).then(|| panel_darkening(view, panel));
    let keeps_world = blend != sys::EnvironmentBlendMode::OPAQUE;
    let (ww, wh) = world.dimensions();
    let mut out = Vec::with_capacity(w * h * 3);
    for y in 0..h {
        for x in 0..w {
            let (light, _) = view.linear(x, y);
            let seen = if keeps_world {
                let p = world.get_pixel(
                    ((x * ww as usize) / w) as u32,
                    ((y * wh as usize) / h) as u32,
                );
                let kept = darkening.as_ref().map_or(1.0, |d| 1.0 - d[y * w + x]);
                p.0.map(|v| srgb_to_linear(f32::from(v) / 255.0) * kept)
            } else {
                [0.0; 3]
            };
            for c in 0..3 {
                out.push((linear_to_srgb(seen[c] + light[c]) * 255.0 + 0.5) as u8);
            }
        }
    }
    out
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

/// Writes each of the last frame's views as the wearer sees it over `world` into `dir`
/// (`wearer-left.png`, `wearer-right.png`, then `wearer-view2.png`, ...), each whole or not at
/// all.
pub fn write_wearer_views(
    dir: &Path,
    world: &Path,
    views: &[ViewImage],
    blend: sys::EnvironmentBlendMode,
    panel: &SimPanel,
) -> Result<Vec<PathBuf>, String> {
    let world = image::open(world)
        .map_err(|e| format!("reading the world picture {}: {e}", world.display()))?
        .to_rgb8();
    let mut written = Vec::new();
    for (i, view) in views.iter().enumerate() {
        let name = match i {
            0 => "wearer-left.png".to_owned(),
            1 => "wearer-right.png".to_owned(),
            n => format!("wearer-view{n}.png"),
        };
        let rgb = wearer_view(view, blend, &world, panel);
        let picture = image::RgbImage::from_raw(view.size.0, view.size.1, rgb)
            .ok_or("a wearer's view of the wrong size")?;
        let mut png = Vec::new();
        picture
            .write_to(&mut io::Cursor::new(&mut png), image::ImageFormat::Png)
            .map_err(|e| format!("encoding {name}: {e}"))?;
        let path = dir.join(&name);
        vitreous_xr::atomic_file::write(&path, &png)
            .map_err(|e| format!("writing {}: {e}", path.display()))?;
        written.push(path);
    }
    Ok(written)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(alpha: impl Fn(u32, u32) -> u8, light: u8) -> ViewImage {
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

    #[test]
    fn alpha_statistics_count_bound_and_average_the_alpha() {
        let v = view(
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
        assert_eq!(view(|_, _| 0, 9).alpha().bounds, None);
    }

    #[test]
    fn a_sharp_panel_takes_away_each_cells_mean_alpha() {
        // One alpha-1 pixel per 2 x 2 cell of a 32 x 24 panel: every cell a quarter.
        let v = view(|x, y| if x % 2 == 0 && y % 2 == 0 { 255 } else { 0 }, 0);
        let sharp = SimPanel {
            cells: [32, 24],
            blur_deg: 0.0,
        };
        for d in panel_darkening(&v, &sharp) {
            assert!((d - 0.25).abs() < 1e-6, "{d}");
        }
    }

    #[test]
    fn a_blurred_panel_spreads_the_darkening_and_keeps_its_total() {
        let v = view(|x, y| if x == 32 && y == 24 { 255 } else { 0 }, 0);
        let sharp = SimPanel {
            cells: [64, 48],
            blur_deg: 0.0,
        };
        let soft = SimPanel {
            cells: [64, 48],
            blur_deg: 2.0,
        };
        let (a, b) = (panel_darkening(&v, &sharp), panel_darkening(&v, &soft));
        let (sa, sb): (f32, f32) = (a.iter().sum(), b.iter().sum());
        assert!(
            (sa - 1.0).abs() < 1e-4 && (sb - 1.0).abs() < 0.02,
            "{sa} {sb}"
        );
        // Spread: a neighbour 3 cells away gets some, less than the centre.
        let at = |d: &[f32], x: usize, y: usize| d[y * 64 + x];
        assert_eq!(at(&a, 35, 24), 0.0);
        assert!(at(&b, 35, 24) > 0.0 && at(&b, 35, 24) < at(&b, 32, 24));
    }

    #[test]
    fn the_wearer_sees_the_world_dimmed_where_the_alpha_asks_and_the_light_added() {
        let world = image::RgbImage::from_pixel(8, 8, image::Rgb([188, 188, 188]));
        let sharp = SimPanel {
            cells: [64, 48],
            blur_deg: 0.0,
        };
        // Half the pixels alpha 1 with no light: black there on ALPHA_BLEND; the world
        // elsewhere; the world plus the light on ADDITIVE.
        let v = view(|x, _| if x < 32 { 255 } else { 0 }, 0);
        let seen = wearer_view(&v, sys::EnvironmentBlendMode::ALPHA_BLEND, &world, &sharp);
        assert_eq!(seen[0], 0);
        assert_eq!(seen[(10 * 64 + 40) * 3], 188);
        let lit = view(|_, _| 0, 64);
        let added = wearer_view(&lit, sys::EnvironmentBlendMode::ADDITIVE, &world, &sharp);
        assert!(added[0] > 188);
        // The image alone: linear 64/255 is sRGB 137.
        let opaque = wearer_view(&lit, sys::EnvironmentBlendMode::OPAQUE, &world, &sharp);
        assert_eq!(opaque[0], 137);
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
