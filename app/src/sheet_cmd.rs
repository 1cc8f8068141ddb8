//! `vitreous sheet RUN...`: one picture that puts what the wearer sees beside a real glass
//! object, for one or more `replay --compare-reference` runs. Each run is a column: on top what
//! the eye sees through the scene's display (its light over the physical reference's seen
//! image, as `compare --display` measures it), below it the physical reference (a real glass
//! object there), both cropped to the object and its shadow; under them
//! the run's scene and effects and its ꟻLIP figures for the object's disc and its shadow, with
//! showing nothing and the additive limit beside them. `tools/demo` ends with one.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde_json::Value;
use vitreous_compare::{Eye, Png, Region, frame_for_scene, regions_of};
use vitreous_frames::input_files::InputFiles;
use vitreous_frames::output::{EYE_NAMES, encode_png, write_atomic};
use vitreous_frames::wearer::WearerView;
use vitreous_scene::Scene;

use crate::font::TextBox;

/// Height of the captions' text, pixels.
const CAPTION_PX: f32 = 15.0;

/// Margin around the crop of the object's disc and its shadow and caustic, as a share of their
/// extent.
const MARGIN: f32 = 0.4;

/// Share of the shadow and caustic's pixels left out at each side of its crop: the caustic's
/// faint tails.
const SHADOW_TAIL: f32 = 0.02;

/// Gap between columns and rows, pixels.
const GAP: u32 = 6;

/// Options of `vitreous sheet` (docs/cli.md).
#[derive(clap::Args, Debug)]
pub struct SheetArgs {
    /// Output folders of `vitreous replay ... --compare-reference` (each with its summary.json
    /// and frames/), one column each, in this order.
    #[arg(required = true, value_name = "RUN")]
    pub runs: Vec<PathBuf>,
    /// The saved frame to show (it must have been measured).
    #[arg(long, default_value_t = 0)]
    pub frame: u64,
    /// The eye to show: left or right.
    #[arg(long, default_value = "left", value_parser = parse_eye)]
    pub eye: Eye,
    /// A column's caption title, once per RUN in order [default: the scene file's name and the
    /// effects].
    #[arg(long = "label", value_name = "TEXT")]
    pub labels: Vec<String>,
    /// The picture to write (PNG).
    #[arg(
        long,
        short = 'o',
        value_name = "FILE",
        default_value = "out/realism-sheet.png"
    )]
    pub out: PathBuf,
}

fn parse_eye(s: &str) -> std::result::Result<Eye, String> {
    match s {
        "left" => Ok(Eye::Left),
        "right" => Ok(Eye::Right),
        _ => Err(format!("expected left or right, found {s:?}")),
    }
}

/// One region's ꟻLIP: what the eye sees, showing nothing, the additive limit.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Figures {
    shown: f64,
    nothing: f64,
    limit: f64,
}

/// One column: its pictures cropped, and its caption.
struct Column {
    /// What the eye sees, then the physical reference, RGBA8, `size` each.
    tiles: [Vec<u8>; 2],
    size: (u32, u32),
    caption: Vec<String>,
}

