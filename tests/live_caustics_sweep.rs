//! The sweep of live-map settings behind docs/caustics.md's tables, with the helpers of
//! tests/live_maps.rs.

use vitreous_optics::live_caustics::LiveCausticsDesc;

use crate::live_maps::{
    LiveFrame, axis_texel, baked_at, baked_scene, live_gains, live_scene, peak, relative_rms,
    smoothed, speckle,
};

/// The measurements behind docs/caustics.md's tables of live maps (run it with
/// `cargo test --release -p vitreous-tests --test gpu -- --ignored --nocapture sweep`): for
/// map sizes, smoothing radii and photon counts, the relative RMS against the shipped bake
/// averaged down to the live map's resolution and smoothed alike, and against the baker's
/// own map at that resolution (baked here, once per size), smoothed alike.
#[test]
#[ignore]
fn sweep() {
    for name in ["glass-sphere", "diamond"] {
        let base = baked_scene(&format!("{name}.toml"));
        let full = base.caustics.gain.as_ref().expect("the bake").width_px as usize;
        let mut own_bakes: Vec<(usize, Vec<f32>)> = Vec::new();
        for (factor, radius, photons) in [
            (1usize, 5u32, 128u32),
            (2, 2, 128),
            (2, 3, 128),
            (3, 2, 128),
            (4, 1, 128),
            (4, 2, 128),
            (2, 2, 96),
            (2, 2, 64),
            (3, 2, 96),
            (4, 1, 96),
            (4, 1, 64),
            (4, 1, 56),
            (4, 1, 48),
            (4, 1, 40),
            (4, 1, 32),
        ] {
            let side = full / factor;
            let (live_scene, averaged) = live_scene(&format!("{name}.toml"), Some(side as u32));
            if !own_bakes.iter().any(|(s, _)| *s == side) {
                own_bakes.push((side, baked_at(&live_scene, side as u32, 1 << 18)));
            }
            let own = &own_bakes.iter().find(|(s, _)| *s == side).expect("baked").1;
            let live = LiveCausticsDesc {
                photons_per_side: photons,
                smoothing_px: radius,
                ..LiveCausticsDesc::default()
            };
            let LiveFrame { gain, wall_ms, .. } = &live_gains(&live_scene, live, &[None], false)[0];
            let reference = smoothed(&averaged, side, radius);
            let own_smoothed = smoothed(own, side, radius);
            let (px, py) = peak(gain, side as u32);
            // Speckles: the largest difference from the baker's map outside the caustic
            // region, where the relative figure does not look.
            let speckle = speckle(gain, &own_smoothed);
            let axis = axis_texel(&base, base.light.position_m, side as u32, side as u32);
            eprintln!(
                "{name} {side}x{side} r = {radius} {photons}^2 photons: relative RMS {:.2} % over \
                 {} texels (the baker's own map: {:.2} %; it against the averaged bake {:.2} %), \
                 peak G {:.1} at ({px}, {py}) (light axis at {axis}), at most {speckle:.2} off \
                 the baker's map outside the region, {wall_ms:.0} ms",
                relative_rms(gain, &reference) * 100.0,
                reference.iter().filter(|&&g| g > 0.1).count(),
                relative_rms(gain, &own_smoothed) * 100.0,
                relative_rms(&own_smoothed, &reference) * 100.0,
                gain[py as usize * side + px as usize],
            );
        }
    }
}
