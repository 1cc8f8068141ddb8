//! The cost guard: every condition's counted work per frame (`vitreous bench`'s `work`: passes,
//! draws, dispatches, uploaded bytes, each pass's shader invocations and the glass's and
//! floor's fetches, texels and instructions, and where the glass counts them the positions it
//! shades) held to the expectation committed in `tests/cost-expected.json`, with 5 % margin;
//! and each condition's work over the baseline's (O2, or a) held to its committed ratio the same
//! way, so that a cheaper baseline the method does not follow fails too. Counts, not times: the
//! same run after run on one driver. In the realism scenes the glass shades the rest of a
//! ball's light over the whole grid only where a pixel needs it (`positions_where_they_matter`);
//! a mesh's searches count the nodes and triangles they visit and test (`glass_mesh.*`), held
//! like every other count, so that a hierarchy that searches more fails.
//!
//! After a deliberate change of cost, write the new expectation with
//! `VITREOUS_UPDATE_COST=1 cargo test -p vitreous-tests --test gpu cost` and say why in the
//! commit. Invocation counts hold for the driver that recorded them (the file names it); on
//! another device only the recorded counts, which are the same everywhere, are compared.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde_json::{Value, json};
use vitreous::bench::{BenchOptions, BenchReport, bench};
use vitreous_render::Reflection;
use vitreous_scene::effects::EffectSet;

use vitreous_tests::workspace;

/// How much a count may grow over its expectation.
const MARGIN: f64 = 1.05;

/// Counts of the recorded work, the same on every device.
const RECORDED: [&str; 6] = [
    "render_passes",
    "draws",
    "vertices",
    "dispatches",
    "workgroups",
    "uploaded_bytes",
];

/// Counts whose ratio to the baseline's is held too: the work that decides a condition's
/// cost over the conventional method's.
const RATIOS: [&str; 4] = [
    "glass_texels",
    "glass_instructions",
    "floor_texels",
    "floor_instructions",
];

/// One benchmarked case: a name, the scene and the bench's switches.
struct Case {
    name: &'static str,
    scene: &'static str,
    effects: &'static [&'static str],
    moving: bool,
    two_surface: bool,
    /// Frames drawn before the counted ones: enough for the gaze pipeline to decide an image
    /// where a condition has defocus, and as many as the expectation was recorded after where
    /// the light circles (the counted frames' poses); the bench's own few elsewhere.
    warm_up: usize,
    /// Frames counted, after the warm-up: their mean is held.
    frames: usize,
    /// The glass shades a ball's light in the room in parts and counts its positions.
    positions: bool,
    /// The glass searches a mesh's triangles for the exit and counts the nodes and triangles.
    mesh: bool,
}

/// The study's conditions (with two-surface O5), the floor's, the live scene's moving light,
/// the segmented dimmer's panel and resolve (glass-sphere-ml2.toml), and the realism scene's
/// glass over several positions per pixel (glass-sphere-real.toml), and a mesh's searches of its
/// triangles with those settings (goblet-real.toml).
const CASES: [Case; 6] = [
    Case {
        name: "visual-effects O3 O4 O5",
        scene: "visual-effects.toml",
        effects: &["O3", "O4", "O5"],
        moving: false,
        two_surface: true,
        warm_up: 40,
        frames: FRAMES,
        positions: false,
        mesh: false,
    },
    Case {
        name: "glass-sphere b c",
        scene: "glass-sphere.toml",
        effects: &["b", "c"],
        moving: false,
        two_surface: false,
        warm_up: vitreous::bench::WARM_UP_FRAMES,
        frames: FRAMES,
        positions: false,
        mesh: false,
    },
    Case {
        name: "moving-light c moving",
        scene: "moving-light.toml",
        effects: &["c"],
        moving: true,
        two_surface: false,
        warm_up: 40,
        frames: FRAMES,
        positions: false,
        mesh: false,
    },
    Case {
        name: "glass-sphere-ml2 dimmer",
        scene: "glass-sphere-ml2.toml",
        effects: &["caustics"],
        moving: false,
        two_surface: true,
        warm_up: vitreous::bench::WARM_UP_FRAMES,
        frames: FRAMES,
        positions: true,
        mesh: false,
    },
    Case {
        name: "glass-sphere-real",
        scene: "glass-sphere-real.toml",
        // Disparity's look (the background's, every position whole) draws the ball on its
        // proxy too.
        effects: &["O4"],
        moving: false,
        two_surface: false,
        warm_up: vitreous::bench::WARM_UP_FRAMES,
        frames: FRAMES,
        positions: true,
        mesh: false,
    },
    Case {
        name: "goblet-real",
        scene: "goblet-real.toml",
        effects: &[],
        moving: false,
        two_surface: false,
        // A mesh's frame costs lavapipe seconds (a search of the triangles at every position of
        // the grid): one frame after one (the synthetic trace's head hardly moves: a frame's
        // counts stand within 5 % of the mean of four).
        warm_up: 1,
        frames: 1,
        positions: false,
        mesh: true,
    },
];