/// `vitreous sheet`.
pub fn sheet_command(args: SheetArgs) -> Result<()> {
    if !args.labels.is_empty() && args.labels.len() != args.runs.len() {
        bail!(
            "--label: {} given for {} runs: give one per RUN, in order, or none",
            args.labels.len(),
            args.runs.len()
        );
    }
    let eye = EYE_NAMES[args.eye.index()];
    let mut inputs = InputFiles::new();
    let mut runs = Vec::new();
    for run in &args.runs {
        let loaded = Run::load(run, args.frame, eye)?;
        for file in loaded.files() {
            inputs.add(&file, "RUN");
        }
        inputs
            .add(&run.join("summary.json"), "RUN")
            .add(&run.join("frames").join("reference.json"), "RUN");
        inputs.add_scene(&loaded.scene, "RUN's scene");
        runs.push(loaded);
    }
    inputs.check_file("--out", &args.out)?;

    // Every column is cropped to the same size, the largest any run's regions need, about
    // its own object.
    let boxes: Vec<Crop> = runs.iter().map(Run::crop).collect::<Result<_>>()?;
    let size = boxes
        .iter()
        .fold((1, 1), |(w, h), b| (w.max(b.size.0), h.max(b.size.1)));
    let text = TextBox::new(CAPTION_PX)?;
    let mut columns: Vec<Column> = runs
        .iter()
        .zip(&boxes)
        .enumerate()
        .map(|(i, (run, crop))| run.column(crop.centred(size), size, args.labels.get(i)))
        .collect::<Result<_>>()?;
    for column in &mut columns {
        column.caption = column
            .caption
            .iter()
            .flat_map(|line| wrap(&text, line, size.0))
            .collect();
    }

    let title = vec![format!(
        "frame {}, {eye} eye: above, what the wearer sees; below, a real glass object there \
         (the physical reference). ꟻLIP against it, lower is closer",
        args.frame
    )];
    let caption_h = columns
        .iter()
        .map(|c| text.size(&c.caption).1)
        .max()
        .unwrap_or(0);
    let title_h = text.size(&title).1;
    let width = (size.0 + GAP) * columns.len() as u32 + GAP;
    let width = width.max(text.size(&title).0 + 2 * GAP);
    let height = title_h + GAP + 2 * (size.1 + GAP) + caption_h + GAP;
    let mut sheet = vec![0u8; (width * height * 4) as usize];
    for p in sheet.chunks_exact_mut(4) {
        p.copy_from_slice(&[24, 24, 24, 255]);
    }
    text.draw(&mut sheet, (width, height), (GAP, 0), &title);
    let row = |r: u32| title_h + GAP + r * (size.1 + GAP);
    for (i, column) in columns.iter().enumerate() {
        let x = GAP + i as u32 * (column.size.0 + GAP);
        for (r, tile) in column.tiles.iter().enumerate() {
            blit(&mut sheet, width, tile, column.size, (x, row(r as u32)));
        }
        let y = row(2);
        text.draw(&mut sheet, (width, height), (x, y), &column.caption);
    }
    write_atomic(&args.out, &encode_png(&sheet, width, height)?)?;
    println!(
        "wrote {}: {} columns of {} x {} pixel tiles, what the wearer sees from y = {}, the \
         reference from y = {}",
        args.out.display(),
        columns.len(),
        size.0,
        size.1,
        row(0),
        row(1)
    );
    Ok(())
}

/// Copies `tile` (RGBA8, `size`) into `out` (RGBA8, `width` wide) at `at`.
fn blit(out: &mut [u8], width: u32, tile: &[u8], size: (u32, u32), at: (u32, u32)) {
    let row = (size.0 * 4) as usize;
    for y in 0..size.1 {
        let from = (y * size.0 * 4) as usize;
        let to = (((at.1 + y) * width + at.0) * 4) as usize;
        out[to..to + row].copy_from_slice(&tile[from..from + row]);
    }
}

/// A rectangle of an eye image: its top left corner and size, pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Crop {
    at: (u32, u32),
    size: (u32, u32),
    image: (u32, u32),
}

impl Crop {
    /// The rectangle of `size` (at most the image's) with this one's centre, moved inside the
    /// image.
    fn centred(&self, size: (u32, u32)) -> Crop {
        let place = |at: u32, have: u32, want: u32, limit: u32| {
            let want = want.min(limit);
            let centre = at + have / 2;
            (centre.saturating_sub(want / 2).min(limit - want), want)
        };
        let (x, w) = place(self.at.0, self.size.0, size.0, self.image.0);
        let (y, h) = place(self.at.1, self.size.1, size.1, self.image.1);
        Crop {
            at: (x, y),
            size: (w, h),
            image: self.image,
        }
    }

