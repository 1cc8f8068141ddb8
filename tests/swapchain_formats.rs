//! Swapchain images of each 8-bit colour format a runtime may offer (RGBA or BGRA, sRGB or
//! UNORM), on the machine's Vulkan device with validation on: a frame drawn into them is the
//! frame the renderer draws into its own images, both eyes, its light and its alpha.

use ash::vk;
use vitreous_render::{Composition, Image, Readback, Renderer, Want};
use vitreous_tests::{assert_silent, neutral_eyes, plain_params, scene_renderer, shipped_scene};

const FORMATS: [vk::Format; 4] = [
    vk::Format::R8G8B8A8_SRGB,
    vk::Format::B8G8R8A8_SRGB,
    vk::Format::R8G8B8A8_UNORM,
    vk::Format::B8G8R8A8_UNORM,
];

/// Draws one frame into `renderer`'s attached image `image` and returns its readback.
fn drawn(
    renderer: &mut Renderer,
    image: usize,
    params: &vitreous_render::FrameParams,
    composition: Composition,
) -> Readback {
    let want = Want {
        eyes: true,
        world: false,
    };
    let mut done: Vec<_> = renderer
        .submit_external(image, params, want, composition)
        .expect("drawn into the external image")
        .into_iter()
        .collect();
    done.extend(renderer.flush().expect("finished"));
    done.pop()
        .and_then(|f| f.readback)
        .expect("the frame was read back")
}

/// The largest difference between `a` and `b` in linear light (colour) and in alpha.
fn largest_difference(a: &[u8], b: &[u8]) -> (f32, u8) {
    let lin = vitreous_optics::srgb::to_linear;
    a.chunks_exact(4)
        .zip(b.chunks_exact(4))
        .fold((0.0f32, 0u8), |(c, al), (p, q)| {
            let colour = (0..3)
                .map(|i| (lin(p[i]) - lin(q[i])).abs())
                .fold(c, f32::max);
            (colour, al.max(p[3].abs_diff(q[3])))
        })
}

#[test]
fn every_eight_bit_swapchain_format_shows_the_frame_the_renderer_draws() {
    let scene = shipped_scene("glass-sphere-ml2.toml");
    let (w, h) = (160u32, 120u32);
    let mut renderer = scene_renderer(&scene, w, h);
    let eyes = neutral_eyes(&scene);
    let mut params = plain_params(eyes[0]);
    params.eyes = eyes;
    let extent = vk::Extent2D {
        width: w,
        height: h,
    };
    // The dimmer's light and panel (alpha), and the room's photos behind the glass (opaque).
    for composition in [Composition::AlphaBlend, Composition::Opaque] {
        let own = vitreous_tests::compose_once(
            &mut renderer,
            &params,
            Want {
                eyes: true,
                world: false,
            },
            composition,
        )
        .readback
        .expect("read back");
        let lit = own.eyes[0]
            .chunks_exact(4)
            .filter(|p| p[..3] != [0, 0, 0])
            .count();
        assert!(lit > 100, "{composition:?}: {lit} lit pixels");
        assert_ne!(own.eyes[0], own.eyes[1], "the eyes differ");
        for format in FORMATS {
            let usage = vk::ImageUsageFlags::COLOR_ATTACHMENT
                | vk::ImageUsageFlags::TRANSFER_SRC
                | vk::ImageUsageFlags::TRANSFER_DST;
            let images: Vec<Image> = (0..2)
                .map(|_| Image::new(renderer.context(), "swapchain", format, extent, 2, usage))
                .collect::<Result<_, _>>()
                .expect("images");
            let raw: Vec<vk::Image> = images.iter().map(|i| i.image).collect();
            // SAFETY: the images live on the renderer's device until after the detach below.
            unsafe { renderer.attach_external(&raw, format) }.expect("attached");
            for image in 0..2 {
                let got = drawn(&mut renderer, image, &params, composition);
                for eye in 0..2 {
                    let (colour, alpha) = largest_difference(&got.eyes[eye], &own.eyes[eye]);
                    // sRGB formats keep the frame's bytes; a UNORM one keeps its light to
                    // within half an 8-bit step (and the decoding's rounding).
                    let bound = if format == vk::Format::R8G8B8A8_SRGB
                        || format == vk::Format::B8G8R8A8_SRGB
                    {
                        1e-6
                    } else {
                        0.6 / 255.0 + 0.006
                    };
                    assert!(
                        colour <= bound && alpha == 0,
                        "{format:?}, {composition:?}, image {image}, eye {eye}: light {colour}, \
                         alpha {alpha} off"
                    );
                }
            }
            renderer.detach_external().expect("detached");
            drop(images);
        }
    }
    assert_silent(&renderer);
}
