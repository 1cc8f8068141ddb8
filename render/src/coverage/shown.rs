//! The tiles of an eye's image a ball may show in: those whose pixels' frustum the ball
//! reaches. The glass pass draws no other tile, so the test errs only towards showing.

use glam::Vec3;
use vitreous_optics::camera::EyeParams;

use super::tiles::{TILES, Tiles, edge};

/// The tiles of the image of `eye` (`extent` pixels) that the ball about `center` (world) of
/// `radius` may show in. A tile is left out where its frustum (its pixels' box, grown by a
/// pixel) lies wholly outside the ball: the ball's centre is farther than the radius beyond one
/// of the frustum's four sides, or beyond the edge where a column's side meets a row's.
pub fn shown_tiles(center: Vec3, radius: f32, eye: &EyeParams, extent: (u32, u32)) -> Tiles {
    let center = eye.view_from_world.transform_point3(center).extend(1.0);
    // Room for rounding in the ball and in the transforms.
    let radius = radius * (1.0 + 1e-3);
    let clip = eye.clip_from_view;
    // The side `sign` (1: towards greater coordinates) of the line where normalised device
    // coordinate `axis` is `at`, as a plane through the eye: its unit normal pointing into the
    // side, and the centre's distance into it. A point of the ball the eye sees there (clip w
    // above 0) lies on that side, so a centre farther out than the radius shows nothing there.
    let side = |axis: usize, at: f32, sign: f32| {
        let plane = (clip.row(axis) - clip.row(3) * at) * sign;
        let length = plane.truncate().length();
        Side {
            normal: plane.truncate() / length,
            into: plane.dot(center) / length,
        }
    };
    // Each tile's sides along each axis: its first pixel's edge, less a pixel, towards
    // greater coordinates, and its end's, plus a pixel, towards smaller ones.
    let sides = |axis: usize, size: u32| -> Vec<[Side; 2]> {
        let ndc = |px: f32| 2.0 * px / size as f32 - 1.0;
        (0..TILES)
            .map(|t| {
                let (first, end) = (edge(t, size) as f32, edge(t + 1, size) as f32);
                [
                    side(axis, ndc(first - 1.0), 1.0),
                    side(axis, ndc(end + 1.0), -1.0),
                ]
            })
            .collect()
    };
    let (cols, rows) = (sides(0, extent.0), sides(1, extent.1));
    let centre = center.truncate();
    let mut shown = Tiles::NONE;
    for (row, row_sides) in rows.iter().enumerate() {
        for (col, col_sides) in cols.iter().enumerate() {
            let all = col_sides.iter().chain(row_sides);
            let reached = all.clone().all(|s| s.into >= -radius)
                && col_sides.iter().all(|a| {
                    row_sides
                        .iter()
                        .all(|b| wedge_distance(a, b, centre) <= radius)
                });
            if reached {
                shown.put_in(col as u32, row as u32);
            }
        }
    }
    shown
}

/// One side of a plane through the eye (the view's origin).
#[derive(Clone, Copy)]
struct Side {
    /// Unit normal, pointing into the side.
    normal: Vec3,
    /// The ball's centre's signed distance into the side.
    into: f32,
}

/// The distance from `point` (view frame, its distances into `a` and `b` given) to the wedge
/// where the sides `a` and `b` meet: 0 inside it; beyond one side only, or where the nearest
/// point of a side's plane lies on the other side, the distance to that plane; else the
/// distance to the edge where the two planes meet.
fn wedge_distance(a: &Side, b: &Side, point: Vec3) -> f32 {
    if a.into >= 0.0 && b.into >= 0.0 {
        return 0.0;
    }
    let cos = a.normal.dot(b.normal);
    // The nearest point of a's plane, moved -a.into along a's normal, lies on b's side when
    // b.into - a.into cos >= 0; b's alike.
    if a.into < 0.0 && b.into - a.into * cos >= 0.0 {
        return -a.into;
    }
    if b.into < 0.0 && a.into - b.into * cos >= 0.0 {
        return -b.into;
    }
    let along = a.normal.cross(b.normal);
    let length = along.length();
    if length < 1e-12 {
        return -a.into.min(b.into);
    }
    point.cross(along / length).length()
}