    /// The pixels of `image` (RGBA8, `self.image`) inside the rectangle, opaque, in a tile of
    /// `size`; black where the tile is larger (another run's image was larger than this one).
    fn cut(&self, image: &[u8], size: (u32, u32)) -> Vec<u8> {
        let mut out = [0, 0, 0, 255].repeat((size.0 * size.1) as usize);
        for y in 0..size.1.min(self.size.1) {
            for x in 0..size.0.min(self.size.0) {
                let from = (((self.at.1 + y) * self.image.0 + self.at.0 + x) * 4) as usize;
                let to = ((y * size.0 + x) * 4) as usize;
                out[to..to + 4].copy_from_slice(&image[from..from + 4]);
                out[to + 3] = 255;
            }
        }
        out
    }
}

/// One `replay --compare-reference` run's frame and eye, read.
struct Run {
    dir: PathBuf,
    scene: Scene,
    effects: String,
    eye: &'static str,
    frame: u64,
    disc: Figures,
    shadow: Figures,
}

impl Run {
    /// Reads `dir`'s summary.json and scene, and checks that it measured `frame`'s `eye`.
    fn load(dir: &Path, frame: u64, eye: &'static str) -> Result<Run> {
        let summary_path = dir.join("summary.json");
        let bytes = std::fs::read(&summary_path).with_context(|| {
            format!(
                "reading {} (RUN is a `vitreous replay ... --compare-reference` output folder)",
                summary_path.display()
            )
        })?;
        let summary: Value = serde_json::from_slice(&bytes)
            .with_context(|| format!("{}: not a replay's summary.json", summary_path.display()))?;
        let text = |key: &str| -> Result<String> {
            summary[key]
                .as_str()
                .map(str::to_owned)
                .with_context(|| format!("{}: no \"{key}\" text", summary_path.display()))
        };
        let scene_path = PathBuf::from(text("scene")?);
        let scene_hash = text("scene_hash")?;
        let effects = text("effects")?;
        let mut scene = vitreous_scene::load_scene(&scene_path).with_context(|| {
            format!(
                "{}: its scene {} (a path from where the replay ran)",
                summary_path.display(),
                scene_path.display()
            )
        })?;
        if scene.hash != scene_hash {
            bail!(
                "{}: made with an earlier version of {} (its scene_hash differs): replay it \
                 again",
                summary_path.display(),
                scene_path.display()
            );
        }
        if scene.caustics.bake.is_some()
            && let Err(e) = scene.load_caustics()
        {
            tracing::warn!("the caustic is left out of the crop: {e}");
        }
        let Some(measured) = summary["compare_reference"].as_array() else {
            bail!(
                "{}: no compare_reference figures: run the replay with --compare-reference",
                summary_path.display()
            );
        };
        let Some(entry) = measured
            .iter()
            .find(|e| e["frame"].as_u64() == Some(frame) && e["eye"].as_str() == Some(eye))
        else {
            bail!(
                "{}: frame {frame}'s {eye} eye was not measured against the reference (a saved \
                 frame: --save-every, --frames); see --frame and --eye",
                summary_path.display()
            );
        };
        let figures = |region: &str| -> Result<Figures> {
            let of = |list: &str| {
                entry[list].as_array().and_then(|rows| {
                    rows.iter()
                        .find(|r| r["region"].as_str() == Some(region))
                        .and_then(|r| r["flip_mean"].as_f64())
                })
            };
            match (of("regions"), of("nothing_drawn"), of("additive_limit")) {
                (Some(shown), Some(nothing), Some(limit)) => Ok(Figures {
                    shown,
                    nothing,
                    limit,
                }),
                _ => bail!(
                    "{}: frame {frame} {eye}: no ꟻLIP figures for the region {region}",
                    summary_path.display()
                ),
            }
        };
        Ok(Run {
            dir: dir.to_path_buf(),
            disc: figures(Region::Disc.name())?,
            shadow: figures(Region::ShadowCaustic.name())?,
            scene,
            effects,
            eye,
            frame,
        })
    }

