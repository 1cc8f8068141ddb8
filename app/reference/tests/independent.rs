//! The reference's image of `glass-sphere-real.toml`'s ball against a tracer written apart from
//! it, here: its own eye rays, ray-sphere meetings, Fresnel reflectance (s and p written out),
//! branch sums, floor light (photons from the lamp on a grid of equal solid angle, landing on a
//! grid of its own) and the environment's direction-to-texel map as the docs state it (u = 0.5
//! down -z, +x to the right, top row straight up). Shared with the reference: the scene's
//! loading, where a ray meets a photo's plane and a photo's texel interpolation, which are the
//! world, not the optics.
//!
//! Left eye, neutral head, 640 x 480, 6 x 6 positions per pixel in both, over the 1450 pixels
//! that see the ball within 0.9 of its radius: the disc's mean light agrees within 0.05 % and
//! the pixels differ by 0.3 % of the light. About 17 % of the disc's light comes from the
//! environment map (the front surface's reflection 9 %, the internal echoes 6 %, past the wall
//! and table 2 %). Each of these in either tracer makes the test fail: the map mirrored (mean
//! 1.2 %, pixels 20 %) or turned a quarter (3.9 %, 22 %), the ball at n = 1.50 (pixels 6.5 %),
//! Schlick's approximation for the reflectance (mean 1.8 %), the lamp's shadow and caustic left
//! out of the floor's light (0.7 %), each ray leaving a surface started 0.22 mm off it (pixels
//! 2.5 %: Mitsuba 3 offsets by about that much at the ball's 1.5 m from the origin, its offset
//! growing with the coordinates; docs/realism.md, "Against Mitsuba 3").

use std::f32::consts::{PI, TAU};
use std::path::Path;

use glam::{Quat, Vec2, Vec3};
use vitreous_optics::camera::{EyeParams, Fov};
use vitreous_reference::{
    FloorLight, PhotonParams, Picture, Sampling, Surface, Window, World, render_eye,
};

const SIZE: (u32, u32) = (640, 480);
/// Positions along each side of a pixel, in both tracers.
const PER_SIDE: u32 = 6;
/// Branches weaker than this are dropped.
const MIN_WEIGHT: f32 = 1e-6;

/// A glass ball and the world around it, traced here.
struct Apart {
    centre: Vec3,
    radius: f32,
    ior: f32,
    floor: Surface,
    wall: Surface,
    environment: Picture,
    share: f32,
    floor_light: LampGrid,
}

/// Exact Fresnel reflectance for unpolarised light from index `n1` into `n2` at incidence
/// cosine `cos_i`; 1 when the light cannot leave.
fn reflectance(n1: f32, n2: f32, cos_i: f32) -> (f32, f32) {
    let sin_t2 = (n1 / n2).powi(2) * (1.0 - cos_i * cos_i);
    if sin_t2 >= 1.0 {
        return (1.0, 0.0);
    }
    let cos_t = (1.0 - sin_t2).sqrt();
    let rs = ((n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t)).powi(2);
    let rp = ((n1 * cos_t - n2 * cos_i) / (n1 * cos_t + n2 * cos_i)).powi(2);
    ((rs + rp) / 2.0, cos_t)
}

/// Where the ray meets the ball: the near side from outside, the far side from inside.
fn meet(centre: Vec3, radius: f32, origin: Vec3, dir: Vec3, inside: bool) -> Option<f32> {
    let oc = origin - centre;
    let b = oc.dot(dir);
    let disc = b * b - (oc.length_squared() - radius * radius);
    if disc <= 0.0 {
        return None;
    }
    let t = if inside {
        -b + disc.sqrt()
    } else {
        -b - disc.sqrt()
    };
    (t > 1e-6).then_some(t)
}

/// One interface of the ball: the reflected and transmitted branches (direction, weight, inside
/// afterwards) of a ray meeting it at `p`.
fn split(ball: (Vec3, f32, f32), p: Vec3, dir: Vec3, inside: bool) -> [(Vec3, f32, bool); 2] {
    let (centre, radius, ior) = ball;
    let outward = (p - centre) / radius;
    let facing = if dir.dot(outward) < 0.0 {
        outward
    } else {
        -outward
    };
    let cos_i = -dir.dot(facing);
    let (n1, n2) = if inside { (ior, 1.0) } else { (1.0, ior) };
    let (r, cos_t) = reflectance(n1, n2, cos_i);
    let reflected = dir + facing * (2.0 * cos_i);
    let eta = n1 / n2;
    let transmitted = dir * eta + facing * (eta * cos_i - cos_t);
    [(reflected, r, inside), (transmitted, 1.0 - r, !inside)]
}

