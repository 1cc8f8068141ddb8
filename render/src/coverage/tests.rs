//! The proof against the rays themselves: sampled 8 times finer than the proof, no covered
//! tile holds a ray beside the photo; the rays left out carry under 1e-4 of the light; the
//! split draws each pixel once.

use super::*;
use proptest::prelude::*;

/// The visual-effects scene's glass (render/../config/scenes/visual-effects.toml): a
/// 15 cm ball of n = 1.51 0.2 m ahead, a 0.6 m photo 0.4 m ahead.
fn scene(model: Refraction, photo_m: f32) -> PhotoCoverage {
    let world_from_plane = Mat4::from_scale_rotation_translation(
        Vec3::new(photo_m, photo_m, 1.0),
        glam::Quat::IDENTITY,
        Vec3::new(0.0, 0.0, -0.4),
    );
    PhotoCoverage {
        center: Vec3::ZERO,
        radius: 1.0,
        ior: 1.51,
        model,
        background_from_world: world_from_plane.inverse(),
    }
}

fn ball_at(position_m: Vec3) -> Mat4 {
    Mat4::from_scale_rotation_translation(Vec3::splat(0.075), glam::Quat::IDENTITY, position_m)
}

const IPD_M: f32 = 0.063;

/// Two eyes at `head_m` looking down -z turned by `yaw`, seeing the scene's 40 x 30 degrees.
fn eyes(head_m: Vec3, yaw: f32) -> [EyeParams; 2] {
    let (h, v) = (20f32.to_radians(), 15f32.to_radians());
    let fov = vitreous_optics::camera::Fov {
        left_rad: -h,
        right_rad: h,
        up_rad: v,
        down_rad: -v,
    };
    let turn = glam::Quat::from_rotation_y(yaw);
    [-1.0, 1.0].map(|side| EyeParams::new(head_m + turn * Vec3::X * side * IPD_M / 2.0, turn, fov))
}

/// Refraction seen from each eye (disparity) or from between them.
fn origins(eyes: &[EyeParams; 2], disparity: bool) -> [Vec3; 2] {
    if disparity {
        eyes.each_ref().map(|e| e.position_m)
    } else {
        [(eyes[0].position_m + eyes[1].position_m) / 2.0; 2]
    }
}

/// The image size the tests prove for.
const EXTENT: (u32, u32) = (320, 240);

/// Each eye's covered tiles.
fn tiles(
    coverage: &PhotoCoverage,
    world_from_model: Mat4,
    eyes: &[EyeParams; 2],
    origins: [Vec3; 2],
) -> [Tiles; 2] {
    [0, 1].map(|i| coverage.covered_tiles(world_from_model, &eyes[i], origins[i], EXTENT))
}

/// The tile of each eye's image where a ray through the ball misses the photo, among the
/// points of the cap sampled 8 times finer than the proof (but for those the proof leaves
/// out: within `grazing_cos` of grazing): for each eye, `(col, row)` of every such tile.
fn dense_misses(
    coverage: &PhotoCoverage,
    world_from_model: Mat4,
    eyes: &[EyeParams; 2],
    origins: [Vec3; 2],
) -> [Vec<(u32, u32)>; 2] {
    let center = world_from_model.transform_point3(coverage.center);
    let radius = uniform_scale(world_from_model).unwrap() * coverage.radius;
    [0, 1].map(|i| {
        let (eye, origin) = (&eyes[i], origins[i]);
        let position = eye.position_m;
        let to_eye = (position - center).normalize();
        let (across, up) = to_eye.any_orthonormal_pair();
        let (rings, spokes) = (8 * RINGS, 8 * SPOKES);
        let mut misses = Vec::new();
        for ring in 0..=rings {
            for spoke in 0..spokes {
                let a = std::f32::consts::FRAC_PI_2 * ring as f32 / rings as f32;
                let b = std::f32::consts::TAU * spoke as f32 / spokes as f32;
                let normal = a.cos() * to_eye + a.sin() * (b.cos() * across + b.sin() * up);
                let point = center + radius * normal;
                let cos_in = (position - point).normalize().dot(normal);
                let clip = eye.clip_from_world() * point.extend(1.0);
                let ndc = clip.truncate().truncate() / clip.w;
                // Two surfaces: a ray that grazes the ball from the refraction origin
                // passes as little light as one that grazes it from the eye.
                let cos_origin = (point - origin).normalize().dot(normal).abs();
                let least = coverage.grazing_cos();
                let grazing = cos_in < least
                    || (coverage.model == Refraction::TwoSurface && cos_origin < least);
                if grazing || clip.w <= 0.0 || ndc.abs().max_element() >= 1.0 {
                    continue;
                }
                let on_photo = coverage
                    .landing(center, point, normal, position, origin)
                    .is_some_and(|uv| uv.cmpge(Vec2::ZERO).all() && uv.cmple(Vec2::ONE).all());
                if !on_photo {
                    let pixel = (ndc + 1.0) * 0.5 * Vec2::new(EXTENT.0 as f32, EXTENT.1 as f32);
                    let at = tile_at(pixel);
                    if !misses.contains(&at) {
                        misses.push(at);
                    }
                }
            }
        }
        misses
    })
}

