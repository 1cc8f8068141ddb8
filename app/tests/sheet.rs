//! `vitreous sheet`: what the wearer sees beside the physical reference for several
//! `replay --compare-reference` runs, one column each, and bad input.

use std::path::Path;

use crate::cli::{assert_clean_failure, scene, vitreous, workspace};

/// Replays frame 0 of `scene_name` (the neutral head) at 160 x 120 into `out`, measured against
/// the physical reference when `measured`.
fn replay(scene_name: &str, out: &Path, measured: bool) {
    let trace = workspace().join("config/traces/neutral-then-turned.csv");
    let (scene, trace, out) = (
        scene(scene_name),
        trace.display().to_string(),
        out.display().to_string(),
    );
    let mut args = vec![
        "replay",
        scene.as_str(),
        "--trace",
        trace.as_str(),
        "--frames",
        "1",
        "--save-every",
        "1",
        "--size",
        "160x120",
        "--out",
        out.as_str(),
    ];
    if measured {
        args.push("--compare-reference");
    }
    let run = vitreous(&args, &workspace());
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
}

fn rgba(path: &Path) -> (Vec<u8>, u32, u32) {
    let image = image::open(path).unwrap().to_rgba8();
    let (w, h) = image.dimensions();
    (image.into_raw(), w, h)
}

/// Where the `n` x `n` patch of `image` (`iw` wide) with its top left corner at `at` appears in
/// `sheet` (`sw` x `sh`), every match.
fn find_patch(
    sheet: &[u8],
    (sw, sh): (u32, u32),
    image: &[u8],
    iw: u32,
    at: (u32, u32),
    n: u32,
) -> Vec<(u32, u32)> {
    let px = |buf: &[u8], w: u32, x: u32, y: u32| {
        let i = ((y * w + x) * 4) as usize;
        [buf[i], buf[i + 1], buf[i + 2]]
    };
    let mut found = Vec::new();
    for y in 0..sh.saturating_sub(n) {
        for x in 0..sw.saturating_sub(n) {
            let same = (0..n).all(|dy| {
                (0..n)
                    .all(|dx| px(sheet, sw, x + dx, y + dy) == px(image, iw, at.0 + dx, at.1 + dy))
            });
            if same {
                found.push((x, y));
            }
        }
    }
    found
}

