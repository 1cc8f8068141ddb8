"""ColorVideoVDP (cvvdp) of what the wearer sees against the physical reference.

Called by tools/perceived, which installs cvvdp and makes the images: for each look a
`vitreous replay --compare-reference` folder, and beside each saved eye image the wearer's
views `vitreous compare --wearer-view` composed, registered and misregistered.

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
    parser.add_argument("--ppd", type=float, default=32.0,
                        help="pixels per degree of the images (the shipped scenes: 32)")
    parser.add_argument("--json", type=Path, help="write the figures here as JSON")
    parser.add_argument("looks", nargs="+", metavar="LABEL=FOLDER",
                        help="a replay --compare-reference folder and its label")
    args = parser.parse_args()

    metrics = {}

    def jod(test, reference):
        h, w = reference.shape[:2]
        if (w, h) not in metrics:
            geometry = pycvvdp.vvdp_display_geometry((w, h), distance_m=1.0, ppd=args.ppd)
            # An sRGB display of 200 cd/m^2 peak, 1000:1, in a dark room.
            photometry = pycvvdp.vvdp_display_photo_eotf(
                Y_peak=200, contrast=1000, source_colorspace="sRGB")
            metrics[(w, h)] = pycvvdp.cvvdp(
                display_name="standard_fhd", display_photometry=photometry,
                display_geometry=geometry, quiet=True, device=torch.device("cpu"))
        with torch.no_grad():
            q, _ = metrics[(w, h)].predict(
                torch.from_numpy(np.ascontiguousarray(test)),
                torch.from_numpy(np.ascontiguousarray(reference)), dim_order="HWC")
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
            box = crop_about_object(real, seen, args.ppd)
            if box is None:
                continue

            def both(image):
                y0, y1, x0, x1 = box
                return {"crop": jod(image[y0:y1, x0:x1], real[y0:y1, x0:x1]),
                        "whole": jod(image, real)}

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
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")


if __name__ == "__main__":
    main()