/// The tile of an image of `EXTENT` that holds `pixel`.
fn tile_at(pixel: Vec2) -> (u32, u32) {
    let tile = |x: f32, size: u32| {
        (0..TILES)
            .rev()
            .find(|&t| tiles::edge(t, size) as f32 <= x)
            .unwrap_or(0)
    };
    (tile(pixel.x, EXTENT.0), tile(pixel.y, EXTENT.1))
}

/// The first miss (eye, column, row) in a tile the proof covers, if any.
fn covered_miss(tiles: &[Tiles; 2], misses: &[Vec<(u32, u32)>; 2]) -> Option<(usize, u32, u32)> {
    (0..2).find_map(|eye| {
        misses[eye]
            .iter()
            .find(|&&(col, row)| tiles[eye].contains(col, row))
            .map(|&(col, row)| (eye, col, row))
    })
}

#[test]
fn the_study_scene_is_covered_from_its_viewing_position_in_the_papers_model() {
    let coverage = scene(Refraction::Paper, 0.6);
    let ball = ball_at(Vec3::new(0.0, 0.0, -0.2));
    for disparity in [false, true] {
        let eyes = eyes(Vec3::ZERO, 0.0);
        let origins = origins(&eyes, disparity);
        assert_eq!(tiles(&coverage, ball, &eyes, origins), [Tiles::ALL; 2]);
    }
}

#[test]
fn two_surfaces_bend_the_rim_beside_the_photo_in_the_corners_only() {
    let coverage = scene(Refraction::TwoSurface, 0.6);
    let ball = ball_at(Vec3::new(0.0, 0.0, -0.2));
    let eyes = eyes(Vec3::ZERO, 0.0);
    let origins = origins(&eyes, true);
    let tiles = tiles(&coverage, ball, &eyes, origins);
    let misses = dense_misses(&coverage, ball, &eyes, origins);
    assert_eq!(covered_miss(&tiles, &misses), None);
    for eye in 0..2 {
        assert!(
            !misses[eye].is_empty(),
            "eye {eye}: the rim's rays miss the photo"
        );
        // The middle of the image is proved.
        for (col, row) in [(15, 15), (16, 16), (15, 16), (16, 15)] {
            assert!(
                tiles[eye].contains(col, row),
                "eye {eye}: tile {col}, {row}"
            );
        }
    }
}

#[test]
fn a_photo_whose_edge_shows_through_the_ball_loses_the_tiles_that_see_past_it() {
    for model in [Refraction::Paper, Refraction::TwoSurface] {
        // A 5 cm photo: most rays through the ball pass beside it.
        let coverage = scene(model, 0.05);
        let ball = ball_at(Vec3::new(0.0, 0.0, -0.2));
        let eyes = eyes(Vec3::ZERO, 0.0);
        let origins = origins(&eyes, true);
        let tiles = tiles(&coverage, ball, &eyes, origins);
        let misses = dense_misses(&coverage, ball, &eyes, origins);
        assert!(misses.iter().all(|m| m.len() > 10), "{model:?}");
        assert_eq!(covered_miss(&tiles, &misses), None, "{model:?}");
    }
}

