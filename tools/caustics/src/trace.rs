//! Light paths from the point light through the object to the floor, with deterministic
//! Fresnel splitting: one grid ray becomes a small tree of weighted paths.

use glam::{Mat4, Vec2, Vec3};
use vitreous_optics::optics::{fresnel_reflectance, reflect, refract};
use vitreous_optics::solid::Solid;
use vitreous_optics::solid::bvh::{Bvh, Hit};

use crate::{CausticScene, InputError};

/// How a path ended.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum End {
    /// On the floor rectangle, at these continuous texel coordinates (x right, y down).
    Floor(Vec2),
    /// Left the scene without reaching the floor rectangle.
    Away,
    /// Still going when it reached the interaction limit.
    Limit,
    /// Its weight fell below the pruning threshold.
    Pruned,
}

/// One leaf of a grid ray's path tree.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Leaf {
    /// Hash of the event sequence (reflect/refract, smooth patch) that led here.
    pub sig: u64,
    /// Fraction of the grid ray's flux on this path.
    pub weight: f32,
    /// The first interaction was an external reflection.
    pub reflected_first: bool,
    /// Where the path ended.
    pub end: End,
}

/// A traced grid ray.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Corner {
    /// The ray hit the object (else it is direct light).
    pub hit: bool,
    /// Where the straight, unobstructed ray meets the floor rectangle (texel coordinates).
    pub straight: Option<Vec2>,
    /// Start of this ray's leaves in the row's leaf list (sorted by `sig`).
    pub first_leaf: u32,
    /// Number of leaves.
    pub leaf_count: u32,
}

/// The floor rectangle in the bake frame.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FloorFrame {
    /// Centre, metres.
    pub origin: Vec3,
    /// Unit normal of the visible side.
    pub normal: Vec3,
    /// Full width vector (local x), metres.
    pub axis_x: Vec3,
    /// Full height vector (local y, photo top), metres.
    pub axis_y: Vec3,
    /// Inverse Gram matrix of the two axes (local coordinates from dot products).
    gram_inv: [f32; 4],
    /// Texture width, texels.
    pub width_px: u32,
    /// Texture height, texels.
    pub height_px: u32,
}

impl FloorFrame {
    /// Floor point for local coordinates in `[-0.5, 0.5]^2`.
    pub fn point(&self, local: Vec2) -> Vec3 {
        self.origin + local.x * self.axis_x + local.y * self.axis_y
    }

    /// Continuous texel coordinates of a floor point, if inside the rectangle.
    pub fn texel(&self, p: Vec3) -> Option<Vec2> {
        let d = p - self.origin;
        let (a, b) = (d.dot(self.axis_x), d.dot(self.axis_y));
        let [g00, g01, g10, g11] = self.gram_inv;
        let (u, v) = (g00 * a + g01 * b, g10 * a + g11 * b);
        if u.abs() > 0.5 || v.abs() > 0.5 || !u.is_finite() || !v.is_finite() {
            return None;
        }
        Some(Vec2::new(
            (u + 0.5) * self.width_px as f32,
            (0.5 - v) * self.height_px as f32,
        ))
    }

    /// Area of the rectangle, square metres.
    pub fn area_m2(&self) -> f32 {
        self.axis_x.cross(self.axis_y).length()
    }

    /// Distance along the ray to the floor plane, approaching its visible side.
    fn hit_t(&self, origin: Vec3, dir: Vec3) -> Option<f32> {
        let denom = dir.dot(self.normal);
        if denom >= 0.0 {
            return None;
        }
        let t = (self.origin - origin).dot(self.normal) / denom;
        (t > 0.0).then_some(t)
    }
}

/// A scene prepared for tracing, in the bake frame: world axes with the origin moved to the
/// object's bounding-sphere centre (so f32 keeps sub-micrometre precision on the glass).
pub(crate) struct Tracer {
    /// The closed mesh.
    pub solid: Solid,
    /// Acceleration structure over `solid.triangles_m`.
    pub bvh: Bvh,
    /// Refractive index.
    pub ior: f32,
    /// Light, metres.
    pub light: Vec3,
    /// Bounding-sphere radius, metres.
    pub radius_m: f32,
    /// The floor.
    pub floor: FloorFrame,
    /// Self-intersection offset, metres.
    eps_m: f32,
    /// Most surface interactions on one path.
    pub max_interactions: u32,
    /// Paths below this weight end (and are counted as pruned).
    pub min_weight: f32,
}

/// A path segment waiting to be traced.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    origin: Vec3,
    dir: Vec3,
    weight: f32,
    sig: u64,
    interactions: u32,
    inside: bool,
    reflected_first: bool,
}