/// Frames counted in most cases.
const FRAMES: usize = 4;

/// Positions along each side of a glass pixel in the realism scenes (`[output] glass_samples`).
const GLASS_SAMPLES: f64 = 4.0;

/// Where the glass shades a ball's light in the room in parts (shaders/shared/glass_positions.wgsl),
/// each variant that counted its positions shades the first image over the whole grid of every
/// covered pixel, and the rest over it only where a pixel needs it: on average under half the
/// grid (the rim and the highlight; a 2 x 2 grid elsewhere). The lines of the variants that do
/// not; and whether any variant counted.
fn positions_where_they_matter(
    counts: &BTreeMap<String, BTreeMap<String, f64>>,
) -> (Vec<String>, bool) {
    let grid = GLASS_SAMPLES * GLASS_SAMPLES;
    let mut failures = Vec::new();
    let mut counted = false;
    for (variant, c) in counts {
        let Some(&pixels) = c.get("glass_positions.pixels").filter(|&&p| p > 0.0) else {
            continue;
        };
        counted = true;
        let (rest, first) = (c["glass_positions"], c["glass_positions.first_images"]);
        if first != grid * pixels {
            failures.push(format!(
                "{variant}: {first} positions of the first image for {pixels} pixels"
            ));
        }
        if rest >= 0.5 * grid * pixels || rest < pixels {
            failures.push(format!(
                "{variant}: {rest} positions of the rest for {pixels} pixels"
            ));
        }
    }
    (failures, counted)
}

fn expectation_path() -> PathBuf {
    workspace().join("tests/cost-expected.json")
}

/// The case's bench: small eye images (counts scale with the area, ratios do not), the case's
/// warm-up frames first, validation on.
fn run(case: &Case) -> BenchReport {
    bench(&BenchOptions {
        scene: workspace().join("config/scenes").join(case.scene),
        effects: case
            .effects
            .iter()
            .map(|e| EffectSet::parse(e).unwrap())
            .collect(),
        size: (320, 240),
        frames: case.frames,
        warm_up: case.warm_up,
        reflection: Reflection::Phong,
        validate: true,
        device: None,
        pupils_mm: Vec::new(),
        moving: case.moving,
        live_caustics: false,
        two_surface: case.two_surface,
        unproved: false,
    })
    .unwrap_or_else(|e| panic!("{}: {e:#}", case.name))
}

/// The case's counts, variant by variant, with each [`RATIOS`] count over the baseline's (the
/// conventional method standing still under the paper's refraction) as `<count>/baseline`.
fn counts(report: &BenchReport) -> BTreeMap<String, BTreeMap<String, f64>> {
    let baseline = &report
        .variants
        .iter()
        .find(|v| v.effects == "none")
        .expect("the baseline's variant")
        .work;
    report
        .variants
        .iter()
        .map(|v| {
            let mut counts = v.work.clone();
            for name in RATIOS {
                if let (Some(&mine), Some(&base)) = (v.work.get(name), baseline.get(name))
                    && base > 0.0
                {
                    counts.insert(format!("{name}/baseline"), mine / base);
                }
            }
            (v.effects.clone(), counts)
        })
        .collect()
}

#[test]
fn every_conditions_counted_work_stays_within_its_expectation() {
    let mut driver = String::new();
    let mut measured = serde_json::Map::new();
    for case in &CASES {
        let report = run(case);
        assert!(
            report.invocations_counted,
            "{}: lavapipe counts invocations; this device did not",
            case.name
        );
        driver = report.driver.clone();
        let counts = counts(&report);
        if case.positions {
            let (failures, counted) = positions_where_they_matter(&counts);
            assert!(
                counted,
                "{}: no variant counted the glass's positions",
                case.name
            );
            assert!(failures.is_empty(), "{}: {failures:#?}", case.name);
        }
        if case.mesh {
            for (variant, c) in &counts {
                let fragments = c.get("glass_mesh.fragments").copied().unwrap_or(0.0);
                assert!(
                    fragments > 0.0 && c["glass_mesh.nodes"] > fragments,
                    "{} {variant}: no search of the mesh's triangles counted ({c:?})",
                    case.name
                );
            }
        }
        measured.insert(case.name.to_owned(), json!(counts));
    }
    let measured = json!({ "driver": driver, "cases": measured });
    if std::env::var_os("VITREOUS_UPDATE_COST").is_some() {
        let text = serde_json::to_string_pretty(&measured).unwrap() + "\n";
        std::fs::write(expectation_path(), text).unwrap();
        eprintln!("wrote {}", expectation_path().display());
        return;
    }
    let text = std::fs::read_to_string(expectation_path()).unwrap();
    let expected: Value = serde_json::from_str(&text).unwrap();
    let failures = compare(&expected, &measured);
    assert!(
        failures.is_empty(),
        "counted work above its expectation ({}, margin {:.0} %):\n{}\nIf the change is \
         meant, write the new expectation with VITREOUS_UPDATE_COST=1 and say why.",
        expectation_path().display(),
        (MARGIN - 1.0) * 100.0,
        failures.join("\n")
    );
}