#[test]
fn no_proof_for_an_eye_inside_the_ball_or_a_stretched_ball() {
    let coverage = scene(Refraction::Paper, 0.6);
    let eyes = eyes(Vec3::ZERO, 0.0);
    let origins = origins(&eyes, true);
    let inside = ball_at(Vec3::new(0.0, 0.0, -0.05));
    assert_eq!(tiles(&coverage, inside, &eyes, origins), [Tiles::NONE; 2]);
    let stretched = Mat4::from_scale_rotation_translation(
        Vec3::new(0.075, 0.08, 0.075),
        glam::Quat::IDENTITY,
        Vec3::new(0.0, 0.0, -0.2),
    );
    assert_eq!(
        tiles(&coverage, stretched, &eyes, origins),
        [Tiles::NONE; 2]
    );
}

#[test]
fn the_rays_left_out_carry_under_1e4_of_the_light() {
    let incident = |cos: f32| Vec3::new((1.0 - cos * cos).sqrt(), 0.0, -cos);
    // The paper's model: the refracted image is weighted by 1 - F, F the empirical term.
    let paper = scene(Refraction::Paper, 0.6);
    let cos = paper.grazing_cos();
    assert!(1.0 - vitreous_optics::optics::fresnel(incident(cos), Vec3::Z) < 1e-4);
    assert!(1.0 - vitreous_optics::optics::fresnel(incident(cos * 10.0), Vec3::Z) > 1e-4);
    // Two surfaces: a ball's exit meets the surface as the entry did, so the light passed
    // is (1 - F)^2, F exact.
    let two = scene(Refraction::TwoSurface, 0.6);
    let passed =
        |cos: f32| (1.0 - vitreous_optics::optics::fresnel_reflectance(cos, 1.0 / two.ior)).powi(2);
    assert!(
        passed(two.grazing_cos()) < 1e-4,
        "{}",
        passed(two.grazing_cos())
    );
    assert!(passed(two.grazing_cos() * 10.0) > 1e-4);
}

/// Every pixel of `shown` tiles drawn once by `split` of `extent`, none twice, and those
/// drawn without the lookup in `covered` tiles only.
fn check_split(covered: Tiles, shown: Tiles, split: &Split, extent: (u32, u32)) {
    let tile_of = |x: u32, y: u32| {
        let tile = |p: u32, size: u32| (0..TILES).rev().find(|&t| tiles::edge(t, size) <= p);
        (tile(x, extent.0).unwrap(), tile(y, extent.1).unwrap())
    };
    let mut owner = vec![0u32; (extent.0 * extent.1) as usize];
    for (rects, without) in [(&split.covered, true), (&split.rest, false)] {
        for &[x, y, w, h] in rects {
            assert!(w > 0 && h > 0, "{:?}", [x, y, w, h]);
            for py in y..y + h {
                for px in x..x + w {
                    owner[(py * extent.0 + px) as usize] += 1;
                    let (col, row) = tile_of(px, py);
                    assert!(!without || covered.contains(col, row), "{px}, {py}");
                }
            }
        }
    }
    for py in 0..extent.1 {
        for px in 0..extent.0 {
            let (col, row) = tile_of(px, py);
            let n = owner[(py * extent.0 + px) as usize];
            assert!(n <= 1, "{px}, {py} drawn {n} times");
            assert!(n == 1 || !shown.contains(col, row), "{px}, {py} not drawn");
        }
    }
}

