//! Gap study: where the physical reference's light through a glass object comes from, and how
//! much of it the GPU's two-surface tracer follows.
//!
//! `cargo run -p vitreous-compare --example gap_study -- SCENE.toml REPLAY_DIR [GPU_T.png]`
//!
//! REPLAY_DIR is a `replay --compare-reference` output of SCENE (frame 0, left eye). For the
//! left eye's pixels inside the object's disc it traces the reference with its light split by
//! order (how many times a path took the branch the GPU's main path does not take) and by what
//! the path ends on, and an emulation of the GPU's algorithm (main path, front reflection to the
//! room, first-order branches followed without splitting), then measures each variant as if
//! the display showed it (eq. 6: seen + max(T - seen, 0)) with ꟻLIP against the reference.

use std::path::Path;

use glam::{Vec2, Vec3};
use vitreous_compare::{Labels, Region, frame_of_image, scene_pixels_per_degree};
use vitreous_optics::optics::{fresnel_reflectance, reflect, refract};
use vitreous_optics::two_surface::Body;
use vitreous_reference::world::{Glass, PhotoHit, World};
use vitreous_reference::{FloorLight, PhotonParams};

const EPS_M: f32 = 1e-6;
const ORDERS: usize = 4; // 0, 1, 2, 3+
const ENDS: usize = 4; // floor, wall, environment, nothing (cut)

#[derive(Clone, Copy)]
struct Knobs {
    max_interfaces: u32,
    min_weight: f32,
}

/// Light binned by order and end.
#[derive(Clone, Copy, Default)]
struct Bins([[Vec3; ENDS]; ORDERS]);

impl Bins {
    fn total(&self) -> Vec3 {
        self.0.iter().flatten().copied().sum()
    }
    fn order_le(&self, k: usize) -> Vec3 {
        self.0[..=k].iter().flatten().copied().sum()
    }
    fn scale(&mut self, s: f32) {
        for row in &mut self.0 {
            for v in row {
                *v *= s;
            }
        }
    }
}

struct Tracer<'a> {
    world: &'a World,
    knobs: Knobs,
    /// Interface count at which the deepest path was cut (statistics).
    cut_weight: std::cell::Cell<f32>,
}