fn mix(sig: u64, event: u64) -> u64 {
    // splitmix64 finaliser over the running hash and the event.
    let mut z =
        (sig ^ event.wrapping_mul(0x9E37_79B9_7F4A_7C15)).wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

impl Tracer {
    /// Checks and prepares a scene for a `width_px` x `height_px` floor texture.
    pub fn new(
        scene: &CausticScene,
        width_px: u32,
        height_px: u32,
        max_interactions: u32,
        min_weight: f32,
    ) -> Result<Self, InputError> {
        if !(scene.ior.is_finite() && scene.ior >= 1.0) {
            return Err(InputError::BadValue(format!(
                "the refractive index must be a finite number >= 1, found {}",
                scene.ior
            )));
        }
        if !scene.light_position_m.is_finite() {
            return Err(InputError::BadValue(format!(
                "the light position {} is not finite",
                scene.light_position_m
            )));
        }
        let m = scene.world_from_floor;
        let corners = [m.x_axis, m.y_axis, m.w_axis].map(|c| c.truncate());
        if !corners.iter().all(|c| c.is_finite()) {
            return Err(InputError::BadValue(
                "the floor transform is not finite".into(),
            ));
        }
        // Bounding sphere: the bounding-box centre and the farthest vertex.
        let (lo, hi) = scene
            .positions_m
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(l, h), &p| {
                (l.min(p), h.max(p))
            });
        let center = if lo.is_finite() {
            (lo + hi) / 2.0
        } else {
            Vec3::ZERO
        };
        let local: Vec<Vec3> = scene.positions_m.iter().map(|&p| p - center).collect();
        let solid = Solid::new(&local, &scene.normals, &scene.indices)?;
        let radius_m = solid
            .triangles_m
            .iter()
            .flatten()
            .map(|p| p.length())
            .fold(0.0f32, f32::max);

        let floor = floor_frame(&m, center, width_px, height_px)?;
        let light = scene.light_position_m - center;
        let height_m = (light - floor.origin).dot(floor.normal);
        if height_m.is_nan() || height_m <= 0.0 {
            return Err(InputError::LightBelowFloor { height_m });
        }
        let bvh = Bvh::new(&solid.triangles_m);
        let tracer = Tracer {
            solid,
            bvh,
            ior: scene.ior,
            light,
            radius_m,
            floor,
            eps_m: radius_m * 2e-5,
            max_interactions,
            min_weight,
        };
        if tracer.contains(light) {
            return Err(InputError::LightInsideObject {
                light_m: scene.light_position_m,
            });
        }
        Ok(tracer)
    }

    /// Whether a point is inside the solid: crossing parity, majority of three directions
    /// (a ray through an edge or vertex can miscount once).
    fn contains(&self, p: Vec3) -> bool {
        if p.length() > self.radius_m {
            return false;
        }
        let dirs = [
            Vec3::new(0.5377, 0.8321, 0.1357),
            Vec3::new(-0.6231, 0.2219, -0.7501),
            Vec3::new(0.1113, -0.9123, 0.3941),
        ];
        dirs.iter()
            .filter(|d| self.bvh.count_hits(p, d.normalize()) % 2 == 1)
            .count()
            >= 2
    }

    /// Traces the grid ray leaving the light in unit direction `dir`; appends its leaves,
    /// sorted by signature, to `leaves`.
    pub fn trace(&self, dir: Vec3, leaves: &mut Vec<Leaf>, stack: &mut Vec<Ray>) -> Corner {
        let first_leaf = leaves.len() as u32;
        // Start just outside the bounding sphere: the f32 hit points stay precise even for a
        // light far away.
        let dist = self.light.length();
        let advance = (dist - 1.05 * self.radius_m).max(0.0);
        let origin = self.light + dir * advance;
        let straight_t = self.floor.hit_t(origin, dir);
        let straight = straight_t.and_then(|t| self.floor.texel(origin + dir * t));
        let mut corner = Corner {
            hit: false,
            straight,
            first_leaf,
            leaf_count: 0,
        };

        let Some(hit) = self
            .bvh
            .closest(origin, dir, straight_t.unwrap_or(f32::INFINITY))
        else {
            return corner;
        };
        corner.hit = true;
        stack.clear();
        let root = Ray {
            origin,
            dir,
            weight: 1.0,
            sig: 0x5EED_CA05_71C5_0001,
            interactions: 0,
            inside: false,
            reflected_first: false,
        };
        self.interact(&root, hit, leaves, stack);
        while let Some(ray) = stack.pop() {
            let floor_t = if ray.inside {
                None
            } else {
                self.floor.hit_t(ray.origin, ray.dir)
            };
            match self
                .bvh
                .closest(ray.origin, ray.dir, floor_t.unwrap_or(f32::INFINITY))
            {
                Some(hit) => self.interact(&ray, hit, leaves, stack),
                None => {
                    let end = match floor_t {
                        Some(t) => match self.floor.texel(ray.origin + ray.dir * t) {
                            Some(px) => End::Floor(px),
                            None => End::Away,
                        },
                        // Includes a ray leaking out of the inside through a crack.
                        None => End::Away,
                    };
                    leaves.push(Leaf {
                        sig: ray.sig,
                        weight: ray.weight,
                        reflected_first: ray.reflected_first,
                        end,
                    });
                }
            }
        }
        let mine = &mut leaves[first_leaf as usize..];
        mine.sort_unstable_by_key(|l| l.sig);
        corner.leaf_count = mine.len() as u32;
        corner
    }

    /// Splits `ray` at the surface point `hit` into its reflected and refracted parts.
    fn interact(&self, ray: &Ray, hit: Hit, leaves: &mut Vec<Leaf>, stack: &mut Vec<Ray>) {
        let leaf = |end| Leaf {
            sig: ray.sig,
            weight: ray.weight,
            reflected_first: ray.reflected_first,
            end,
        };
        if ray.interactions >= self.max_interactions {
            leaves.push(leaf(End::Limit));
            return;
        }
        let ti = hit.triangle as usize;
        let tri = &self.solid.triangles_m[ti];
        let point = ray.origin + ray.dir * hit.t_m;
        let geometric = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize();
        let [n0, n1, n2] = self.solid.corner_normals[ti];
        let shading = ((1.0 - hit.u - hit.v) * n0 + hit.u * n1 + hit.v * n2).normalize_or_zero();
        let entering = ray.dir.dot(geometric) < 0.0;
        // Normals on the incident side.
        let side_g = if entering { geometric } else { -geometric };
        let side_s = if entering { shading } else { -shading };
        let side_s = if side_s.dot(ray.dir) < 0.0 && side_s.dot(side_g) > 0.0 {
            side_s
        } else {
            side_g
        };
        let eta = if entering { 1.0 / self.ior } else { self.ior };
        let cos_i = -ray.dir.dot(side_s);
        let reflectance = fresnel_reflectance(cos_i, eta);

        let patch = self.solid.patch[ti] as u64;
        let interactions = ray.interactions + 1;
        let mut push = |dir: Vec3, weight: f32, event: u64, crossed: bool| {
            if weight <= 0.0 {
                return;
            }
            let child = Ray {
                origin: point + if crossed { -side_g } else { side_g } * self.eps_m,
                dir,
                weight,
                sig: mix(ray.sig, patch << 1 | event),
                interactions,
                inside: ray.inside ^ crossed,
                reflected_first: if ray.interactions == 0 {
                    event == 0
                } else {
                    ray.reflected_first
                },
            };
            if weight < self.min_weight {
                leaves.push(Leaf {
                    sig: child.sig,
                    weight,
                    reflected_first: child.reflected_first,
                    end: End::Pruned,
                });
            } else {
                stack.push(child);
            }
        };

        // A shading normal may bend a ray to the wrong side of the real surface: fall back
        // to the geometric normal then.
        let mut r = reflect(ray.dir, side_s);
        if r.dot(side_g) <= 0.0 {
            r = reflect(ray.dir, side_g);
        }
        let t = refract(ray.dir, side_s, eta).map(|t| {
            if t.dot(side_g) < 0.0 {
                t
            } else {
                refract(ray.dir, side_g, eta).unwrap_or(t)
            }
        });
        match t {
            Some(t) if t.dot(side_g) < 0.0 => {
                push(r, ray.weight * reflectance, 0, false);
                push(t, ray.weight * (1.0 - reflectance), 1, true);
            }
            _ => push(r, ray.weight, 0, false),
        }
    }
}

fn floor_frame(
    m: &Mat4,
    center: Vec3,
    width_px: u32,
    height_px: u32,
) -> Result<FloorFrame, InputError> {
    let axis_x = m.x_axis.truncate();
    let axis_y = m.y_axis.truncate();
    let area_m2 = axis_x.cross(axis_y).length();
    if area_m2.is_nan() || area_m2 <= 1e-12 {
        return Err(InputError::ZeroAreaFloor { area_m2 });
    }
    let (gxx, gxy, gyy) = (axis_x.dot(axis_x), axis_x.dot(axis_y), axis_y.dot(axis_y));
    let det = gxx * gyy - gxy * gxy;
    let normal_local = m.z_axis.truncate();
    let mut normal = axis_x.cross(axis_y).normalize();
    if normal_local.length_squared() > 0.0 && normal.dot(normal_local) < 0.0 {
        normal = -normal;
    }
    Ok(FloorFrame {
        origin: m.w_axis.truncate() - center,
        normal,
        axis_x,
        axis_y,
        gram_inv: [gyy / det, -gxy / det, -gxy / det, gxx / det],
        width_px,
        height_px,
    })
}
