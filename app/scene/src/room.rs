//! `[environment] room = true`: the environment map with the room the scene registers in it.
//! Every direction of the latitude-longitude map that, seen from the object's centre, meets the
//! floor or the background photo takes that photo's linear radiance (the nearer of the two);
//! the map's own HDR radiance stays where neither lies. Rays the glass sends towards the
//! environment (refraction that misses the background photo, reflection) then show the real
//! floor and wall instead of an unrelated scene. The map is at infinity: a ray leaving the
//! object away from its centre sees the photos with the parallax of that offset ignored.

use glam::{Vec2, Vec3};

use crate::{Image, PixelData, RealPlane};
use vitreous_optics::srgb::to_linear as linear;

/// The unit direction of texel centre `(x, y)` of a `w` x `h` latitude-longitude map: u = 0.5
/// looks down -z, u grows towards +x, v = 0 straight up (shaders/glass.wgsl `latlong_uv`).
fn direction(x: u32, y: u32, w: u32, h: u32) -> Vec3 {
    let u = (x as f32 + 0.5) / w as f32;
    let v = (y as f32 + 0.5) / h as f32;
    let azimuth = (u - 0.5) * std::f32::consts::TAU;
    let polar = v * std::f32::consts::PI;
    Vec3::new(
        polar.sin() * azimuth.sin(),
        polar.cos(),
        -polar.sin() * azimuth.cos(),
    )
}

/// Where the ray from `origin` along `dir` meets the plane's photo: the distance and the photo
/// coordinate (u right, v down).
fn hit(plane: &RealPlane, origin: Vec3, dir: Vec3) -> Option<(f32, Vec2)> {
    let plane_from_world = plane.world_from_plane().inverse();
    let o = plane_from_world.transform_point3(origin);
    let d = plane_from_world.transform_vector3(dir);
    if d.z.abs() < 1e-12 {
        return None;
    }
    let t = -o.z / d.z;
    let p = o + d * t;
    (t > 0.0 && p.x.abs() <= 0.5 && p.y.abs() <= 0.5).then(|| (t, Vec2::new(p.x + 0.5, 0.5 - p.y)))
}

/// The photo's linear RGB at `uv` (nearest texel).
fn sample(photo: &Image, uv: Vec2) -> Option<[f32; 3]> {
    let PixelData::Srgb8(bytes) = &photo.data else {
        return None;
    };
    let x = ((uv.x * photo.width as f32) as u32).min(photo.width - 1);
    let y = ((uv.y * photo.height as f32) as u32).min(photo.height - 1);
    let i = ((y * photo.width + x) * 4) as usize;
    Some([linear(bytes[i]), linear(bytes[i + 1]), linear(bytes[i + 2])])
}

/// `map` (linear RGBA f32) with the floor and background photos seen from `center` written in.
pub fn with_room(map: &Image, center: Vec3, floor: &RealPlane, background: &RealPlane) -> Image {
    let PixelData::LinearF32(pixels) = &map.data else {
        return map.clone();
    };
    let (w, h) = (map.width, map.height);
    let mut out = pixels.clone();
    for y in 0..h {
        for x in 0..w {
            let dir = direction(x, y, w, h);
            let seen = [floor, background]
                .into_iter()
                .filter_map(|p| hit(p, center, dir).map(|(t, uv)| (t, p, uv)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some(rgb) = seen.and_then(|(_, p, uv)| sample(&p.photo, uv)) {
                let i = ((y * w + x) * 4) as usize;
                out[i..i + 3].copy_from_slice(&rgb);
            }
        }
    }
    Image {
        width: w,
        height: h,
        data: PixelData::LinearF32(out),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;
    use vitreous_trace::Pose;

    fn plane(level: u8, position: Vec3, orientation: Quat) -> RealPlane {
        RealPlane {
            photo: Image::new(2, 2, PixelData::Srgb8([level, level, level, 255].repeat(4)))
                .unwrap(),
            size_m: Vec2::new(1.0, 1.0),
            pose: Pose {
                position,
                orientation,
            },
        }
    }

    #[test]
    fn directions_to_the_floor_and_wall_show_their_photos_and_the_rest_keeps_the_map() {
        let (w, h) = (64u32, 32u32);
        let map = Image::new(
            w,
            h,
            PixelData::LinearF32([5.0, 5.0, 5.0, 1.0].repeat(64 * 32)),
        )
        .unwrap();
        // A floor 0.3 m below the object and a wall 0.5 m ahead of it.
        let floor = plane(
            255,
            Vec3::new(0.0, -0.3, 0.0),
            Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        );
        let wall = plane(0, Vec3::new(0.0, 0.0, -0.5), Quat::IDENTITY);
        let room = with_room(&map, Vec3::ZERO, &floor, &wall);
        let PixelData::LinearF32(px) = &room.data else {
            unreachable!()
        };
        let at = |x: u32, y: u32| px[((y * w + x) * 4) as usize];
        // Straight down (last row): the white floor; straight ahead (u = 0.5, v = 0.5): the
        // black wall; straight up and straight behind: the map.
        assert_eq!(at(w / 2, h - 1), 1.0);
        assert_eq!(at(w / 2, h / 2), 0.0);
        assert_eq!(at(w / 2, 0), 5.0);
        assert_eq!(at(0, h / 2), 5.0);
        // The direction matches the glass shader's lookup: u = 0.5 looks down -z.
        let ahead = direction(w / 2, h / 2, w, h);
        assert!(ahead.z < -0.99, "{ahead}");
    }
}
