//! Counted work by name (`vitreous bench`'s counts): the mean per frame of what the renderer
//! recorded and of each pass's shader invocations ([`super`]). Timings on a shared machine
//! scatter by tens of percent; these counts are the same run after run, so a test can hold
//! them to a committed expectation (tests/cost.rs).

use std::collections::BTreeMap;

use super::{FrameWork, Invocations, ShaderCost};

/// Named counts, mean per frame, in a stable order. Names: `render_passes`, `draws`,
/// `vertices`, `dispatches`, `workgroups`, `uploaded_bytes` (recorded, the same on every
/// device); where the device counts invocations, `<pass>.<stage>_invocations` for each pass
/// (`mask`, `nearest`, `ramp`, `caustic_photons`, `caustic_smoothing`, `blur`, `eye_floor`,
/// `eye_glass`, and `eye_glass_covered`: the glass drawn without the environment's lookup where
/// the frame proved every refracted ray reaches the background photo) and shader stage
/// (`vertex`, `fragment`, `compute`), and the work of the eye passes' fragments, their
/// invocations times the static cost of one ([`ShaderCost`]):
/// `glass_fetches`, `glass_texels`, `glass_instructions` (both of the glass's pipelines), and
/// the same for the floor overlay (`floor_*`); where the glass shades a ball's light in two
/// parts, each over as many positions as it needs, the positions of the rest
/// (`glass_positions`) and of the first image (`glass_positions.first_images`) and the covered
/// pixels that shaded them (`glass_positions.pixels`), counted on the device
/// ([`super::GlassPositions`]), what a pixel shaded beyond one position of each charged to
/// `glass_*` at their static costs; where the frames count their work with live
/// caustics on, what the live map's computation did (`caustic_photons.traced`,
/// `caustic_photons.splatted`, `caustic_smoothing.texels`: [`super::PhotonWork`]).
pub type WorkCounts = BTreeMap<String, f64>;

/// The mean per frame of `frames`' work; empty without frames.
pub fn mean_counts(frames: &[FrameWork]) -> WorkCounts {
    let mut sums = WorkCounts::new();
    for frame in frames {
        for (name, value) in frame_counts(frame) {
            *sums.entry(name).or_default() += value;
        }
    }
    let n = frames.len().max(1) as f64;
    sums.values_mut().for_each(|sum| *sum /= n);
    sums
}

