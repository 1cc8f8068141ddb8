//! `vitreous compare REFERENCE TEST`: how far an image is from a reference, as ꟻLIP (NVIDIA's
//! perceptual difference evaluator, `nv-flip`; mean over pixels, 0 identical, lower is
//! closer) and PSNR (8-bit sRGB, all three channels), over the whole view and, with a scene,
//! region by region (the object's disc, the shadow and caustic, the inducer's ramp, the rest);
//! with what the eye sees when nothing is drawn, the same figures for it and for the additive
//! limit beside the test's; with the display's light and panel misregistered by a given angle
//! (`--shift-deg`, `--roll-deg`), the ring around the object beside the regions; optionally
//! the ꟻLIP error map and the image measured (what the eye sees) as PNGs. The figures, the regions
//! and the images read are `vitreous-compare`'s; here the options, the display's light over
//! the seen image as the scene's display shows it, and the table.

use std::path::PathBuf;

use anyhow::{Result, bail};
use vitreous_compare::{
    Comparison, Eye, Labels, Png, RegionFigures, additive_limit, compare, flip, frame_for_scene,
    neutral_camera, reference_json_beside, rgb_of, scene_pixels_per_degree,
};

use vitreous_frames::input_files::InputFiles;
use vitreous_frames::output::{EYE_NAMES, encode_png, write_atomic};
use vitreous_frames::wearer::WearerView;
use vitreous_optics::display::registration::{self, Misregistration};

/// Options of `vitreous compare` (docs/cli.md).
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// The reference image (PNG, sRGB): what the eye should see.
    pub reference: PathBuf,
    /// The image to measure (PNG, sRGB, the reference's size).
    pub test: PathBuf,
    /// Split the figures by region of this scene (object's disc, shadow and caustic, inducer
    /// ramp, rest), for an image of `--eye` at the scene's neutral head.
    #[arg(long, value_name = "SCENE")]
    pub scene: Option<PathBuf>,
    /// The eye the images show, with --scene: left or right [default: left, or the eye the
    /// reference.json beside REFERENCE lists it as].
    #[arg(long, value_name = "EYE", value_parser = parse_eye)]
    pub eye: Option<Eye>,
    /// Pixels per degree of visual angle for ꟻLIP (default: the scene's, width over horizontal
    /// field of view, with --scene; else ꟻLIP's default, 67, a 0.7 m viewing distance from a
    /// 24-inch 4K monitor).
    #[arg(long, value_name = "PPD", allow_negative_numbers = true, value_parser = parse_ppd)]
    pub ppd: Option<f32>,
    /// What the eye sees with nothing drawn (PNG, the reference's size): adds two rows, that
    /// image itself and the additive limit, the per-pixel maximum of it and the reference (the
    /// closest any display that only adds light can get).
    #[arg(long, value_name = "PNG")]
    pub seen: Option<PathBuf>,
    /// TEST is the display's light alone (an eye image such as a replay's `NNNNNN-left.png`),
    /// not what the eye sees: it is added to --seen in linear light first, as an optical
    /// see-through display adds it to the real world.
    #[arg(long, requires = "seen")]
    pub display: bool,
    /// With --display and a scene whose display has a segmented dimmer: the blur the wearer's
    /// panel really has (standard deviation, degrees), instead of the scene's
    /// `dimmer_blur_deg` that the image was drawn for. Shows what a mis-measured panel costs.
    #[arg(long, value_name = "DEG", requires = "display", allow_negative_numbers = true,
          value_parser = parse_blur)]
    pub panel_blur_deg: Option<f32>,
    /// With --display: the display's light and its dimmer's panel land this far from where
    /// they belong against the seen image, degrees right and down (`X,Y`; each at most 10), as
    /// a registration error puts them; the regions stay the real world's.
    #[arg(long, value_name = "X,Y", requires = "display", allow_negative_numbers = true,
          value_parser = parse_shift)]
    pub shift_deg: Option<[f32; 2]>,
    /// With --display: the display's image also turned this far about the view's centre,
    /// degrees (clockwise as the eye sees it; at most 45).
    #[arg(long, value_name = "DEG", requires = "display", allow_negative_numbers = true,
          value_parser = parse_roll)]
    pub roll_deg: Option<f32>,
    /// Write the ꟻLIP error map here (PNG, the magma colour map: black no error, yellow most).
    #[arg(long, value_name = "FILE")]
    pub map: Option<PathBuf>,
    /// Write the image measured here (PNG, sRGB): with --display what the eye sees, the display's
    /// light and panel over --seen where --shift-deg and --roll-deg put them; else TEST itself.
    /// For another metric, or to look at a misregistered view.
    #[arg(long, value_name = "FILE")]
    pub wearer_view: Option<PathBuf>,
    /// Print the figures as JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

