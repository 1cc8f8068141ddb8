"""ColorVideoVDP (cvvdp) of what the wearer sees against the physical reference.

Called by tools/perceived, which installs cvvdp and makes the images: for each look a
`vitreous replay --compare-reference` folder, and beside each saved eye image the wearer's
views `vitreous compare --wearer-view` composed, registered and misregistered, with the
registered comparison's JSON (`NNNNNN-EYE-view.json`: the pixels per degree the images are
rated at). With --video, each eye's registered views are also rated as one video at the
replay's frame rate (its summary.json), over the whole view.

Each figure is ColorVideoVDP's quality in JOD (just-objectionable differences; 10 is
indistinguishable from the reference, higher is closer), over the whole view and over a crop
about the object: the box where the reference with the real object differs from the seen image
without it, widened by 1.5 degrees. Beside the look: showing nothing (the seen image itself)
and the additive limit (the per-pixel maximum of the seen image and the reference, the closest
a display that only adds light can get).
"""

import argparse
import json
import re
import sys
from pathlib import Path

import numpy as np
import pycvvdp
import torch
from PIL import Image


def load(path):
    return np.array(Image.open(path).convert("RGB"))


def pixels_per_degree(report):
    """The pixels per degree `vitreous compare --json` measured the image at."""
    return float(json.loads(Path(report).read_text())["pixels_per_degree"])


def crop_about_object(real, seen, ppd):
    """The box where the real object changes the view, widened by 1.5 degrees."""
    changed = np.abs(real.astype(np.int32) - seen.astype(np.int32)).sum(axis=2) > 6
    ys, xs = np.nonzero(changed)
    if len(ys) == 0:
        return None
    pad = int(round(1.5 * ppd))
    h, w = changed.shape
    return (max(0, ys.min() - pad), min(h, ys.max() + 1 + pad),
            max(0, xs.min() - pad), min(w, xs.max() + 1 + pad))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path, help="write the figures here as JSON")
    parser.add_argument("--video", action="store_true",
                        help="also rate each eye's frames as one video (whole view, registered), "
                             "at the replay's frame rate")
    parser.add_argument("looks", nargs="+", metavar="LABEL=FOLDER",
                        help="a replay --compare-reference folder and its label")
    args = parser.parse_args()

    metrics = {}

    def jod(test, reference, ppd):
        h, w = reference.shape[:2]
        if (w, h, ppd) not in metrics:
            geometry = pycvvdp.vvdp_display_geometry((w, h), distance_m=1.0, ppd=ppd)
            # An sRGB display of 200 cd/m^2 peak, 1000:1, in a dark room.
            photometry = pycvvdp.vvdp_display_photo_eotf(
                Y_peak=200, contrast=1000, source_colorspace="sRGB")
            metrics[(w, h, ppd)] = pycvvdp.cvvdp(
                display_name="standard_fhd", display_photometry=photometry,
                display_geometry=geometry, quiet=True, device=torch.device("cpu"))
        with torch.no_grad():
            q, _ = metrics[(w, h, ppd)].predict(
                torch.from_numpy(np.ascontiguousarray(test)),
                torch.from_numpy(np.ascontiguousarray(reference)), dim_order="HWC")
        return round(float(q), 4)

    def jod_video(frames, references, fps, ppd):
        jod(references[0], references[0], ppd)  # the metric for this size
        h, w = references[0].shape[:2]
        with torch.no_grad():
            q, _ = metrics[(w, h, ppd)].predict(
                torch.from_numpy(np.stack(frames)), torch.from_numpy(np.stack(references)),
                dim_order="FHWC", frames_per_second=fps)
        return round(float(q), 4)

    rows = []
    for look in args.looks:
        label, _, folder = look.partition("=")
        frames = Path(folder) / "frames"
        reals = sorted(frames.glob("*-real.png"))
        if not reals:
            sys.exit(f"perceived: {frames}: no NNNNNN-EYE-real.png (replay --compare-reference)")
        for real_path in reals:
            stem = real_path.name[: -len("-real.png")]
            real = load(real_path)
            seen = load(frames / f"{stem}-seen.png")
            ppd = pixels_per_degree(frames / f"{stem}-view.json")
            box = crop_about_object(real, seen, ppd)
            if box is None:
                continue

            def both(image):
                y0, y1, x0, x1 = box
                return {"crop": jod(image[y0:y1, x0:x1], real[y0:y1, x0:x1], ppd),
                        "whole": jod(image, real, ppd)}

            row = {"look": label, "image": stem, "crop_px": [int(v) for v in box],
                   "nothing": both(seen), "additive_limit": both(np.maximum(seen, real)),
                   "views": {}}
            pattern = re.compile(re.escape(stem) + r"-view(.*)\.png$")
            for view in sorted(frames.glob(f"{stem}-view*.png")):
                shift = pattern.match(view.name).group(1).lstrip("_") or "0"
                row["views"][shift] = both(load(view))
            rows.append(row)
            views = "  ".join(f"{k}: {v['crop']:.3f}/{v['whole']:.3f}"
                              for k, v in row["views"].items())
            print(f"{label:<24} {stem:<14} nothing {row['nothing']['crop']:.3f}/"
                  f"{row['nothing']['whole']:.3f}  limit {row['additive_limit']['crop']:.3f}/"
                  f"{row['additive_limit']['whole']:.3f}  {views}", flush=True)
    videos = []
    if args.video:
        for look in args.looks:
            label, _, folder = look.partition("=")
            videos.extend(rate_videos(label, Path(folder), jod_video))
    if args.json:
        args.json.write_text(json.dumps({"images": rows, "videos": videos}, indent=1) + "\n")


def rate_videos(label, folder, jod_video):
    """Each eye's registered views, the seen images and the additive limit as videos against
    the reference's frames, at the frame rate of the replay's frames.csv."""
    frames = folder / "frames"
    fps = float(json.loads((folder / "summary.json").read_text())["frame_rate_hz"])
    out = []
    for eye in ("left", "right"):
        stems = [p.name[: -len("-real.png")] for p in sorted(frames.glob(f"*-{eye}-real.png"))]
        if len(stems) < 2:
            continue
        real = [load(frames / f"{s}-real.png") for s in stems]
        seen = [load(frames / f"{s}-seen.png") for s in stems]
        views = [load(frames / f"{s}-view.png") for s in stems]
        limit = [np.maximum(a, b) for a, b in zip(seen, real)]
        ppd = pixels_per_degree(frames / f"{stems[0]}-view.json")
        row = {"look": label, "eye": eye, "frames": len(stems), "fps": round(fps, 3),
               "drawn": jod_video(views, real, fps, ppd),
               "nothing": jod_video(seen, real, fps, ppd),
               "additive_limit": jod_video(limit, real, fps, ppd)}
        out.append(row)
        print(f"{label:<24} {eye} video, {len(stems)} frames at {fps:.1f} Hz: drawn "
              f"{row['drawn']:.3f}  nothing {row['nothing']:.3f}  limit "
              f"{row['additive_limit']:.3f}", flush=True)
    return out


if __name__ == "__main__":
    main()