    /// The frame's images: the eye's light, the seen image, the physical reference.
    fn files(&self) -> [PathBuf; 3] {
        let stem = format!("{:06}-{}", self.frame, self.eye);
        let frames = self.dir.join("frames");
        [
            frames.join(format!("{stem}.png")),
            frames.join(format!("{stem}-seen.png")),
            frames.join(format!("{stem}-real.png")),
        ]
    }

    /// The rectangle around the object's disc and its shadow and caustic, as the reference.json
    /// beside the reference image places them, with a margin.
    fn crop(&self) -> Result<Crop> {
        let [_, _, real] = self.files();
        let png = Png::read(&real)?;
        let (w, h) = (png.width, png.height);
        let Some(listed) = frame_for_scene(&real, &self.scene, Some(eye_index(self.eye)))? else {
            bail!(
                "{}: not listed in the reference.json beside it: replay with --compare-reference \
                 again",
                real.display()
            );
        };
        let labels = regions_of(
            &self.scene,
            &listed.frame.eyes[listed.eye].camera(),
            &listed.frame.placement(),
            w,
            h,
        );
        let pixels = |region: Region| -> Vec<(u32, u32)> {
            labels
                .iter()
                .enumerate()
                .filter(|(_, r)| **r == region)
                .map(|(i, _)| ((i as u32) % w, (i as u32) / w))
                .collect()
        };
        let disc = pixels(Region::Disc);
        if disc.is_empty() {
            bail!(
                "{}: the object is not in frame {}'s {} eye",
                self.dir.display(),
                self.frame,
                self.eye
            );
        }
        // The disc whole; the shadow and caustic without the few texels of the caustic's
        // faint tails that reach across the floor.
        let (mut lo, mut hi) = bounds(&disc, 0.0);
        if let Some((shadow_lo, shadow_hi)) = Some(pixels(Region::ShadowCaustic))
            .filter(|p| !p.is_empty())
            .map(|p| bounds(&p, SHADOW_TAIL))
        {
            lo = (lo.0.min(shadow_lo.0), lo.1.min(shadow_lo.1));
            hi = (hi.0.max(shadow_hi.0), hi.1.max(shadow_hi.1));
        }
        let grow = |lo: u32, hi: u32, limit: u32| {
            let margin = ((hi - lo) as f32 * MARGIN).ceil() as u32;
            (lo.saturating_sub(margin), (hi + margin).min(limit))
        };
        let (x0, x1) = grow(lo.0, hi.0, w);
        let (y0, y1) = grow(lo.1, hi.1, h);
        Ok(Crop {
            at: (x0, y0),
            size: (x1 - x0, y1 - y0),
            image: (w, h),
        })
    }

    /// The column: what the eye sees and the reference inside `crop`, in tiles of `size`, and
    /// the caption.
    fn column(&self, crop: Crop, size: (u32, u32), label: Option<&String>) -> Result<Column> {
        let [light, seen, real] = self.files();
        let real = Png::read(&real)?;
        let light = Png::read_like(&light, &real)?;
        let seen = Png::read_like(&seen, &real)?;
        let shown = WearerView::of_scene(&self.scene).see(
            &light.rgba,
            &seen.rgba,
            [real.width, real.height],
        );
        let name = self.scene.path.file_name().map_or_else(
            || self.scene.path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        let title = label
            .cloned()
            .unwrap_or_else(|| format!("{name}, effects {}", self.effects));
        let line = |what: &str, f: Figures| {
            format!(
                "{what} {:.3}  (nothing {:.3}, limit {:.3})",
                f.shown, f.nothing, f.limit
            )
        };
        Ok(Column {
            tiles: [crop.cut(&shown, size), crop.cut(&real.rgba, size)],
            size,
            caption: vec![title, line("disc", self.disc), line("shadow", self.shadow)],
        })
    }
}

/// `line` broken between words into lines whose box is at most `width` pixels wide (a word
/// wider than that on a line of its own).
fn wrap(text: &TextBox, line: &str, width: u32) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in line.split(' ') {
        match lines.last_mut() {
            Some(last) if text.size(&[format!("{last} {word}")]).0 <= width => {
                last.push(' ');
                last.push_str(word);
            }
            _ => lines.push(word.to_owned()),
        }
    }
    lines
}