fn parse_eye(s: &str) -> std::result::Result<Eye, String> {
    match s {
        "left" => Ok(Eye::Left),
        "right" => Ok(Eye::Right),
        _ => Err(format!("expected left or right, found {s:?}")),
    }
}

fn parse_blur(s: &str) -> std::result::Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && (0.0..=20.0).contains(&v) => Ok(v),
        _ => Err(format!("expected a blur from 0 to 20 degrees, found {s:?}")),
    }
}

fn parse_shift(s: &str) -> std::result::Result<[f32; 2], String> {
    let limit = registration::MAX_SHIFT_DEG;
    let bad = || format!("expected X,Y in degrees, each from -{limit} to {limit}, found {s:?}");
    let values: Vec<f32> = s
        .split(',')
        .map(|v| v.trim().parse::<f32>().map_err(|_| bad()))
        .collect::<std::result::Result<_, _>>()?;
    match values[..] {
        [x, y] if Misregistration::new([x, y], 0.0).is_ok() => Ok([x, y]),
        _ => Err(bad()),
    }
}

fn parse_roll(s: &str) -> std::result::Result<f32, String> {
    let limit = registration::MAX_ROLL_DEG;
    match s.parse::<f32>() {
        Ok(v) if Misregistration::new([0.0, 0.0], v).is_ok() => Ok(v),
        _ => Err(format!(
            "expected a roll from -{limit} to {limit} degrees, found {s:?}"
        )),
    }
}

fn parse_ppd(s: &str) -> std::result::Result<f32, String> {
    match s.parse::<f32>() {
        Ok(v) if v.is_finite() && (1.0..=1000.0).contains(&v) => Ok(v),
        _ => Err(format!(
            "expected pixels per degree between 1 and 1000, found {s:?}"
        )),
    }
}

/// What the eye sees with `display` (sRGB RGBA8, alpha what a dimmer takes away) shown over
/// `seen` (sRGB RGB8) on the display `view`, misregistered by `error` at `ppd` pixels per
/// degree: sRGB RGB8.
fn add_light(
    view: &WearerView,
    display: &[u8],
    seen: &[u8],
    size: (u32, u32),
    (error, ppd): (&Misregistration, f32),
) -> Vec<u8> {
    let rgba: Vec<u8> = seen
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    rgb_of(&view.see_misregistered(display, &rgba, [size.0, size.1], error, ppd))
}

/// How the wearer of `scene`'s display sees (added light without a scene), with the dimmer's
/// blur replaced by `panel_blur_deg` when given: an error unless the scene has a dimmer.
fn wearer_view(
    scene: Option<&vitreous_scene::Scene>,
    panel_blur_deg: Option<f32>,
) -> Result<WearerView> {
    let Some(scene) = scene else {
        if panel_blur_deg.is_some() {
            bail!(
                "--panel-blur-deg needs --scene with a segmented dimmer ([display] model = \"dimmer\")"
            );
        }
        return Ok(WearerView::additive());
    };
    let Some(blur_deg) = panel_blur_deg else {
        return Ok(WearerView::of_scene(scene));
    };
    let Some(dimmer) = scene.dimmer else {
        bail!(
            "--panel-blur-deg: {} has no segmented dimmer ([display] model = \"dimmer\")",
            scene.path.display()
        );
    };
    let dimmer = vitreous_optics::display::dimmer::DimmerDesc { blur_deg, ..dimmer };
    Ok(WearerView::new(
        Some(dimmer),
        scene.global_dimmer,
        vitreous_frames::wearer::scene_fov_deg(scene),
    ))
}