impl Apart {
    /// Light arriving along `dir` at `origin` (outside or inside the ball).
    fn radiance(&self, origin: Vec3, dir: Vec3, inside: bool, weight: f32, depth: u32) -> Vec3 {
        if weight < MIN_WEIGHT || depth > 48 {
            return Vec3::ZERO;
        }
        let Some(t) = meet(self.centre, self.radius, origin, dir, inside) else {
            return self.room(origin, dir);
        };
        let p = origin + dir * t;
        let ball = (self.centre, self.radius, self.ior);
        split(ball, p, dir, inside)
            .into_iter()
            .filter(|&(_, w, _)| w > 0.0)
            .map(|(d, w, inside)| {
                let d = d.normalize();
                w * self.radiance(p + d * 1e-6, d, inside, weight * w, depth + 1)
            })
            .sum()
    }

    /// What a ray outside the ball sees: the nearer photo, else the environment.
    fn room(&self, origin: Vec3, dir: Vec3) -> Vec3 {
        let floor = self.floor.hit(origin, dir);
        let wall = self.wall.hit(origin, dir);
        match (floor, wall) {
            (Some((tf, uv)), w) if w.is_none_or(|(tw, _)| tf <= tw) => {
                let lamp = self.floor_light.ratio(uv);
                self.floor.radiance(uv) * ((1.0 - self.share) + self.share * lamp)
            }
            (_, Some((_, uv))) => self.wall.radiance(uv),
            _ => {
                let u = dir.x.atan2(-dir.z) / TAU + 0.5;
                let v = dir.y.clamp(-1.0, 1.0).acos() / PI;
                self.environment.bilinear(Vec2::new(u, v), true)
            }
        }
    }
}

/// The floor's irradiance from the lamp with the ball against without it, on a grid over the
/// floor photo's coordinates: photons on a regular grid of equal solid angle over a cone about
/// the ball, each landing with its flux.
struct LampGrid {
    texels: u32,
    ratio: Vec<f32>,
}

impl LampGrid {
    fn trace(lamp: Vec3, ball: (Vec3, f32, f32), floor: &Surface) -> LampGrid {
        const TEXELS: u32 = 500; // 2 mm on the 1 m photo
        const SIDE: u32 = 1200;
        let (centre, radius, _) = ball;
        let axis = (centre - lamp).normalize();
        let half = (radius / (centre - lamp).length()).asin() * 1.6;
        let a = axis.cross(Vec3::X).normalize();
        let b = axis.cross(a);
        let cells = (TEXELS * TEXELS) as usize;
        let (mut with, mut without) = (vec![0f32; cells], vec![0f32; cells]);
        let land = |grid: &mut Vec<f32>, origin: Vec3, dir: Vec3, w: f32| {
            if let Some((_, uv)) = floor.hit(origin, dir) {
                let (x, y) = ((uv.x * TEXELS as f32) as u32, (uv.y * TEXELS as f32) as u32);
                if x < TEXELS && y < TEXELS {
                    grid[(y * TEXELS + x) as usize] += w;
                }
            }
        };
        for i in 0..SIDE {
            for j in 0..SIDE {
                let cos = 1.0 - (i as f32 + 0.5) / SIDE as f32 * (1.0 - half.cos());
                let phi = (j as f32 + 0.5) / SIDE as f32 * TAU;
                let sin = (1.0 - cos * cos).sqrt();
                let dir = axis * cos + a * (sin * phi.cos()) + b * (sin * phi.sin());
                land(&mut without, lamp, dir, 1.0);
                let mut rays = vec![(lamp, dir, false, 1.0f32)];
                while let Some((o, d, inside, w)) = rays.pop() {
                    match meet(centre, radius, o, d, inside) {
                        None => land(&mut with, o, d, w),
                        Some(t) => {
                            let p = o + d * t;
                            for (d, r, inside) in split(ball, p, d, inside) {
                                if w * r > MIN_WEIGHT {
                                    let d = d.normalize();
                                    rays.push((p + d * 1e-6, d, inside, w * r));
                                }
                            }
                        }
                    }
                }
            }
        }
        let ratio = with
            .iter()
            .zip(&without)
            .map(|(&w, &o)| if o > 0.0 { w / o } else { 1.0 })
            .collect();
        LampGrid {
            texels: TEXELS,
            ratio,
        }
    }

    fn ratio(&self, uv: Vec2) -> f32 {
        let (x, y) = (uv * self.texels as f32).floor().as_ivec2().into();
        let n = self.texels as i32;
        if (0..n).contains(&x) && (0..n).contains(&y) {
            self.ratio[(y * n + x) as usize]
        } else {
            1.0
        }
    }
}