#[test]
fn each_run_is_a_column_with_its_physical_reference_under_what_the_wearer_sees() {
    let dir = tempfile::tempdir().unwrap();
    // The paper's scene (the light gives all of the floor's light) and the real one (half):
    // their references differ in the shadow.
    replay("glass-sphere.toml", &dir.path().join("paper"), true);
    replay("glass-sphere-real.toml", &dir.path().join("real"), true);
    let sheet = dir.path().join("sheet.png");
    let out = vitreous(
        &[
            "sheet",
            "paper",
            "real",
            "--label",
            "paper",
            "--label",
            "real",
            "-o",
            "sheet.png",
        ],
        dir.path(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let (pixels, w, h) = rgba(&sheet);
    assert!(pixels.chunks_exact(4).all(|p| p[3] == 255), "not opaque");
    let reference = |run: &str| rgba(&dir.path().join(run).join("frames/000000-left-real.png"));
    let (paper, iw, ih) = reference("paper");
    let (real, _, _) = reference("real");
    // The 6 x 6 patch where the two references differ most: in the shadow.
    let n = 6;
    let differ = |x: u32, y: u32| -> u32 {
        (0..n * n)
            .map(|k| (((y + k / n) * iw + x + k % n) * 4) as usize)
            .map(|i| {
                (0..3)
                    .map(|c| paper[i + c].abs_diff(real[i + c]) as u32)
                    .sum::<u32>()
            })
            .sum()
    };
    let at = (0..ih - n)
        .flat_map(|y| (0..iw - n).map(move |x| (x, y)))
        .max_by_key(|&(x, y)| differ(x, y))
        .unwrap();
    assert!(differ(at.0, at.1) > 0, "the references are the same");
    // Each is in the sheet once, in the lower row, the paper's column left of the real one's.
    let paper_at = find_patch(&pixels, (w, h), &paper, iw, at, n);
    let real_at = find_patch(&pixels, (w, h), &real, iw, at, n);
    assert_eq!(
        paper_at.len(),
        1,
        "the paper's reference found at {paper_at:?}"
    );
    assert_eq!(
        real_at.len(),
        1,
        "the real scene's reference found at {real_at:?}"
    );
    assert!(paper_at[0].0 < real_at[0].0, "{paper_at:?} {real_at:?}");
    assert_eq!(paper_at[0].1, real_at[0].1);
    // The lower row, as the command says where it lies.
    let said = String::from_utf8_lossy(&out.stdout);
    let number_after = |key: &str| -> u32 {
        let rest = &said[said.find(key).unwrap_or_else(|| panic!("{said}")) + key.len()..];
        let digits: String = rest.chars().take_while(char::is_ascii_digit).collect();
        digits.parse().unwrap_or_else(|_| panic!("{said}"))
    };
    let (tile_h, lower) = (number_after(" x "), number_after("reference from y = "));
    assert!(
        (lower..lower + tile_h).contains(&real_at[0].1),
        "{real_at:?} in a sheet {w} x {h}: {said}"
    );
}

#[test]
fn runs_that_were_not_measured_and_outputs_over_inputs_are_refused_naming_them() {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path();
    replay("glass-sphere-real.toml", &cwd.join("plain"), false);
    let out = vitreous(&["sheet", "plain", "-o", "sheet.png"], cwd);
    assert_clean_failure(&out, &["plain/summary.json", "--compare-reference"]);
    let out = vitreous(&["sheet", "missing", "-o", "sheet.png"], cwd);
    assert_clean_failure(&out, &["missing/summary.json"]);
    replay("glass-sphere-real.toml", &cwd.join("real"), true);
    let out = vitreous(&["sheet", "real", "--frame", "7", "-o", "sheet.png"], cwd);
    assert_clean_failure(&out, &["real/summary.json", "frame 7", "--frame"]);
    let out = vitreous(&["sheet", "real", "--label", "a", "--label", "b"], cwd);
    assert_clean_failure(&out, &["--label", "2 given for 1 runs"]);
    assert!(!cwd.join("sheet.png").exists());
    // An output that names a file the sheet reads: refused, the file kept.
    let summary = cwd.join("real/summary.json");
    let before = std::fs::read(&summary).unwrap();
    let out = vitreous(&["sheet", "real", "-o", "real/summary.json"], cwd);
    assert_clean_failure(&out, &["--out", "summary.json"]);
    assert_eq!(std::fs::read(&summary).unwrap(), before);
    let reference = cwd.join("real/frames/000000-left-real.png");
    let before = std::fs::read(&reference).unwrap();
    let out = vitreous(
        &["sheet", "real", "-o", "real/frames/000000-left-real.png"],
        cwd,
    );
    assert_clean_failure(&out, &["--out", "000000-left-real.png"]);
    assert_eq!(std::fs::read(&reference).unwrap(), before);
    // A run whose scene file changed since: its figures are not that scene's.
    let text = String::from_utf8(std::fs::read(&summary).unwrap()).unwrap();
    let hash = serde_json::from_str::<serde_json::Value>(&text).unwrap()["scene_hash"]
        .as_str()
        .unwrap()
        .to_owned();
    std::fs::write(&summary, text.replace(&hash, &"0".repeat(hash.len()))).unwrap();
    let out = vitreous(&["sheet", "real", "-o", "sheet.png"], cwd);
    assert_clean_failure(&out, &["real/summary.json", "scene_hash"]);
    assert!(!cwd.join("sheet.png").exists());
}