/// `vitreous compare`.
pub fn compare_command(args: CompareArgs) -> Result<()> {
    if let (Some(eye), None) = (args.eye, &args.scene) {
        bail!(
            "--eye {} chooses the eye whose regions --scene splits the figures into; without \
             --scene there are none: add --scene SCENE or leave --eye out",
            EYE_NAMES[eye.index()]
        );
    }
    let scene = match &args.scene {
        Some(path) => {
            let mut scene = vitreous_scene::load_scene(path)?;
            if scene.caustics.bake.is_some()
                && let Err(e) = scene.load_caustics()
            {
                tracing::warn!("the caustic is left out of the regions: {e}");
            }
            Some(scene)
        }
        None => None,
    };
    let outputs: Vec<(&str, &PathBuf)> =
        [("--map", &args.map), ("--wearer-view", &args.wearer_view)]
            .into_iter()
            .filter_map(|(option, path)| path.as_ref().map(|p| (option, p)))
            .collect();
    if !outputs.is_empty() {
        let mut inputs = InputFiles::new();
        inputs
            .add(&args.reference, "REFERENCE")
            .add(&args.test, "TEST");
        if let Some(seen) = &args.seen {
            inputs.add(seen, "--seen");
        }
        if let Some(scene) = &scene {
            inputs.add_scene(scene, "--scene");
        }
        let beside = reference_json_beside(&args.reference);
        if beside.exists() {
            inputs.add(&beside, "the reference.json beside REFERENCE");
        }
        for (option, path) in &outputs {
            inputs.check_file(option, path)?;
        }
        if let [(_, map), (_, view)] = outputs[..]
            && map == view
        {
            bail!(
                "--map and --wearer-view both name {}: give each its own file",
                map.display()
            );
        }
    }
    let reference = Png::read(&args.reference)?;
    let (w, h) = (reference.width, reference.height);
    let test = Png::read_like(&args.test, &reference)?;
    let seen = args
        .seen
        .as_deref()
        .map(|path| Png::read_like(path, &reference))
        .transpose()?;
    let ppd = args.ppd.unwrap_or_else(|| match &scene {
        Some(s) => scene_pixels_per_degree(s, w),
        None => flip::DEFAULT_PIXELS_PER_DEGREE,
    });
    let misregistration = Misregistration::new(
        args.shift_deg.unwrap_or_default(),
        args.roll_deg.unwrap_or_default(),
    )?;
    if !misregistration.is_none() && scene.is_none() && args.ppd.is_none() {
        bail!(
            "--shift-deg and --roll-deg need the image's pixels per degree: add --scene SCENE \
             or --ppd PPD"
        );
    }
    // The display light over the seen image, as the scene's display composes them (its
    // dimmers, when it has any; else added), where the registration error puts it.
    let (test_rgb, test_alpha_used) = match &seen {
        Some(seen) if args.display => {
            let view = wearer_view(scene.as_ref(), args.panel_blur_deg)?;
            (
                add_light(
                    &view,
                    &test.rgba,
                    &seen.rgb(),
                    (w, h),
                    (&misregistration, ppd),
                ),
                view.panel.is_some(),
            )
        }
        _ => (test.rgb(), false),
    };
    let ignored = [
        reference.alpha_ignored(false),
        test.alpha_ignored(test_alpha_used),
        seen.as_ref().and_then(|s| s.alpha_ignored(false)),
    ];
    for warning in ignored.into_iter().flatten() {
        tracing::warn!("{warning}");
    }
    let (labels, regions_from) = match &scene {
        Some(s) => match frame_for_scene(&args.reference, s, args.eye.map(Eye::index))? {
            Some(listed) => (
                Some(Labels::of(
                    s,
                    &listed.frame.eyes[listed.eye].camera(),
                    &listed.frame.placement(),
                    w,
                    h,
                )),
                Some(format!(
                    "frame {} {} eye of {}",
                    listed.frame.frame,
                    EYE_NAMES[listed.eye],
                    listed.file.display()
                )),
            ),
            None => {
                let eye = args.eye.unwrap_or(Eye::Left);
                (
                    Some(Labels::of(
                        s,
                        &neutral_camera(s, eye),
                        &s.rest_placement(),
                        w,
                        h,
                    )),
                    Some(format!("neutral head, {} eye", EYE_NAMES[eye.index()])),
                )
            }
        },
        None => (None, None),
    };
    let reference = reference.rgb();
    let (error, figures) = compare(&reference, &test_rgb, (w, h), ppd, labels.as_ref())?;
    let rows = |image: &[u8]| compare(&reference, image, (w, h), ppd, labels.as_ref()).map(|r| r.1);
    let seen = seen.map(|s| s.rgb());
    let nothing_drawn = seen.as_deref().map(rows).transpose()?;
    let limit = seen
        .as_deref()
        .map(|s| rows(&additive_limit(s, &reference)))
        .transpose()?;
    // Both images encoded before either is written: a failure leaves neither behind.
    let map_png = match &args.map {
        Some(_) => Some(encode_png(&opaque(&flip::magma(&error, (w, h))), w, h)?),
        None => None,
    };
    let view_png = match &args.wearer_view {
        Some(_) => Some(encode_png(&opaque(&test_rgb), w, h)?),
        None => None,
    };
    for (path, png) in [(&args.map, map_png), (&args.wearer_view, view_png)] {
        if let (Some(path), Some(png)) = (path, png) {
            write_atomic(path, &png)?;
        }
    }
    let report = Comparison {
        reference: args.reference.display().to_string(),
        test: args.test.display().to_string(),
        width_px: w,
        height_px: h,
        pixels_per_degree: ppd,
        scene: args.scene.as_ref().map(|p| p.display().to_string()),
        regions_from,
        display_added_to_seen: args.display,
        misregistration_deg: (!misregistration.is_none()).then_some([
            misregistration.shift_deg[0],
            misregistration.shift_deg[1],
            misregistration.roll_deg,
        ]),
        regions: figures,
        nothing_drawn,
        additive_limit: limit,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", table(&report));
    }
    Ok(())
}