#[test]
fn the_balls_disc_matches_a_tracer_written_apart() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let scene =
        vitreous_scene::load_scene(&root.join("config/scenes/glass-sphere-real.toml")).unwrap();
    let placement = scene.rest_placement();
    let eye = scene.viewer.neutral_eye_positions_m()[0];
    let f = scene.output.fov;
    let fov = Fov {
        left_rad: f.angle_left_rad,
        right_rad: f.angle_right_rad,
        up_rad: f.angle_up_rad,
        down_rad: f.angle_down_rad,
    };

    // The reference, as `vitreous reference` traces it.
    let world = World::of(&scene, &placement).unwrap();
    let lamp = FloorLight::trace(&world, &PhotonParams::default());
    let world = World {
        floor_light: lamp,
        ..world
    };
    let camera = EyeParams::new(eye, Quat::IDENTITY, fov);

    // The same scene traced here.
    let centre = placement.object_position_m;
    let (radius, ior) = (scene.object.radius_m, scene.object.ior);
    let floor = Surface::of(&scene.floor);
    let floor_light = LampGrid::trace(placement.light_position_m, (centre, radius, ior), &floor);
    let apart = Apart {
        centre,
        radius,
        ior,
        wall: Surface::of(&scene.background),
        environment: Picture::of(&scene.environment.latlong),
        share: scene.light.share,
        floor,
        floor_light,
    };
    let (w, h) = (SIZE.0 as f32, SIZE.1 as f32);
    let (l, r) = (fov.left_rad.tan(), fov.right_rad.tan());
    let (u, d) = (fov.up_rad.tan(), fov.down_rad.tan());
    let ray = |p: Vec2| Vec3::new(l + p.x / w * (r - l), u - p.y / h * (u - d), -1.0).normalize();

    // The disc: pixels whose centre sees the ball within 0.9 of its angular radius.
    let to_centre = (centre - eye).normalize();
    let cos_limit = ((radius / (centre - eye).length()).asin() * 0.9).cos();
    let disc: Vec<(u32, u32)> = (0..SIZE.1)
        .flat_map(|y| (0..SIZE.0).map(move |x| (x, y)))
        .filter(|&(x, y)| ray(Vec2::new(x as f32 + 0.5, y as f32 + 0.5)).dot(to_centre) > cos_limit)
        .collect();
    assert!(disc.len() > 1000, "{} disc pixels", disc.len());
    let (x0, y0) = disc
        .iter()
        .fold((u32::MAX, u32::MAX), |(a, b), &(x, y)| (a.min(x), b.min(y)));
    let (x1, y1) = disc
        .iter()
        .fold((0, 0), |(a, b), &(x, y)| (a.max(x), b.max(y)));
    let window = Window {
        x: x0,
        y: y0,
        width: x1 - x0 + 1,
        height: y1 - y0 + 1,
    };
    let traced = render_eye(&world, &camera, SIZE, window, Sampling::uniform(PER_SIDE));

    let (mut sum_ref, mut sum_apart, mut sum_diff) = (0.0f64, 0.0f64, 0.0f64);
    for &(x, y) in &disc {
        let mut light = Vec3::ZERO;
        for j in 0..PER_SIDE {
            for i in 0..PER_SIDE {
                let offset = (Vec2::new(i as f32, j as f32) + 0.5) / PER_SIDE as f32;
                light += apart.radiance(
                    eye,
                    ray(Vec2::new(x as f32, y as f32) + offset),
                    false,
                    1.0,
                    0,
                );
            }
        }
        let light = light / (PER_SIDE * PER_SIDE) as f32;
        let reference = traced.at(x, y);
        sum_ref += f64::from(reference.element_sum());
        sum_apart += f64::from(light.element_sum());
        sum_diff += f64::from((reference - light).abs().element_sum());
    }
    let n = disc.len() as f64;
    let (mean_ref, mean_apart) = (sum_ref / n, sum_apart / n);
    let ratio = mean_ref / mean_apart;
    let per_pixel = sum_diff / sum_apart;
    eprintln!(
        "{} disc pixels: reference {mean_ref:.4}, apart {mean_apart:.4} (ratio {ratio:.4}); \
         mean per-pixel difference {per_pixel:.4} of the light",
        disc.len()
    );
    assert!(
        (ratio - 1.0).abs() < 0.005,
        "the disc's mean light: ratio {ratio}"
    );
    assert!(
        per_pixel < 0.01,
        "per-pixel difference {per_pixel} of the light"
    );
}