impl Tracer<'_> {
    fn glass(&self) -> &Glass {
        self.world.glass.as_ref().unwrap()
    }

    /// Room lookup (no glass): the photo met first, else the environment.
    fn room(&self, origin: Vec3, dir: Vec3, left_glass: bool) -> (Vec3, usize) {
        match self.world.photo_hit(origin, dir) {
            Some((_, PhotoHit::Floor(uv))) => (self.world.floor_radiance(uv), 0),
            Some((_, PhotoHit::Background(uv))) => (
                self.world
                    .background
                    .as_ref()
                    .map_or(Vec3::ZERO, |b| b.radiance(uv)),
                1,
            ),
            None if left_glass => (self.world.environment_radiance(dir), 2),
            None => (Vec3::ZERO, 3),
        }
    }

    // The reference, with throughput carried down and the order of the path counted: the
    // main branch is the transmitted one (the reflected one at total internal reflection).
    fn outside(
        &self,
        bins: &mut Bins,
        origin: Vec3,
        dir: Vec3,
        thr: Vec3,
        weight: f32,
        interfaces: u32,
        order: usize,
        left_glass: bool,
    ) {
        let photo = self.world.photo_hit(origin, dir);
        if let Some((t, normal)) = self.glass().shape.enter(origin, dir)
            && photo.is_none_or(|(t_photo, _)| t < t_photo)
        {
            if interfaces < self.knobs.max_interfaces && weight >= self.knobs.min_weight {
                self.enter(bins, origin + dir * t, dir, normal, thr, weight, interfaces, order);
            } else {
                self.cut_weight.set(self.cut_weight.get() + weight);
                // cut: nothing
            }
            return;
        }
        let (l, end) = self.room(origin, dir, left_glass);
        bins.0[order.min(ORDERS - 1)][end] += thr * l;
    }

    #[allow(clippy::too_many_arguments)]
    fn enter(
        &self,
        bins: &mut Bins,
        at: Vec3,
        dir: Vec3,
        normal: Vec3,
        thr: Vec3,
        weight: f32,
        interfaces: u32,
        order: usize,
    ) {
        let ior = self.glass().ior;
        let facing = if dir.dot(normal) < 0.0 { normal } else { -normal };
        let f = fresnel_reflectance(-dir.dot(facing), 1.0 / ior);
        let inward = refract(dir, facing, 1.0 / ior);
        // Reflection: a split (order + 1) unless nothing is transmitted.
        let r_order = if inward.is_some() { order + 1 } else { order };
        self.outside(
            bins,
            at + facing * EPS_M,
            reflect(dir, facing),
            thr * f,
            weight * f,
            interfaces + 1,
            r_order,
            true,
        );
        if let Some(inward) = inward {
            self.inside(
                bins,
                at - facing * EPS_M,
                inward,
                thr * (1.0 - f),
                weight * (1.0 - f),
                interfaces + 1,
                order,
            );
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn inside(
        &self,
        bins: &mut Bins,
        origin: Vec3,
        dir: Vec3,
        thr: Vec3,
        weight: f32,
        interfaces: u32,
        order: usize,
    ) {
        if interfaces >= self.knobs.max_interfaces || weight < self.knobs.min_weight {
            self.cut_weight.set(self.cut_weight.get() + weight);
            return;
        }
        let glass = self.glass();
        let Some((t, normal)) = glass.shape.leave(origin, dir) else {
            self.cut_weight.set(self.cut_weight.get() + weight);
            return;
        };
        let absorbed = glass.attenuation.transmittance(t);
        let at = origin + dir * t;
        let facing = if dir.dot(normal) > 0.0 { -normal } else { normal };
        let f = fresnel_reflectance(-dir.dot(facing), glass.ior);
        let weight = weight * absorbed.max_element();
        let thr = thr * absorbed;
        let outward = refract(dir, facing, glass.ior);
        if let Some(outward) = outward {
            self.outside(
                bins,
                at - facing * EPS_M,
                outward,
                thr * (1.0 - f),
                weight * (1.0 - f),
                interfaces + 1,
                order,
                true,
            );
        }
        let b_order = if outward.is_some() { order + 1 } else { order };
        self.inside(
            bins,
            at + facing * EPS_M,
            reflect(dir, facing),
            thr * f,
            weight * f,
            interfaces + 1,
            b_order,
        );
    }

    // ---- Emulation of the GPU (shaders/glass.wgsl two_surface, mesh path, ROOM) ----

    /// `to_the_outside`: (position, direction, transmission, escaped, arriving, reflectance,
    /// echo direction, lost).
    fn to_the_outside(&self, s: &mut GpuState) {
        let n = std::env::var("MESH_TIR").ok().and_then(|s| s.parse().ok()).unwrap_or(8);
        self.to_the_outside_n(s, n);
    }

    fn to_the_outside_n(&self, s: &mut GpuState, max_tir: u32) {
        let glass = self.glass();
        for _bounce in 0..=max_tir {
            let Some((t, normal)) = glass.shape.leave(s.p, s.d) else {
                s.transmission = 0.0;
                s.arriving = 0.0;
                s.escaped = true;
                s.lost = true;
                return;
            };
            s.p += s.d * t;
            let outward = if s.d.dot(normal) >= 0.0 { normal } else { -normal };
            if let Some(leaving) = refract(s.d, -outward, glass.ior) {
                s.arriving = s.transmission;
                s.reflectance = fresnel_reflectance(s.d.dot(outward), glass.ior);
                s.echo_d = reflect(s.d, outward);
                s.transmission *= 1.0 - s.reflectance;
                s.d = leaving;
                s.escaped = true;
                s.n_out = outward;
                return;
            }
            s.d = reflect(s.d, outward);
            s.p -= outward * EPS_M;
        }
        s.gave_up = true;
    }

    /// `follow`.
    fn follow(&self, start: Vec3, dir: Vec3, from_inside: bool, meetings: u32) -> Vec3 {
        let glass = self.glass();
        let (mut p, mut d, mut inside, mut passed) = (start, dir, from_inside, 1.0f32);
        for _ in 0..meetings {
            if inside {
                let Some((t, normal)) = glass.shape.leave(p, d) else {
                    return Vec3::ZERO;
                };
                p += d * t;
                let outward = if d.dot(normal) >= 0.0 { normal } else { -normal };
                if let Some(leaving) = refract(d, -outward, glass.ior) {
                    passed *= 1.0 - fresnel_reflectance(d.dot(outward), glass.ior);
                    d = leaving;
                    p += outward * EPS_M;
                    inside = false;
                } else {
                    d = reflect(d, outward);
                    p -= outward * EPS_M;
                }
            } else {
                let Some((t, normal)) = glass.shape.enter(p, d) else {
                    break;
                };
                // The GPU's `follow` does not check whether a photo is nearer.
                p += d * t;
                let facing = if d.dot(normal) < 0.0 { normal } else { -normal };
                passed *= 1.0 - fresnel_reflectance(-d.dot(facing), 1.0 / glass.ior);
                d = refract(d, facing, 1.0 / glass.ior).unwrap();
                p -= facing * EPS_M;
                inside = true;
            }
        }
        if inside {
            return Vec3::ZERO;
        }
        self.room(p, d, true).0 * passed
    }

    /// The GPU's light for a view ray that meets the glass at `at` (normal facing the eye):
    /// (front reflection, main path, branches, lost share, given-up share).
    fn gpu(&self, at: Vec3, dir: Vec3, normal: Vec3, branch_meetings: u32, max_entries: u32) -> [Vec3; 3] {
        let glass = self.glass();
        let ior = glass.ior;
        let facing = if dir.dot(normal) < 0.0 { normal } else { -normal };
        let f0 = fresnel_reflectance(-dir.dot(facing), 1.0 / ior);
        let front = if std::env::var("FRONT_FOLLOW").is_ok() {
            self.follow(at + facing * EPS_M, reflect(dir, facing), false, branch_meetings) * f0
        } else {
            self.room(at + facing * EPS_M, reflect(dir, facing), true).0 * f0
        };
        let Some(inward) = refract(dir, facing, 1.0 / ior) else {
            return [front, Vec3::ZERO, Vec3::ZERO];
        };
        let mut s = GpuState {
            p: at - facing * EPS_M,
            d: inward,
            transmission: 1.0 - f0,
            escaped: false,
            arriving: 0.0,
            reflectance: 0.0,
            echo_d: inward,
            lost: false,
            gave_up: false,
            n_out: Vec3::ZERO,
        };
        self.to_the_outside(&mut s);
        let mut echoes = Vec3::ZERO;
        for entries in 1..=max_entries {
            if !s.escaped || s.lost {
                break;
            }
            // Echo: what the exit reflects back inside. s.p is on the surface; the outward
            // side is along s.d (leaving): step back inside.
            echoes += self.follow(s.p - s.n_out * EPS_M, s.echo_d, true, branch_meetings)
                * (s.arriving * s.reflectance);
            if entries == max_entries {
                break;
            }
            let from = s.p + s.n_out * EPS_M;
            let Some((t, normal)) = glass.shape.enter(from, s.d) else {
                break;
            };
            s.p = from + s.d * t;
            let facing = if s.d.dot(normal) < 0.0 { normal } else { -normal };
            let reflects = fresnel_reflectance(-s.d.dot(facing), 1.0 / ior);
            echoes += self.follow(s.p + facing * EPS_M, reflect(s.d, facing), false, branch_meetings)
                * (s.transmission * reflects);
            s.transmission *= 1.0 - reflects;
            s.d = refract(s.d, facing, 1.0 / ior).unwrap();
            s.p -= facing * EPS_M;
            s.escaped = false;
            self.to_the_outside(&mut s);
        }
        let main = if s.lost {
            Vec3::ZERO
        } else if s.escaped {
            let from = s.p + s.n_out * EPS_M;
            self.room(from, s.d, true).0 * s.transmission
        } else if std::env::var("GIVEUP_ZERO").is_ok() {
            Vec3::ZERO
        } else {
            // Given up inside: the environment along the last direction.
            self.world.environment_radiance(s.d) * s.transmission
        };
        [front, main, echoes]
    }
}

impl Tracer<'_> {
    /// The GPU's convex path (`two_surface` with CONVEX: front reflection, main path with
    /// `max_tir` total internal reflections, then `echoes_of` with `echoes` meetings).
    fn gpu_convex(&self, at: Vec3, dir: Vec3, normal: Vec3, echoes: u32, max_tir: u32) -> Vec3 {
        let glass = self.glass();
        let ior = glass.ior;
        let facing = if dir.dot(normal) < 0.0 { normal } else { -normal };
        let f0 = fresnel_reflectance(-dir.dot(facing), 1.0 / ior);
        let front = self.room(at + facing * EPS_M, reflect(dir, facing), true).0 * f0;
        let Some(inward) = refract(dir, facing, 1.0 / ior) else {
            return front;
        };
        let mut s = GpuState {
            p: at - facing * EPS_M,
            d: inward,
            transmission: 1.0 - f0,
            escaped: false,
            arriving: 0.0,
            reflectance: 0.0,
            echo_d: inward,
            lost: false,
            gave_up: false,
            n_out: Vec3::ZERO,
        };
        self.to_the_outside_n(&mut s, max_tir);
        if s.lost {
            return front;
        }
        if !s.escaped {
            return front + self.world.environment_radiance(s.d) * s.transmission;
        }
        let main = self.room(s.p + s.n_out * EPS_M, s.d, true).0 * s.transmission;
        let mut light = Vec3::ZERO;
        let mut q = s.p - s.n_out * EPS_M;
        let mut e = s.echo_d;
        let mut carried = s.arriving * s.reflectance;
        for _ in 0..echoes {
            let Some((t, normal)) = glass.shape.leave(q, e) else {
                break;
            };
            q += e * t;
            let outward = if e.dot(normal) >= 0.0 { normal } else { -normal };
            if let Some(leaving) = refract(e, -outward, ior) {
                let r = fresnel_reflectance(e.dot(outward), ior);
                light += self.room(q + outward * EPS_M, leaving, true).0 * (carried * (1.0 - r));
                carried *= r;
            }
            e = reflect(e, outward);
            q -= outward * EPS_M;
        }
        front + main + light
    }
}

