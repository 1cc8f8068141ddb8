//! Where in an eye image each part of a scene lies, for comparing images region by region: the
//! object's disc, the floor's shadow and caustic, the shadow inducer's ramp around the shadow,
//! and the rest. Computed on the CPU for one eye at the scene's neutral head from the object's
//! bounding sphere (exact for a ball, a superset of any other object's outline), the point
//! light and the floor; the caustic from the scene's bake, when it has one.

use glam::{Quat, Vec2, Vec3};
use serde::Serialize;
use vitreous_optics::camera::EyeParams;
use vitreous_optics::floor::{FAR_M, exact_edge_distances};
use vitreous_reference::EyeRecord;
use vitreous_scene::{Placement, Scene};

/// A region of the eye image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Region {
    /// The object's disc (its bounding sphere's outline).
    Disc,
    /// The floor in the object's shadow or lit by its caustic.
    ShadowCaustic,
    /// The lit floor within the inducer's ramp width of the shadow.
    InducerRamp,
    /// Everything else.
    Rest,
}

impl Region {
    /// Every region, in report order.
    pub const ALL: [Region; 4] = [
        Region::Disc,
        Region::ShadowCaustic,
        Region::InducerRamp,
        Region::Rest,
    ];

    /// The region's name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Region::Disc => "disc",
            Region::ShadowCaustic => "shadow_caustic",
            Region::InducerRamp => "inducer_ramp",
            Region::Rest => "rest",
        }
    }
}

/// Side of the floor grid the shadow and the ramp are found on, texels.
const FLOOR_GRID: u32 = 256;

/// Caustic gain above which a floor point counts as lit by the caustic.
const CAUSTIC_GAIN: f32 = 0.01;

/// Which eye of the scene's viewer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Eye {
    /// The left eye.
    Left,
    /// The right eye.
    Right,
}

impl Eye {
    /// Both eyes, left first (as a frame's views).
    pub const ALL: [Eye; 2] = [Eye::Left, Eye::Right];

    /// 0 for the left eye, 1 for the right (as a frame's views).
    pub fn index(self) -> usize {
        match self {
            Eye::Left => 0,
            Eye::Right => 1,
        }
    }

    /// `left` or `right`, as the frame files and reports name the eye.
    pub fn name(self) -> &'static str {
        match self {
            Eye::Left => "left",
            Eye::Right => "right",
        }
    }
}

/// The region of every pixel of a `width` x `height` image of `eye` at the scene's neutral
/// head (looking down -z from `viewer.head_position_m`), row by row.
pub fn regions(scene: &Scene, eye: Eye, width: u32, height: u32) -> Vec<Region> {
    regions_of(
        scene,
        &neutral_camera(scene, eye),
        &scene.rest_placement(),
        width,
        height,
    )
}

/// The camera of `eye` at the scene's neutral head.
pub fn neutral_camera(scene: &Scene, eye: Eye) -> EyeParams {
    let position = scene.viewer.neutral_eye_positions_m()[eye.index()];
    let fov = scene.output.fov;
    EyeRecord {
        position_m: position.to_array(),
        orientation_xyzw: Quat::IDENTITY.to_array(),
        fov_rad: [
            fov.angle_left_rad,
            fov.angle_right_rad,
            fov.angle_up_rad,
            fov.angle_down_rad,
        ],
    }
    .camera()
}

/// How wide the ring around the object's disc is ([`Labels::around`]), degrees: 80 pixels at
/// 32 pixels per degree, the reach of a registration error's ghost and of a dimmer's halo.
pub const RING_DEG: f32 = 2.5;

/// Every pixel's region, and the ring around the object's disc (which overlaps the regions
/// outside it).
#[derive(Clone, Debug)]
pub struct Labels {
    /// Each pixel's region, row by row.
    pub regions: Vec<Region>,
    /// Whether each pixel lies outside the object's disc, within [`RING_DEG`] of its outline.
    pub around: Vec<bool>,
}

impl Labels {
    /// The labels of a `width` x `height` image seen by `camera`, with the object and the
    /// light at `placement`.
    pub fn of(
        scene: &Scene,
        camera: &EyeParams,
        placement: &Placement,
        width: u32,
        height: u32,
    ) -> Labels {
        Labels {
            regions: regions_of(scene, camera, placement, width, height),
            around: ring_of(scene, camera, placement, width, height, RING_DEG),
        }
    }
}

/// Whether each pixel of a `width` x `height` image seen by `camera` lies outside the object's
/// disc (its bounding sphere at `placement`) and within `ring_deg` of its outline, row by row.
pub fn ring_of(
    scene: &Scene,
    camera: &EyeParams,
    placement: &Placement,
    width: u32,
    height: u32,
    ring_deg: f32,
) -> Vec<bool> {
    let to_centre = placement.object_position_m - camera.position_m;
    let distance = to_centre.length();
    let radius = scene.object.radius_m;
    // Inside the sphere every direction is the disc.
    let outline = if distance > radius {
        (radius / distance).asin()
    } else {
        std::f32::consts::PI
    };
    let reach = outline + ring_deg.to_radians();
    let rays = camera.pixel_rays(Vec2::new(width as f32, height as f32));
    let mut out = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let dir = rays.direction(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let angle = dir.angle_between(to_centre);
            out.push(angle > outline && angle <= reach);
        }
    }
    out
}