#[test]
fn the_split_draws_each_shown_pixel_once_and_covered_tiles_only_without_the_lookup() {
    let extent = (401, 317);
    assert_eq!(
        Tiles::ALL.split(Tiles::ALL, extent, 40_000),
        Split {
            covered: vec![[0, 0, 401, 317]],
            rest: vec![],
        }
    );
    assert_eq!(
        Tiles::NONE.split(Tiles::ALL, extent, 40_000),
        Split {
            covered: vec![],
            rest: vec![[0, 0, 401, 317]],
        }
    );
    assert_eq!(Tiles::NONE.split(Tiles::NONE, extent, 0), Split::default());
    // A ball seen whole through two surfaces: a disc of glass, its rim a ring of tiles whose
    // rays pass beside the photo.
    let (mut covered, mut shown) = (Tiles::ALL, Tiles::NONE);
    for row in 0..TILES {
        for col in 0..TILES {
            let r = ((col as f32 - 15.5).powi(2) + (row as f32 - 15.5).powi(2)).sqrt();
            if r < 14.0 {
                shown.put_in(col, row);
            }
            if (11.0..14.0).contains(&r) {
                covered.take_out(col, row);
            }
        }
    }
    // Draws for free: four rectangles inside the ring hold most of its covered tiles.
    let split = covered.split(shown, extent, 0);
    check_split(covered, shown, &split, extent);
    // Four rectangles inside the ring hold 85 % of its covered tiles.
    let area = |rects: &[[u32; 4]]| rects.iter().map(|r| r[2] * r[3]).sum::<u32>();
    let inside = (0..TILES * TILES)
        .filter(|i| covered.and(shown).contains(i % TILES, i / TILES))
        .count() as f32;
    let tile_px = (extent.0 * extent.1) as f32 / (TILES * TILES) as f32;
    let share = area(&split.covered) as f32 / tile_px / inside;
    assert_eq!(split.covered.len(), 4);
    assert!(share > 0.8, "{share}");
    let draws_free = split.covered.len() + split.rest.len();
    // The ring and what is left around the rectangles, drawn in ten more.
    assert!(split.rest.len() <= 10, "{:?}", split.rest);
    // A draw dearer than the image: one draw, with the lookup, taking in the whole disc.
    let dear = covered.split(shown, extent, u64::from(extent.0 * extent.1));
    check_split(covered, shown, &dear, extent);
    assert_eq!((dear.covered.len(), dear.rest.len()), (0, 1), "{dear:?}");
    // In between, fewer draws, more of them without the lookup than with it.
    let between = covered.split(shown, extent, u64::from(extent.0 * extent.1) / 40);
    check_split(covered, shown, &between, extent);
    let draws = between.covered.len() + between.rest.len();
    assert!((2..draws_free).contains(&draws), "{between:?}");
}

/// The tiles of each eye's image where a point of the ball, sampled densely over the whole
/// sphere, shows (in front of the eye, inside the image).
fn dense_shown(world_from_model: Mat4, eye: &EyeParams) -> Vec<(u32, u32)> {
    let center = world_from_model.transform_point3(Vec3::ZERO);
    let radius = uniform_scale(world_from_model).unwrap();
    let mut shown = Vec::new();
    for ring in 0..=400 {
        for spoke in 0..800 {
            let a = std::f32::consts::PI * ring as f32 / 400.0;
            let b = std::f32::consts::TAU * spoke as f32 / 800.0;
            let normal = Vec3::new(a.sin() * b.cos(), a.cos(), a.sin() * b.sin());
            let size = Vec2::new(EXTENT.0 as f32, EXTENT.1 as f32);
            let Some(pixel) = eye.project_to_pixel(center + radius * normal, size) else {
                continue;
            };
            if pixel.cmplt(Vec2::ZERO).any() || pixel.cmpge(size).any() {
                continue;
            }
            let at = tile_at(pixel);
            if !shown.contains(&at) {
                shown.push(at);
            }
        }
    }
    shown
}

