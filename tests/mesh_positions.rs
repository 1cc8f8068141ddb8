//! The positions a mesh's pixels shade (`[output] glass_samples`, shaders/shared/glass_positions
//! .wgsl), counted on the machine's Vulkan device with validation on: every position of a pixel's
//! grid is shaded (on lavapipe, whose loop limiter would end a pixel's loops early without a
//! word where a mesh's searches ran too many rounds), and a grid twice as fine only where the
//! first grid's positions disagree.

use vitreous_optics::display::Compensation;
use vitreous_render::{Composition, MeshSearch, Want};
use vitreous_scene::Scene;
use vitreous_tests::{compose_once, neutral_eyes, plain_params, scene_renderer, torus_in_the_room};

const SIZE: (u32, u32) = (320, 240);

/// What the glass's searches and positions counted over one frame of `scene` at the neutral
/// head's left eye (both eyes there), no effects, eq. 6 off.
fn counted(scene: &Scene) -> MeshSearch {
    let mut renderer = scene_renderer(scene, SIZE.0, SIZE.1);
    assert!(
        renderer.count_invocations().unwrap(),
        "this device counts no invocations"
    );
    let params = plain_params(neutral_eyes(scene)[0]);
    let want = Want {
        eyes: false,
        world: false,
    };
    let frame = compose_once(&mut renderer, &params, want, Composition::Additive);
    frame.work.glass_mesh.expect("the mesh's searches counted")
}

fn torus(samples: u32) -> Scene {
    let dir = tempfile::tempdir().unwrap();
    let mut scene = torus_in_the_room(dir.path());
    scene.output.glass_samples = samples;
    scene.compensation = Compensation::None;
    scene
}

/// At 8 x 8 positions (no finer grid then) each of the torus's pixels shades all 64: its light
/// guided round the ring takes hundreds of searches a pixel, which lavapipe cut short while a
/// search visited one node a round and tested a leaf's triangles in a loop (395 of 1,200 pixels
/// at 640 x 480).
#[test]
fn every_position_of_a_mesh_pixels_grid_is_shaded() {
    let work = counted(&torus(8));
    eprintln!(
        "torus at 8 x 8: {} fragments, {} positions, {} nodes",
        work.fragments, work.positions, work.nodes
    );
    assert!(work.fragments > 500, "{} fragments", work.fragments);
    assert_eq!(work.positions, 64 * work.fragments);
}

/// At 4 x 4 positions some of the torus's pixels shade an 8 x 8 grid too (its outline, its
/// lobes where light goes round the ring, the edges of the wall seen through it), not all.
#[test]
fn a_mesh_pixel_shades_a_finer_grid_only_where_its_positions_disagree() {
    let work = counted(&torus(4));
    let finer = (work.positions - 16 * work.fragments) / 64;
    eprintln!(
        "torus at 4 x 4: {} fragments, {} positions, {finer} with the finer grid",
        work.fragments, work.positions
    );
    assert_eq!(
        work.positions,
        16 * work.fragments + 64 * finer,
        "each pixel shades 16 positions, or 80"
    );
    assert!(
        finer * 10 > work.fragments,
        "{finer} of {} pixels shade the finer grid",
        work.fragments
    );
    assert!(
        finer * 10 < 9 * work.fragments,
        "{finer} of {} pixels shade the finer grid",
        work.fragments
    );
}