/// One frame's counts, named as [`WorkCounts`].
fn frame_counts(frame: &FrameWork) -> Vec<(String, f64)> {
    let r = &frame.recorded;
    let mut counts: Vec<(String, f64)> = [
        ("render_passes", r.render_passes),
        ("draws", r.draws),
        ("vertices", r.vertices),
        ("dispatches", r.dispatches),
        ("workgroups", r.workgroups),
        ("uploaded_bytes", r.uploaded_bytes),
    ]
    .into_iter()
    .map(|(name, value)| (name.to_owned(), value as f64))
    .collect();
    if let Some(p) = &frame.invocations {
        let passes: [(&str, Invocations); 9] = [
            ("mask", p.mask),
            ("nearest", p.nearest),
            ("ramp", p.ramp),
            ("caustic_photons", p.caustic_photons),
            ("caustic_smoothing", p.caustic_smoothing),
            ("blur", p.blur),
            ("eye_floor", p.eye_floor),
            ("eye_glass", p.eye_glass),
            ("eye_glass_covered", p.eye_glass_covered),
        ];
        for (pass, i) in passes {
            for (stage, value) in [
                ("vertex", i.vertex),
                ("fragment", i.fragment),
                ("compute", i.compute),
            ] {
                counts.push((format!("{pass}.{stage}_invocations"), value as f64));
            }
        }
        let shaded = [
            (
                "glass",
                [
                    (p.eye_glass.fragment, frame.glass_shader),
                    (p.eye_glass_covered.fragment, frame.glass_covered_shader),
                ],
            ),
            (
                "floor",
                [(p.eye_floor.fragment, frame.overlay_shader), (0, None)],
            ),
        ];
        for (pass, parts) in shaded {
            let total = |of: fn(ShaderCost) -> u32| {
                parts
                    .iter()
                    .map(|&(fragments, cost)| fragments * u64::from(of(cost.unwrap_or_default())))
                    .sum::<u64>()
            };
            // What the glass's pixels shaded beyond their first whole position and first image.
            let [fetches, texels, instructions] = match (pass, frame.glass_positions) {
                ("glass", Some(p)) => p.further(),
                _ => [0; 3],
            };
            // What the mesh's searches visited and tested.
            let [fetches, texels, instructions] = match (pass, frame.glass_mesh) {
                ("glass", Some(m)) => {
                    let [f, t, i] = m.charged();
                    [fetches + f, texels + t, instructions + i]
                }
                _ => [fetches, texels, instructions],
            };
            for (what, value) in [
                ("fetches", total(|c| c.fetches) + fetches),
                ("texels", total(|c| c.texels) + texels),
                ("instructions", total(|c| c.instructions) + instructions),
            ] {
                counts.push((format!("{pass}_{what}"), value as f64));
            }
        }
        if let Some(p) = frame.glass_positions {
            counts.push(("glass_positions".to_owned(), p.shaded as f64));
            counts.push((
                "glass_positions.first_images".to_owned(),
                p.first_images as f64,
            ));
            counts.push(("glass_positions.pixels".to_owned(), p.pixels as f64));
        }
        if let Some(m) = frame.glass_mesh {
            counts.push(("glass_mesh.nodes".to_owned(), m.nodes as f64));
            counts.push(("glass_mesh.triangles".to_owned(), m.triangles as f64));
            counts.push(("glass_mesh.fragments".to_owned(), m.fragments as f64));
            counts.push(("glass_mesh.positions".to_owned(), m.positions as f64));
        }
    }
    if let Some(photons) = frame.photons {
        for (name, value) in [
            ("caustic_photons.traced", photons.traced),
            ("caustic_photons.splatted", photons.splatted),
            ("caustic_smoothing.texels", photons.smoothed_texels),
        ] {
            counts.push((name.to_owned(), value as f64));
        }
    }
    counts
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::work::{GlassPositions, MeshSearch, PassInvocations, RecordedWork, ShaderCost};

    #[test]
    fn counts_are_means_per_frame_and_fetches_follow_each_glass_pipelines_fragments() {
        let frame = |draws: u64, fragments: u64| FrameWork {
            recorded: RecordedWork {
                draws,
                ..RecordedWork::default()
            },
            invocations: Some(PassInvocations {
                eye_glass: Invocations {
                    fragment: fragments,
                    ..Invocations::default()
                },
                eye_glass_covered: Invocations {
                    fragment: 10,
                    ..Invocations::default()
                },
                ..PassInvocations::default()
            }),
            glass_shader: Some(ShaderCost {
                fetches: 3,
                texels: 16,
                instructions: 100,
            }),
            glass_covered_shader: Some(ShaderCost {
                fetches: 2,
                texels: 8,
                instructions: 50,
            }),
            overlay_shader: None,
            photons: (draws == 4).then_some(crate::work::PhotonWork {
                traced: 8,
                splatted: 20,
                smoothed_texels: 64,
            }),
            glass_positions: None,
            glass_mesh: None,
        };
        let counts = mean_counts(&[frame(2, 100), frame(4, 300)]);
        assert_eq!(counts["draws"], 3.0);
        assert_eq!(counts["eye_glass.fragment_invocations"], 200.0);
        // Both pipelines' fragments: 200 with the lookup, 10 without, a frame.
        assert_eq!(counts["glass_fetches"], 600.0 + 20.0);
        assert_eq!(counts["glass_texels"], 3200.0 + 80.0);
        assert_eq!(counts["glass_instructions"], 20_000.0 + 500.0);
        assert_eq!(counts["floor_texels"], 0.0);
        assert_eq!(counts["mask.compute_invocations"], 0.0);
        // The live map computed on one frame of two.
        assert_eq!(counts["caustic_photons.traced"], 4.0);
        assert_eq!(counts["caustic_photons.splatted"], 10.0);
        assert_eq!(counts["caustic_smoothing.texels"], 32.0);
    }

    /// A frame that drew 50 glass fragments at a static cost of 3 fetches, 12 texels and 100
    /// instructions each, and counted nothing else.
    fn fifty_glass_fragments() -> FrameWork {
        FrameWork {
            recorded: RecordedWork::default(),
            invocations: Some(PassInvocations {
                eye_glass: Invocations {
                    fragment: 50,
                    ..Invocations::default()
                },
                ..PassInvocations::default()
            }),
            glass_shader: Some(ShaderCost {
                fetches: 3,
                texels: 12,
                instructions: 100,
            }),
            glass_covered_shader: None,
            overlay_shader: None,
            photons: None,
            glass_positions: None,
            glass_mesh: None,
        }
    }

    #[test]
    fn the_glass_is_charged_each_position_a_pixel_shaded_beyond_its_first() {
        let each = ShaderCost {
            fetches: 2,
            texels: 8,
            instructions: 40,
        };
        let each_first_image = ShaderCost {
            fetches: 1,
            texels: 4,
            instructions: 10,
        };
        let frame = |positions: Option<(u64, u64, u64)>| FrameWork {
            glass_positions: positions.map(|(shaded, first_images, pixels)| GlassPositions {
                shaded,
                first_images,
                pixels,
                each,
                each_first_image,
            }),
            ..fifty_glass_fragments()
        };
        // 40 covered pixels, each with the first image at 16 positions (600 beyond their
        // first), the rest at 16 positions in 10 of them and at 4 in 30 (240 beyond).
        let counts = mean_counts(&[frame(Some((10 * 16 + 30 * 4, 40 * 16, 40)))]);
        assert_eq!(counts["glass_positions"], 280.0);
        assert_eq!(counts["glass_positions.first_images"], 640.0);
        assert_eq!(counts["glass_positions.pixels"], 40.0);
        assert_eq!(counts["glass_fetches"], 150.0 + 240.0 * 2.0 + 600.0);
        assert_eq!(counts["glass_texels"], 600.0 + 240.0 * 8.0 + 600.0 * 4.0);
        assert_eq!(
            counts["glass_instructions"],
            5000.0 + 240.0 * 40.0 + 600.0 * 10.0
        );
        // Every pixel at one position of each: the static cost alone.
        let one = mean_counts(&[frame(Some((40, 40, 40)))]);
        assert_eq!(one["glass_instructions"], 5000.0);
        let uncounted = mean_counts(&[frame(None)]);
        assert_eq!(uncounted["glass_instructions"], 5000.0);
        assert!(!uncounted.contains_key("glass_positions"));
    }

    #[test]
    fn the_glass_is_charged_each_node_and_triangle_its_mesh_searches_visited() {
        let frame = |mesh: Option<(u64, u64)>| FrameWork {
            glass_mesh: mesh.map(|(nodes, triangles)| MeshSearch {
                nodes,
                triangles,
                fragments: 40,
                positions: 640,
                each_node: ShaderCost {
                    fetches: 0,
                    texels: 0,
                    instructions: 30,
                },
                each_triangle: ShaderCost {
                    fetches: 0,
                    texels: 0,
                    instructions: 25,
                },
            }),
            ..fifty_glass_fragments()
        };
        let counts = mean_counts(&[frame(Some((1000, 300)))]);
        assert_eq!(counts["glass_mesh.nodes"], 1000.0);
        assert_eq!(counts["glass_mesh.triangles"], 300.0);
        assert_eq!(counts["glass_mesh.fragments"], 40.0);
        assert_eq!(counts["glass_mesh.positions"], 640.0);
        assert_eq!(counts["glass_fetches"], 150.0);
        assert_eq!(
            counts["glass_instructions"],
            5000.0 + 1000.0 * 30.0 + 300.0 * 25.0
        );
        let uncounted = mean_counts(&[frame(None)]);
        assert_eq!(uncounted["glass_instructions"], 5000.0);
        assert!(!uncounted.contains_key("glass_mesh.nodes"));
    }

    #[test]
    fn without_invocation_counts_only_the_recorded_work_is_named() {
        let frame = FrameWork {
            recorded: RecordedWork {
                dispatches: 5,
                ..RecordedWork::default()
            },
            invocations: None,
            glass_shader: None,
            glass_covered_shader: None,
            overlay_shader: None,
            photons: None,
            glass_positions: None,
            glass_mesh: None,
        };
        let counts = mean_counts(&[frame]);
        assert_eq!(counts["dispatches"], 5.0);
        assert!(!counts.contains_key("glass_fetches"));
        assert_eq!(counts.len(), 6);
    }
}