struct GpuState {
    p: Vec3,
    d: Vec3,
    transmission: f32,
    escaped: bool,
    arriving: f32,
    reflectance: f32,
    echo_d: Vec3,
    lost: bool,
    gave_up: bool,
    n_out: Vec3,
}

fn srgb8(v: f32) -> u8 {
    vitreous_optics::srgb::from_linear(v)
}
fn lin8(v: u8) -> f32 {
    vitreous_optics::srgb::to_linear(v)
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let scene = vitreous_scene::load_scene(Path::new(&args[1]))?;
    let dir = Path::new(&args[2]).join("frames");
    let real_path = dir.join("000000-left-real.png");
    let listed = frame_of_image(&real_path)?.expect("reference.json lists the frame");
    let camera = listed.frame.eyes[0].camera();
    let placement = listed.frame.placement();
    let read = |p: &Path| -> anyhow::Result<(u32, u32, Vec<u8>)> {
        let img = image::open(p)?.to_rgb8();
        Ok((img.width(), img.height(), img.into_raw()))
    };
    let (w, h, mut real8) = read(&real_path)?;
    let (_, _, seen8) = read(&dir.join("000000-left-seen.png"))?;
    // What the eye sees with the GPU's display light (eq. 6 over the seen image, additive).
    let (_, _, left8) = read(&dir.join("000000-left.png"))?;
    let preview8: Vec<u8> = left8
        .iter()
        .zip(&seen8)
        .map(|(&l, &s)| srgb8(lin8(l) + lin8(s)))
        .collect();
    let gpu_t = args.get(3).map(|p| read(Path::new(p))).transpose()?;
    let samples: u32 = std::env::var("SAMPLES").ok().and_then(|s| s.parse().ok()).unwrap_or(3);

    let world0 = World::of(&scene, &placement)?;
    let t0 = std::time::Instant::now();
    let floor_light = FloorLight::trace(&world0, &PhotonParams::default());
    eprintln!("floor light traced in {:.1}s", t0.elapsed().as_secs_f32());
    let world_mod = World { floor_light, ..world0.clone() };
    let world_photo = World { floor_light: None, ..world0 };

    let labels = Labels::of(&scene, &camera, &placement, w, h);
    let disc: Vec<usize> = (0..(w * h) as usize)
        .filter(|&i| labels.regions[i] == Region::Disc)
        .collect();
    let rays = camera.pixel_rays(Vec2::new(w as f32, h as f32));
    let full = Knobs { max_interfaces: 16, min_weight: 1e-4 };
    let deep = Knobs { max_interfaces: 64, min_weight: 1e-6 };
    let me: u32 = std::env::var("MAX_ENTRIES").ok().and_then(|s| s.parse().ok()).unwrap_or(4);
    let bm: u32 = std::env::var("BRANCH_MEETINGS").ok().and_then(|s| s.parse().ok()).unwrap_or(6);

    // Per disc pixel: [ref full mod bins], [ref photo bins], [ref deep bins], gpu emu parts,
    // glass coverage, height of first hit.
    struct Px {
        full: Bins,
        photo: Bins,
        deep: Bins,
        gpu: [Vec3; 3],
        gpu_photo: [Vec3; 3],
        cover: f32,
        y: f32,
        cut: f32,
    }
    let work = |idx: &[usize]| -> Vec<Px> {
        let tm = Tracer { world: &world_mod, knobs: full, cut_weight: 0.0.into() };
        let tp = Tracer { world: &world_photo, knobs: full, cut_weight: 0.0.into() };
        let td = Tracer { world: &world_mod, knobs: deep, cut_weight: 0.0.into() };
        idx.iter()
            .map(|&i| {
                let (x, y) = ((i as u32 % w) as f32, (i as u32 / w) as f32);
                let n = samples;
                let mut px = Px {
                    full: Bins::default(),
                    photo: Bins::default(),
                    deep: Bins::default(),
                    gpu: [Vec3::ZERO; 3],
                    gpu_photo: [Vec3::ZERO; 3],
                    cover: 0.0,
                    y: f32::NAN,
                    cut: 0.0,
                };
                for j in 0..n {
                    for k in 0..n {
                        let off = Vec2::new((k as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                        let d = rays.direction(Vec2::new(x, y) + off);
                        let o = camera.position_m;
                        tm.outside(&mut px.full, o, d, Vec3::ONE, 1.0, 0, 0, false);
                        tp.outside(&mut px.photo, o, d, Vec3::ONE, 1.0, 0, 0, false);
                        td.outside(&mut px.deep, o, d, Vec3::ONE, 1.0, 0, 0, false);
                        let glass = world_mod.glass.as_ref().unwrap();
                        let photo = world_mod.photo_hit(o, d);
                        if let Some((t, normal)) = glass.shape.enter(o, d)
                            && photo.is_none_or(|(tp, _)| t < tp)
                        {
                            let at = o + d * t;
                            px.cover += 1.0;
                            if px.y.is_nan() {
                                px.y = at.y;
                            }
                            let g = tm.gpu(at, d, normal, bm, me);
                            let gp = tp.gpu(at, d, normal, bm, me);
                            for q in 0..3 {
                                px.gpu[q] += g[q];
                                px.gpu_photo[q] += gp[q];
                            }
                        } else {
                            // Not on the glass: the room as the GPU's frame shows it (seen).
                            let (l, _) = tm.room(o, d, false);
                            px.gpu[2] += l;
                            px.gpu_photo[2] += tp.room(o, d, false).0;
                        }
                    }
                }
                let s = 1.0 / (n * n) as f32;
                px.full.scale(s);
                px.photo.scale(s);
                px.deep.scale(s);
                for q in 0..3 {
                    px.gpu[q] *= s;
                    px.gpu_photo[q] *= s;
                }
                px.cover *= s;
                px.cut = tm.cut_weight.replace(0.0) * s;
                px
            })
            .collect()
    };
    // REF_SAMPLES: the reference over the disc traced again with that many positions along
    // each side of a pixel (a converged reference), everything measured against it.
    if let Some(nr) = std::env::var("REF_SAMPLES").ok().and_then(|s| s.parse::<u32>().ok()) {
        let t0 = std::time::Instant::now();
        let trace = |idx: &[usize]| -> Vec<Vec3> {
            let knobs = if std::env::var("REF_DEEP").is_ok() { deep } else { full };
            let tm = Tracer { world: &world_mod, knobs, cut_weight: 0.0.into() };
            idx.iter()
                .map(|&i| {
                    let (x, y) = ((i as u32 % w) as f32, (i as u32 / w) as f32);
                    let mut b = Bins::default();
                    for j in 0..nr {
                        for k in 0..nr {
                            let off = Vec2::new((k as f32 + 0.5) / nr as f32, (j as f32 + 0.5) / nr as f32);
                            let d = rays.direction(Vec2::new(x, y) + off);
                            tm.outside(&mut b, camera.position_m, d, Vec3::ONE, 1.0, 0, 0, false);
                        }
                    }
                    b.total() / (nr * nr) as f32
                })
                .collect()
        };
        let half = disc.len() / 2;
        let vals: Vec<Vec3> = std::thread::scope(|sc| {
            let a = sc.spawn(|| trace(&disc[..half]));
            let b = trace(&disc[half..]);
            let mut a = a.join().unwrap();
            a.extend(b);
            a
        });
        for (k, &i) in disc.iter().enumerate() {
            for c in 0..3 {
                real8[i * 3 + c] = srgb8(vals[k][c]);
            }
        }
        eprintln!("reference at {nr}x{nr} over the disc in {:.1}s", t0.elapsed().as_secs_f32());
    }
    let real8 = real8;
    let t0 = std::time::Instant::now();
    let half = disc.len() / 2;
    let pxs: Vec<Px> = std::thread::scope(|sc| {
        let a = sc.spawn(|| work(&disc[..half]));
        let b = work(&disc[half..]);
        let mut a = a.join().unwrap();
        a.extend(b);
        a
    });
    eprintln!("{} disc pixels traced in {:.1}s", disc.len(), t0.elapsed().as_secs_f32());

    // Check: our full trace against the written reference.
    let mut diff = 0.0f64;
    for (k, &i) in disc.iter().enumerate() {
        let t = pxs[k].full.total();
        for c in 0..3 {
            diff += (f64::from(srgb8(t[c])) - f64::from(real8[i * 3 + c])).abs();
        }
    }
    println!("check: mean |ours - real.png| over disc = {:.3} (8-bit)", diff / (disc.len() * 3) as f64);

    // Silhouette: pixels fully covered by glass.
    let sil: Vec<usize> = (0..disc.len()).filter(|&k| pxs[k].cover >= 0.999).collect();
    let mean = |f: &dyn Fn(&Px) -> Vec3, set: &[usize]| -> f32 {
        set.iter().map(|&k| f(&pxs[k]).dot(Vec3::ONE) / 3.0).sum::<f32>() / set.len().max(1) as f32
    };
    let ppd = scene_pixels_per_degree(&scene, w);
    let flip_disc = |shown: &[u8]| -> f64 {
        let e = vitreous_compare::flip::error_map(&real8, shown, (w, h), ppd).unwrap();
        disc.iter().map(|&i| f64::from(e[i])).sum::<f64>() / disc.len() as f64
    };
    // Shown image for a glass light T over the disc (eq. 6 then additive): seen + max(T-seen,0).
    let shown_of = |t: &dyn Fn(&Px) -> Vec3| -> Vec<u8> {
        let mut out = preview8.clone();
        for (k, &i) in disc.iter().enumerate() {
            let tv = t(&pxs[k]);
            for c in 0..3 {
                let s = lin8(seen8[i * 3 + c]);
                let left = srgb8((tv[c] - s).max(0.0));
                out[i * 3 + c] = srgb8(lin8(left) + s);
            }
        }
        out
    };
    let nothing = flip_disc(&seen8);
    let limit_img: Vec<u8> = seen8.iter().zip(&real8).map(|(a, b)| *a.max(b)).collect();
    let limit = flip_disc(&limit_img);
    let gpu_actual = flip_disc(&preview8);
    let gap = |f: f64| (f - limit) / (nothing - limit);
    println!(
        "disc {} px, silhouette (fully covered) {} px; flip nothing {:.4} limit {:.4}; GPU actual preview {:.4} gap {:.3}",
        disc.len(), sil.len(), nothing, limit, gpu_actual, gap(gpu_actual)
    );
    {
        // Where the GPU's error lies: disc pixels by how much of them the glass covers.
        let e = vitreous_compare::flip::error_map(&real8, &preview8, (w, h), ppd).unwrap();
        let el = vitreous_compare::flip::error_map(&real8, &limit_img, (w, h), ppd).unwrap();
        for (name, lo, hi) in [("none", -1.0, 0.001), ("partly", 0.001, 0.999), ("whole", 0.999, 2.0)] {
            let set: Vec<usize> = (0..disc.len()).filter(|&k| pxs[k].cover > lo && pxs[k].cover <= hi).collect();
            let sum: f64 = set.iter().map(|&k| f64::from(e[disc[k]])).sum();
            let lim: f64 = set.iter().map(|&k| f64::from(el[disc[k]])).sum();
            let seen_sum: f64 = {
                let es = vitreous_compare::flip::error_map(&real8, &seen8, (w, h), ppd).unwrap();
                set.iter().map(|&k| f64::from(es[disc[k]])).sum()
            };
            let gpu_glass = set.iter().filter(|&&k| (0..3).any(|c| left8[disc[k] * 3 + c] > 0)).count();
            println!(
                "  covered {name:6}: {:5} px ({} with GPU light); share of disc FLIP sum: GPU {:.4} limit {:.4} nothing {:.4}",
                set.len(), gpu_glass, sum / disc.len() as f64, lim / disc.len() as f64, seen_sum / disc.len() as f64
            );
        }
    }
    let report = |name: &str, t: &dyn Fn(&Px) -> Vec3| {
        let f = flip_disc(&shown_of(t));
        println!("{name:58} sil mean {:.4}  disc flip {:.4}  gap {:.3}", mean(t, &sil), f, gap(f));
    };
    report("reference full (16 interfaces, 1e-4, floor lit)", &|p| p.full.total());
    report("reference deep (64 interfaces, 1e-6)", &|p| p.deep.total());
    report("reference, floor photo as is", &|p| p.photo.total());
    report("reference order 0 (main path only, no splits)", &|p| p.full.order_le(0));
    report("reference order <=1", &|p| p.full.order_le(1));
    report("reference order <=2", &|p| p.full.order_le(2));
    report("reference order <=1, floor photo", &|p| p.photo.order_le(1));
    report("GPU emulation (front+main+branches), floor lit", &|p| p.gpu[0] + p.gpu[1] + p.gpu[2]);
    report("GPU emulation, floor photo (as the GPU)", &|p| p.gpu_photo[0] + p.gpu_photo[1] + p.gpu_photo[2]);
    report("GPU emulation, no branches, floor photo", &|p| p.gpu_photo[0] + p.gpu_photo[1] + if p.cover < 0.999 { p.gpu_photo[2] } else { Vec3::ZERO });
    if std::env::var("CONVEX").is_ok() {
        for (echoes, max_tir) in [(0, 8), (2, 8), (4, 8), (8, 8), (2, 16), (8, 16), (16, 32)] {
            let vals: Vec<Vec3> = {
                let tp = Tracer { world: &world_photo, knobs: full, cut_weight: 0.0.into() };
                disc.iter()
                    .map(|&i| {
                        let (x, y) = ((i as u32 % w) as f32, (i as u32 / w) as f32);
                        let n = samples;
                        let mut sum = Vec3::ZERO;
                        for j in 0..n {
                            for k in 0..n {
                                let off = Vec2::new((k as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                                let d = rays.direction(Vec2::new(x, y) + off);
                                let o = camera.position_m;
                                let glass = world_photo.glass.as_ref().unwrap();
                                let photo = world_photo.photo_hit(o, d);
                                if let Some((t, normal)) = glass.shape.enter(o, d)
                                    && photo.is_none_or(|(tp, _)| t < tp)
                                {
                                    sum += tp.gpu_convex(o + d * t, d, normal, echoes, max_tir);
                                } else {
                                    sum += tp.room(o, d, false).0;
                                }
                            }
                        }
                        sum / (n * n) as f32
                    })
                    .collect()
            };
            let name = format!("GPU convex emulation, floor photo, ECHOES {echoes}, TIR {max_tir}");
            let f = flip_disc(&shown_of(&|p: &Px| {
                let k = pxs.iter().position(|q| std::ptr::eq(q, p)).unwrap();
                vals[k]
            }));
            let m = sil.iter().map(|&k| vals[k].dot(Vec3::ONE) / 3.0).sum::<f32>() / sil.len() as f32;
            println!("{name:58} sil mean {m:.4}  disc flip {f:.4}  gap {:.3}", gap(f));
        }
    }
    let end_names = ["floor", "wall", "env", "none"];
    println!("reference full, silhouette mean by order x end:");
    for o in 0..ORDERS {
        let row: Vec<String> = (0..ENDS)
            .map(|e| format!("{}={:.4}", end_names[e], mean(&|p: &Px| p.full.0[o][e], &sil)))
            .collect();
        println!("  order {o}{}: {}", if o == 3 { "+" } else { "" }, row.join(" "));
    }
    println!("floor photo as is, silhouette mean by order x end:");
    for o in 0..ORDERS {
        let row: Vec<String> = (0..ENDS)
            .map(|e| format!("{}={:.4}", end_names[e], mean(&|p: &Px| p.photo.0[o][e], &sil)))
            .collect();
        println!("  order {o}{}: {}", if o == 3 { "+" } else { "" }, row.join(" "));
    }
    println!(
        "GPU emulation parts (floor photo), silhouette mean: front {:.4} main {:.4} branches {:.4}",
        mean(&|p| p.gpu_photo[0], &sil), mean(&|p| p.gpu_photo[1], &sil), mean(&|p| p.gpu_photo[2], &sil)
    );
    println!("reference: weight cut (16 interfaces / 1e-4 / no exit), silhouette mean {:.4}", sil.iter().map(|&k| pxs[k].cut).sum::<f32>() / sil.len() as f32);
    if let Some((_, _, g)) = &gpu_t {
        let gm = sil.iter().map(|&k| { let i = disc[k]; (0..3).map(|c| lin8(g[i * 3 + c])).sum::<f32>() / 3.0 }).sum::<f32>() / sil.len() as f32;
        println!("GPU actual T (given image), silhouette mean {gm:.4}");
    }
    // Height bands (y of first hit, relative to the object's centre).
    let cy = placement.object_position_m.y;
    println!("by height band (first hit y - centre, mm): n, ref full, ref photo, ref ord<=1 photo, GPU emu photo, GPU actual T");
    for (lo, hi) in [(-60.0, -40.0), (-40.0, -10.0), (-10.0, 10.0), (10.0, 30.0), (30.0, 60.0)] {
        let band: Vec<usize> = sil
            .iter()
            .copied()
            .filter(|&k| {
                let y = (pxs[k].y - cy) * 1000.0;
                y >= lo && y < hi
            })
            .collect();
        let ga = gpu_t.as_ref().map_or(f32::NAN, |(_, _, g)| {
            band.iter().map(|&k| { let i = disc[k]; (0..3).map(|c| lin8(g[i * 3 + c])).sum::<f32>() / 3.0 }).sum::<f32>() / band.len().max(1) as f32
        });
        println!(
            "  [{lo:5.0},{hi:5.0}) n={:5} full {:.4} photo {:.4} ord<=1 {:.4} emu {:.4} gpu {:.4}",
            band.len(),
            mean(&|p| p.full.total(), &band),
            mean(&|p| p.photo.total(), &band),
            mean(&|p| p.photo.order_le(1), &band),
            mean(&|p| p.gpu_photo[0] + p.gpu_photo[1] + p.gpu_photo[2], &band),
            ga
        );
    }
    // Dump per-pixel images for inspection: reference full T and GPU emulation T over the disc.
    let out = Path::new(&args[2]);
    let dump = |name: &str, t: &dyn Fn(&Px) -> Vec3| -> anyhow::Result<()> {
        let mut img = vec![0u8; (w * h * 3) as usize];
        for (k, &i) in disc.iter().enumerate() {
            let v = t(&pxs[k]);
            for c in 0..3 {
                img[i * 3 + c] = srgb8(v[c]);
            }
        }
        image::RgbImage::from_raw(w, h, img).unwrap().save(out.join(name))?;
        Ok(())
    };
    dump("study-ref-full.png", &|p| p.full.total())?;
    dump("study-ref-photo.png", &|p| p.photo.total())?;
    dump("study-emu.png", &|p| p.gpu_photo[0] + p.gpu_photo[1] + p.gpu_photo[2])?;
    dump("study-ref-ord2plus.png", &|p| p.photo.total() - p.photo.order_le(1))?;
    Ok(())
}