/// Every expected count that `measured` lacks or exceeds by more than [`MARGIN`], as lines;
/// invocation-based counts only when the driver is the one that recorded them.
fn compare(expected: &Value, measured: &Value) -> Vec<String> {
    let same_driver = expected["driver"] == measured["driver"];
    let mut failures = Vec::new();
    let Some(cases) = expected["cases"].as_object() else {
        return vec!["the expectation file has no cases".into()];
    };
    for (case, variants) in cases {
        for (variant, counts) in variants.as_object().into_iter().flatten() {
            for (name, want) in counts.as_object().into_iter().flatten() {
                if !same_driver && !RECORDED.contains(&name.as_str()) {
                    continue;
                }
                let want = want.as_f64().unwrap_or(f64::NAN);
                match measured["cases"][case][variant][name].as_f64() {
                    None => failures.push(format!("{case} / {variant}: no {name}")),
                    Some(got) if got > want * MARGIN + 1e-9 => failures.push(format!(
                        "{case} / {variant}: {name} {got:.4} > {want:.4} expected (+{:.1} %)",
                        (got / want - 1.0) * 100.0
                    )),
                    Some(_) => {}
                }
            }
        }
    }
    failures
}

#[test]
fn the_guard_fails_a_glass_that_shades_the_whole_grid_everywhere() {
    let variant = |rest: f64, first: f64| {
        BTreeMap::from([(
            "none".to_owned(),
            BTreeMap::from([
                ("glass_positions".to_owned(), rest),
                ("glass_positions.first_images".to_owned(), first),
                ("glass_positions.pixels".to_owned(), 100.0),
            ]),
        )])
    };
    // A fifth of the pixels at the whole grid, the rest at 2 x 2: 640 of the rest.
    assert_eq!(
        positions_where_they_matter(&variant(640.0, 1600.0)),
        (vec![], true)
    );
    // Every pixel at the whole grid, or the first image short of it.
    assert_eq!(
        positions_where_they_matter(&variant(1600.0, 1600.0))
            .0
            .len(),
        1
    );
    assert_eq!(
        positions_where_they_matter(&variant(640.0, 100.0)).0.len(),
        1
    );
    // Nothing counted.
    assert!(!positions_where_they_matter(&BTreeMap::new()).1);
}

#[test]
fn the_guard_fails_a_count_that_grows_and_a_baseline_that_gets_cheaper_alone() {
    let expected = json!({
        "driver": "d",
        "cases": { "c": {
            "none": { "glass_texels": 100.0, "draws": 2.0 },
            "disparity": { "glass_texels": 100.0, "glass_texels/baseline": 1.0 }
        } }
    });
    let same = expected.clone();
    assert!(compare(&expected, &same).is_empty());
    // 4 % more is within the margin; 6 % more is not.
    let mut grown = expected.clone();
    grown["cases"]["c"]["none"]["glass_texels"] = json!(104.0);
    assert!(compare(&expected, &grown).is_empty());
    grown["cases"]["c"]["none"]["glass_texels"] = json!(106.0);
    assert_eq!(compare(&expected, &grown).len(), 1);
    // The baseline halves, the condition stays: its ratio doubles.
    let mut cheaper = expected.clone();
    cheaper["cases"]["c"]["none"]["glass_texels"] = json!(50.0);
    cheaper["cases"]["c"]["disparity"]["glass_texels/baseline"] = json!(2.0);
    let failures = compare(&expected, &cheaper);
    assert_eq!(failures.len(), 1, "{failures:?}");
    assert!(failures[0].contains("glass_texels/baseline"));
    // A count that disappears fails; on another driver only the recorded counts are held.
    let mut missing = expected.clone();
    missing["cases"]["c"]["none"]
        .as_object_mut()
        .unwrap()
        .remove("draws");
    assert_eq!(compare(&expected, &missing).len(), 1);
    let mut elsewhere = grown.clone();
    elsewhere["driver"] = json!("another");
    assert!(compare(&expected, &elsewhere).is_empty());
}
