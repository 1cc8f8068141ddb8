//! The end-to-end GPU tests, in one binary: each module is one subject (on lavapipe in CI,
//! Vulkan validation on in every test).

mod absorption;
mod caustics;
mod compensation;
mod cost;
mod coverage;
mod defocus;
mod dimmer;
mod glass_samples;
mod inducer;
mod live_caustics;
mod live_caustics_sweep;
mod live_maps;
mod mesh_light;
mod mesh_positions;
mod mesh_refraction;
mod motion;
mod refraction;
mod refraction_scene;
mod registration;
mod render_smoke;
mod replay;
mod room;
mod swapchain_formats;