/// RGB pixels as opaque RGBA, for a PNG.
fn opaque(rgb: &[u8]) -> Vec<u8> {
    rgb.chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect()
}

/// The report as a text table: one line per region, with the nothing-drawn and additive-limit
/// figures beside the test's when they were measured.
fn table(report: &Comparison) -> String {
    let mut out = format!(
        "{}{} against {} ({}x{}, {:.1} pixels per degree{})\n{:<16} {:>9} {:>10} {:>10}",
        report.test,
        match (report.display_added_to_seen, report.misregistration_deg) {
            (true, Some([x, y, roll])) => format!(
                " over the seen image, misregistered {x} degrees right, {y} down, {roll} turned"
            ),
            (true, None) => " over the seen image".to_owned(),
            _ => String::new(),
        },
        report.reference,
        report.width_px,
        report.height_px,
        report.pixels_per_degree,
        report
            .regions_from
            .as_ref()
            .map_or(String::new(), |r| format!("; regions of the {r}")),
        "region",
        "pixels",
        "FLIP mean",
        "PSNR dB"
    );
    let extra = report
        .nothing_drawn
        .as_ref()
        .zip(report.additive_limit.as_ref());
    if extra.is_some() {
        out += &format!(
            " {:>12} {:>12} {:>12} {:>12}",
            "nothing FLIP", "nothing PSNR", "limit FLIP", "limit PSNR"
        );
    }
    out.push('\n');
    let cells = |r: &RegionFigures| {
        let flip = r.flip_mean.map_or("-".to_owned(), |v| format!("{v:.4}"));
        let psnr = match (r.pixels, r.psnr_db) {
            (0, _) => "-".to_owned(),
            (_, None) => "equal".to_owned(),
            (_, Some(v)) => format!("{v:.2}"),
        };
        (flip, psnr)
    };
    for (i, r) in report.regions.iter().enumerate() {
        let (flip, psnr) = cells(r);
        out += &format!("{:<16} {:>9} {:>10} {:>10}", r.region, r.pixels, flip, psnr);
        if let Some((nothing, limit)) = extra {
            let (nf, np) = cells(&nothing[i]);
            let (lf, lp) = cells(&limit[i]);
            out += &format!(" {nf:>12} {np:>12} {lf:>12} {lp:>12}");
        }
        out.push('\n');
    }
    out
}