#[test]
fn a_ball_seen_whole_shows_in_a_disc_of_tiles() {
    let coverage = scene(Refraction::TwoSurface, 0.6);
    // A 15 cm ball 0.6 m ahead, slightly right and up: about 14 degrees across, a disc of
    // about 11 tiles across in the 40 degree wide image.
    let ball = ball_at(Vec3::new(0.05, 0.03, -0.6));
    let eye = eyes(Vec3::ZERO, 0.0)[0];
    let shown = coverage.shown_tiles(ball, &eye, EXTENT);
    let dense = dense_shown(ball, &eye);
    for &(col, row) in &dense {
        assert!(shown.contains(col, row), "{col}, {row}");
    }
    // A tile more is shown only along the disc's edge: no bounding box's corners.
    let (n, m) = (shown.count() as f32, dense.len() as f32);
    // (164 for 163 here; the box of the four sides alone, 192.)
    assert!(n < m * 1.1, "{n} tiles shown for {m}");
    let stretched = Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0)) * ball;
    assert_eq!(coverage.shown_tiles(stretched, &eye, EXTENT), Tiles::ALL);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// Any two sets of tiles are split so that each shown pixel is drawn once, without the
    /// lookup only in covered tiles, in at most four rectangles without it.
    #[test]
    fn any_split_draws_each_shown_pixel_once(
        covered in prop::collection::vec(any::<bool>(), (TILES * TILES) as usize),
        shown in prop::collection::vec(any::<bool>(), (TILES * TILES) as usize),
        width in 32u32..300,
        height in 32u32..300,
        draw_px in 0u64..100_000,
    ) {
        let set = |bits: &[bool]| {
            let mut tiles = Tiles::NONE;
            for (i, _) in bits.iter().enumerate().filter(|(_, on)| **on) {
                tiles.put_in(i as u32 % TILES, i as u32 / TILES);
            }
            tiles
        };
        let (covered, shown) = (set(&covered), set(&shown));
        let split = covered.split(shown, (width, height), draw_px);
        check_split(covered, shown, &split, (width, height));
        prop_assert!(split.covered.len() <= 4);
    }

    /// Soundness: no ray of a cap sampled 8 times finer than the proof's misses the photo
    /// in a covered tile; the head, ball and photo vary far enough that tiles are lost.
    #[test]
    fn a_covered_tile_has_no_ray_beside_the_photo(
        head in prop::array::uniform3(-0.15f32..0.15),
        ball in prop::array::uniform3(-0.1f32..0.1),
        yaw in -0.5f32..0.5,
        spin in -3.0f32..3.0,
        photo_m in 0.1f32..0.8,
        two_surface in any::<bool>(),
        disparity in any::<bool>(),
    ) {
        let model = if two_surface { Refraction::TwoSurface } else { Refraction::Paper };
        let coverage = scene(model, photo_m);
        let world_from_model = ball_at(Vec3::new(ball[0], ball[1], ball[2] - 0.2))
            * Mat4::from_rotation_z(spin);
        let eyes = eyes(Vec3::from_array(head), yaw);
        let origins = origins(&eyes, disparity);
        let tiles = tiles(&coverage, world_from_model, &eyes, origins);
        let misses = dense_misses(&coverage, world_from_model, &eyes, origins);
        prop_assert_eq!(covered_miss(&tiles, &misses), None);
    }

    /// No point of the ball shows in a tile left out of those it shows in, the ball anywhere
    /// about the eyes, behind them or around them included.
    #[test]
    fn a_ball_shows_in_no_tile_left_out(
        head in prop::array::uniform3(-0.15f32..0.15),
        ball in prop::array::uniform3(-0.5f32..0.5),
        size in 0.01f32..0.3,
        yaw in -3.0f32..3.0,
    ) {
        let coverage = scene(Refraction::Paper, 0.6);
        let world_from_model = Mat4::from_scale_rotation_translation(
            Vec3::splat(size),
            glam::Quat::IDENTITY,
            Vec3::from_array(ball),
        );
        let eye = eyes(Vec3::from_array(head), yaw)[1];
        let shown = coverage.shown_tiles(world_from_model, &eye, EXTENT);
        for (col, row) in dense_shown(world_from_model, &eye) {
            prop_assert!(shown.contains(col, row), "{}, {}", col, row);
        }
    }
}