/// The region of every pixel of a `width` x `height` image seen by `camera`, with the object
/// and the light at `placement`, row by row. The caustic counts only at the scene's resting
/// placement, which its bake is for.
pub fn regions_of(
    scene: &Scene,
    camera: &EyeParams,
    placement: &Placement,
    width: u32,
    height: u32,
) -> Vec<Region> {
    let floor = FloorRegions::new(scene, placement);
    let floor_from_world = scene.floor.world_from_plane().inverse();
    let rays = camera.pixel_rays(Vec2::new(width as f32, height as f32));
    let mut out = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        for x in 0..width {
            let dir = rays.direction(Vec2::new(x as f32 + 0.5, y as f32 + 0.5));
            let origin = camera.position_m;
            out.push(classify(
                scene,
                placement,
                &floor,
                floor_from_world,
                origin,
                dir,
            ));
        }
    }
    out
}

/// The region a ray from `origin` along `dir` (unit) falls in; `floor_from_world` is the
/// inverse of the floor's `world_from_plane`.
fn classify(
    scene: &Scene,
    placement: &Placement,
    floor: &FloorRegions,
    floor_from_world: glam::Mat4,
    origin: Vec3,
    dir: Vec3,
) -> Region {
    let center = placement.object_position_m;
    let radius = scene.object.radius_m;
    if ray_sphere(origin, dir, center, radius).is_some() {
        return Region::Disc;
    }
    let normal = scene.floor.normal();
    let along = dir.dot(normal);
    if along.abs() < 1e-9 {
        return Region::Rest;
    }
    let t = (scene.floor.pose.position - origin).dot(normal) / along;
    if t <= 0.0 {
        return Region::Rest;
    }
    let local = floor_from_world.transform_point3(origin + dir * t);
    if local.x.abs() > 0.5 || local.y.abs() > 0.5 {
        return Region::Rest;
    }
    floor.at(Vec2::new(local.x + 0.5, 0.5 - local.y))
}

/// The first crossing of the ray `origin + t dir` (t > 0, `dir` unit) with a sphere.
fn ray_sphere(origin: Vec3, dir: Vec3, center: Vec3, radius: f32) -> Option<f32> {
    let to = origin - center;
    let b = to.dot(dir);
    let c = to.length_squared() - radius * radius;
    let disc = b * b - c;
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    let t = if t > 0.0 { t } else { -b + disc.sqrt() };
    (t > 0.0).then_some(t)
}

/// The floor's regions on a grid over its photo (u right, v down, as the photo).
struct FloorRegions {
    regions: Vec<Region>,
}

impl FloorRegions {
    fn new(scene: &Scene, placement: &Placement) -> FloorRegions {
        let n = FLOOR_GRID;
        let world_from_plane = scene.floor.world_from_plane();
        let centre_of = |i: u32| {
            let (x, y) = (i % n, i / n);
            let uv = Vec2::new((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            world_from_plane.transform_point3(Vec3::new(uv.x - 0.5, 0.5 - uv.y, 0.0))
        };
        let light = placement.light_position_m;
        let (center, radius) = (placement.object_position_m, scene.object.radius_m);
        let mask: Vec<u8> = (0..n * n)
            .map(|i| {
                let p = centre_of(i);
                let to_light = light - p;
                let distance = to_light.length();
                let shaded = distance > 0.0
                    && ray_sphere(p, to_light / distance, center, radius)
                        .is_some_and(|t| t < distance);
                u8::from(shaded)
            })
            .collect();
        let texel_m = scene.floor.size_m / n as f32;
        let distances = exact_edge_distances(&mask, n, texel_m);
        let ramp_m = scene.inducer.ramp_width_m;
        let gain = scene
            .caustics
            .gain
            .as_ref()
            .filter(|_| *placement == scene.rest_placement());
        let regions = (0..n * n)
            .map(|i| {
                let uv = Vec2::new(
                    ((i % n) as f32 + 0.5) / n as f32,
                    ((i / n) as f32 + 0.5) / n as f32,
                );
                let caustic = gain.is_some_and(|g| g.sample(uv.x, uv.y) > CAUSTIC_GAIN);
                let d = distances[i as usize];
                if mask[i as usize] != 0 || caustic {
                    Region::ShadowCaustic
                } else if d < FAR_M && d < ramp_m {
                    Region::InducerRamp
                } else {
                    Region::Rest
                }
            })
            .collect();
        FloorRegions { regions }
    }

    /// The region at floor photo coordinate `uv` (0..1, v down).
    fn at(&self, uv: Vec2) -> Region {
        let n = FLOOR_GRID;
        let x = ((uv.x * n as f32) as u32).min(n - 1);
        let y = ((uv.y * n as f32) as u32).min(n - 1);
        self.regions[(y * n + x) as usize]
    }
}