/// The rectangle `(lo, hi)` (hi exclusive) that holds `pixels` but for the share `tail` of them
/// at each side along each axis (not empty).
fn bounds(pixels: &[(u32, u32)], tail: f32) -> ((u32, u32), (u32, u32)) {
    let range = |mut values: Vec<u32>| {
        values.sort_unstable();
        let cut = ((values.len() as f32 * tail) as usize).min(values.len() - 1);
        (values[cut], values[values.len() - 1 - cut] + 1)
    };
    let (x0, x1) = range(pixels.iter().map(|p| p.0).collect());
    let (y0, y1) = range(pixels.iter().map(|p| p.1).collect());
    ((x0, y0), (x1.max(x0 + 1), y1.max(y0 + 1)))
}

/// 0 for `left`, 1 for `right`.
fn eye_index(eye: &str) -> usize {
    usize::from(eye == "right")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_crop_grown_to_another_size_keeps_its_centre_inside_the_image() {
        let crop = Crop {
            at: (100, 50),
            size: (40, 20),
            image: (320, 240),
        };
        let grown = crop.centred((80, 60));
        assert_eq!(grown.size, (80, 60));
        assert_eq!(grown.at, (80, 30));
        // Near the edge: moved inside, not cut.
        let edge = Crop {
            at: (300, 230),
            size: (20, 10),
            image: (320, 240),
        }
        .centred((80, 60));
        assert_eq!(edge.at, (240, 180));
        // Larger than the image: the image.
        let whole = crop.centred((1000, 1000));
        assert_eq!((whole.at, whole.size), ((0, 0), (320, 240)));
    }

    #[test]
    fn captions_wrap_between_words_to_the_columns_width() {
        let text = TextBox::new(CAPTION_PX).unwrap();
        let line = "the paper's conditions (glass-sphere, inducer + caustics)";
        let whole = text.size(&[line.to_owned()]).0;
        assert_eq!(wrap(&text, line, whole), vec![line.to_owned()]);
        let wrapped = wrap(&text, line, whole / 2);
        assert!(wrapped.len() >= 2, "{wrapped:?}");
        assert_eq!(wrapped.join(" "), line);
        assert!(
            wrapped
                .iter()
                .all(|l| text.size(std::slice::from_ref(l)).0 <= whole / 2)
        );
    }

    #[test]
    fn bounds_leave_out_a_share_of_stray_pixels_at_each_side() {
        let mut pixels: Vec<(u32, u32)> = (0..100).map(|i| (10 + i % 10, 20 + i / 10)).collect();
        assert_eq!(bounds(&pixels, 0.0), ((10, 20), (20, 30)));
        pixels.push((300, 200));
        assert_eq!(bounds(&pixels, 0.0), ((10, 20), (301, 201)));
        assert_eq!(bounds(&pixels, 0.02), ((10, 20), (20, 30)));
        assert_eq!(bounds(&[(5, 6)], 0.4), ((5, 6), (6, 7)));
    }

    #[test]
    fn a_cut_copies_the_rectangle_and_makes_it_opaque() {
        let image: Vec<u8> = (0..4 * 3).flat_map(|i| [i as u8, 0, 0, 7]).collect();
        let crop = Crop {
            at: (1, 1),
            size: (2, 2),
            image: (4, 3),
        };
        let out = crop.cut(&image, (3, 2));
        // Row 1, columns 1 and 2, then black where the tile is wider than the crop.
        assert_eq!(&out[0..4], &[5, 0, 0, 255]);
        assert_eq!(&out[4..8], &[6, 0, 0, 255]);
        assert_eq!(&out[8..12], &[0, 0, 0, 255]);
        assert_eq!(&out[12..16], &[9, 0, 0, 255]);
    }
}
