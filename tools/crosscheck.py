"""The reference's image of a glass object against Mitsuba 3's path tracer (tools/crosscheck).

Reads the scene (TOML), the reference's reference.json and left-eye images (PNG and
OpenEXR), renders the pixels about the object (an analytic ball, or a clear-glass .glb mesh
with its vertex normals) with Mitsuba's `path` integrator over the same grid of positions per pixel and
the same eye rays, with the room built as the reference's docs state it (the photos as emitting
rectangles, decoded from sRGB; the environment map with its rows where docs/config.md puts
them), and writes the reference's image with those pixels replaced, once with the world in the
scene's metres and once moved so that the object's centre is the origin and scaled by 1000.
Mitsuba starts each ray leaving a surface a distance off it that grows with the coordinates'
size (about 0.2 mm at 1.5 m from the origin): the second render takes that out.

usage: crosscheck.py SCENE REFERENCE_DIR OUT_DIR PER_SIDE PATHS
"""

import json
import math
import struct
import sys
import tomllib
from pathlib import Path

import numpy as np
import mitsuba as mi

mi.set_variant("llvm_ad_rgb")
from PIL import Image  # noqa: E402

SCALE = 1000.0
# Path segments: the reference's 256 interfaces (app/reference/src/world.rs MAX_INTERFACES) and
# the last way out; a round brilliant's light is still 1 % short at 64.
MAX_DEPTH = 257


def fail(message):
    print(f"tools/crosscheck: {message}", file=sys.stderr)
    sys.exit(1)


def srgb_to_linear(c):
    c = c / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def linear_to_srgb8(x):
    x = np.clip(x, 0.0, 1.0)
    s = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x ** (1 / 2.4) - 0.055)
    return np.round(s * 255).astype(np.uint8)


def photo(path):
    """A photo as linear RGB rows from the bottom up (Mitsuba's v grows upwards)."""
    rgb = np.asarray(Image.open(path).convert("RGB")).astype(np.float64)
    return np.flipud(srgb_to_linear(rgb)).astype(np.float32).copy()


def environment(path, out):
    """The map resampled so that Mitsuba's rows (centres from the zenith to the nadir) give
    what the project's (texel centres at half-integers, docs/config.md) give: exact, the
    project's lookup being linear between rows."""
    env = np.array(mi.Bitmap(str(path)).convert(
        mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False))
    h = env.shape[0]
    rows = 4 * h + 1
    y = np.arange(rows) / (rows - 1) * h - 0.5
    y0 = np.floor(y).astype(int)
    fy = (y - y0)[:, None, None]
    resampled = env[np.clip(y0, 0, h - 1)] * (1 - fy) + env[np.clip(y0 + 1, 0, h - 1)] * fy
    mi.Bitmap(resampled.astype(np.float32)).write(str(out))


def glb_mesh(path):
    """Positions, normals and triangles of a binary glTF's triangle primitives (nodes without
    transforms of their own; the shipped procedural models are so)."""
    data = path.read_bytes()
    if data[:4] != b"glTF":
        fail(f"{path}: not a binary glTF (.glb); only .glb models are read here")
    length = struct.unpack_from("<I", data, 12)[0]
    gltf = json.loads(data[20:20 + length])
    binary = data[20 + length + 8:]
    for node in gltf.get("nodes", []):
        if any(k in node for k in ("matrix", "translation", "rotation", "scale")):
            fail(f"{path}: a node with its own transform; not read here")

    def accessor(i, width):
        a = gltf["accessors"][i]
        view = gltf["bufferViews"][a["bufferView"]]
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        kind = {5126: np.float32, 5125: np.uint32, 5123: np.uint16}[a["componentType"]]
        values = np.frombuffer(binary, kind, a["count"] * width, start)
        return values.reshape(-1, width) if width > 1 else values

    positions, normals, faces = [], [], []
    for mesh in gltf["meshes"]:
        for prim in mesh["primitives"]:
            if prim.get("mode", 4) != 4 or "NORMAL" not in prim["attributes"]:
                fail(f"{path}: a primitive that is not a triangle list with normals")
            base = sum(len(p) for p in positions)
            positions.append(accessor(prim["attributes"]["POSITION"], 3).astype(np.float64))
            normals.append(accessor(prim["attributes"]["NORMAL"], 3).astype(np.float64))
            faces.append(accessor(prim["indices"], 1).astype(np.uint32).reshape(-1, 3) + base)
    return np.concatenate(positions), np.concatenate(normals), np.concatenate(faces)


def rotation(degrees):
    """docs/config.md's rotation_deg: about world x, then y, then z (Rz Ry Rx)."""
    x, y, z = (math.radians(a) for a in degrees)
    rx = np.array([[1, 0, 0], [0, math.cos(x), -math.sin(x)], [0, math.sin(x), math.cos(x)]])
    ry = np.array([[math.cos(y), 0, math.sin(y)], [0, 1, 0], [-math.sin(y), 0, math.cos(y)]])
    rz = np.array([[math.cos(z), -math.sin(z), 0], [math.sin(z), math.cos(z), 0], [0, 0, 1]])
    return rz @ ry @ rx


def world_mesh(obj, scene_dir):
    """The object's mesh in world metres (docs/config.md: T(position) R S T(-box centre)),
    with its bounding sphere's centre and radius as `vitreous compare` takes them."""
    positions, normals, faces = glb_mesh(scene_dir / obj["model"])
    lo, hi = positions.min(0), positions.max(0)
    box_centre = (lo + hi) / 2
    scale = obj["diameter_m"] / (hi - lo).max() if "diameter_m" in obj else obj.get("scale", 1.0)
    rot = rotation(obj.get("rotation_deg", [0.0, 0.0, 0.0]))
    centre = np.array(obj["position_m"], dtype=np.float64)
    world = (positions - box_centre) * scale @ rot.T + centre
    world_normals = normals @ rot.T
    radius = np.linalg.norm(positions - box_centre, axis=1).max() * scale
    return world, world_normals, faces, centre, radius


def plane_transform(base, table):
    size = table.get("size_m")
    position = table.get("position_m", [0.0, 0.0, 0.0])
    rx, ry, rz = table.get("rotation_deg", [0.0, 0.0, 0.0])
    if size is None:
        fail("a plane without size_m")
    return (base.translate(position).rotate([0, 0, 1], rz).rotate([0, 1, 0], ry)
            .rotate([1, 0, 0], rx).scale([size[0] / 2, size[1] / 2, 1.0]))


def build(scene, scene_dir, centre, radius, mesh, env_file, scale, centred):
    T = mi.ScalarTransform4f
    shift = centre if centred else np.zeros(3)
    base = lambda: T().scale(scale).translate((-shift).tolist())  # noqa: E731
    black = {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}
    world = {"type": "scene"}
    for name in ("floor", "background"):
        table = scene.get(name)
        if table is None:
            continue
        world[name] = {
            "type": "rectangle",
            "to_world": plane_transform(base(), table),
            "bsdf": black,
            "emitter": {"type": "area", "radiance": {
                "type": "bitmap", "data": mi.TensorXf(photo(scene_dir / table["photo"])),
                "raw": True, "filter_type": "bilinear", "wrap_mode": "clamp"}},
        }
    yaw = scene.get("environment", {}).get("yaw_deg", 0.0)
    world["environment"] = {"type": "envmap", "filename": str(env_file),
                            "to_world": T().rotate([0, 1, 0], 180.0 + yaw)}
    glass = {"type": "dielectric", "int_ior": scene["object"].get("ior", 1.5), "ext_ior": 1.0}
    if mesh is None:
        world["object"] = {"type": "sphere", "center": (scale * (centre - shift)).tolist(),
                           "radius": radius * scale, "bsdf": glass}
    else:
        positions, normals, faces = mesh
        shape = mi.Mesh("object", len(positions), len(faces), has_vertex_normals=True)
        params = mi.traverse(shape)
        params["vertex_positions"] = mi.Float(
            (scale * (positions - shift)).astype(np.float32).ravel())
        params["vertex_normals"] = mi.Float(normals.astype(np.float32).ravel())
        params["faces"] = mi.UInt32(faces.ravel())
        params.update()
        shape.set_bsdf(mi.load_dict(glass))
        world["object"] = shape
    return mi.load_dict(world), shift


def eye_rays(eye, size):
    """Unit directions of pixel positions (x right, y down) of an eye record."""
    q = eye["orientation_xyzw"]
    x, y, z, w = q
    rot = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    left, right, up, down = (math.tan(a) for a in eye["fov_rad"])

    def direction(px, py):
        tx = left + (right - left) * px / size[0]
        ty = up - (up - down) * py / size[1]
        d = np.stack([tx, ty, -np.ones_like(tx)], -1)
        d /= np.linalg.norm(d, axis=-1, keepdims=True)
        return d @ rot.T

    return direction


def render(world, shift, scale, eye, direction, window, per_side, paths):
    x0, y0, w, h = window
    integrator = mi.load_dict({"type": "path", "max_depth": MAX_DEPTH, "rr_depth": 1000})
    origin = scale * (np.array(eye["position_m"], dtype=np.float64) - shift)
    out = np.zeros((h, w, 3))
    rows = max(1, 400_000 // (w * per_side * per_side * paths))
    for top in range(y0, y0 + h, rows):
        n = min(rows, y0 + h - top)
        jj, ii, sj, si, _ = np.meshgrid(np.arange(top, top + n), np.arange(x0, x0 + w),
                                        np.arange(per_side), np.arange(per_side),
                                        np.arange(paths), indexing="ij")
        d = direction(ii + (si + 0.5) / per_side, jj + (sj + 0.5) / per_side).reshape(-1, 3)
        m = d.shape[0]
        ray = mi.Ray3f(mi.Point3f(*[np.full(m, c, np.float32) for c in origin]),
                       mi.Vector3f(*[d[:, k].astype(np.float32) for k in range(3)]))
        sampler = mi.load_dict({"type": "independent"})
        sampler.seed(top, m)
        light = integrator.sample(world, sampler, ray)[0]
        light = np.stack([np.array(light[k]) for k in range(3)], -1)
        out[top - y0:top - y0 + n] = light.reshape(n, w, -1, 3).mean(axis=2)
        print(f"\r  rows {top + n - y0}/{h}", end="", file=sys.stderr, flush=True)
    print(file=sys.stderr)
    return out


def main():
    scene_path, ref_dir, out_dir = Path(sys.argv[1]), Path(sys.argv[2]), Path(sys.argv[3])
    per_side, paths = int(sys.argv[4]), int(sys.argv[5])
    scene = tomllib.loads(scene_path.read_text())
    scene_dir = scene_path.parent
    report = json.loads((ref_dir / "reference.json").read_text())
    obj = scene["object"]
    if "attenuation_distance_m" in obj or "surface_texture" in obj:
        fail(f"{scene_path}: tinted or textured glass is not modelled here")
    if "environment" not in scene or "map" not in scene["environment"]:
        fail(f"{scene_path}: [environment] map is needed")
    frame = report["frames"][0]
    eye = frame["eyes"][0]
    size = (report["width_px"], report["height_px"])
    if report.get("object") == "analytic ball":
        if "diameter_m" not in obj:
            fail(f"{scene_path}: [object] diameter_m is needed for the ball's radius")
        centre = np.array(frame["object_position_m"], dtype=np.float64)
        radius = obj["diameter_m"] / 2
        mesh = None
    else:
        positions, normals, faces, centre, radius = world_mesh(obj, scene_dir)
        mesh = (positions, normals, faces)
        if np.abs(centre - np.array(frame["object_position_m"])).max() > 1e-6:
            fail(f"{scene_path}: the object is placed elsewhere than position_m at rest")
    env_file = out_dir / "environment-mitsuba.exr"
    environment(scene_dir / scene["environment"]["map"], env_file)

    # The window: the object's bounding sphere's outline and a few pixels around it.
    direction = eye_rays(eye, size)
    ys, xs = np.mgrid[0:size[1], 0:size[0]] + 0.5
    d = direction(xs, ys)
    to_centre = centre - np.array(eye["position_m"])
    along = d @ to_centre
    off = np.linalg.norm(to_centre[None, None] - d * along[..., None], axis=-1)
    disc = (along > 0) & (off < radius)
    near = (along > 0) & (off < radius * 1.15)
    if not disc.any():
        fail("the object is not in the left eye's view")
    rows, cols = np.nonzero(near)
    window = (int(cols.min()), int(rows.min()), int(cols.max() - cols.min() + 1),
              int(rows.max() - rows.min() + 1))
    x0, y0, w, h = window

    base = np.asarray(Image.open(ref_dir / "000000-left.png").convert("RGB"))
    reference = srgb_to_linear(base.astype(np.float64))
    reference_hdr = np.array(mi.Bitmap(str(ref_dir / "000000-left.exr")).convert(
        mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, srgb_gamma=False), dtype=np.float64)
    figures = {"scene": str(scene_path), "window_px": list(window), "per_side": per_side,
               "paths_per_position": paths, "disc_pixels": int(disc.sum()), "renders": {}}
    for name, scale, centred in (("in-place", 1.0, False), ("centred", SCALE, True)):
        print(f"Mitsuba, {name}: {w} x {h} pixels, {per_side}x{per_side} positions x {paths} paths",
              file=sys.stderr)
        world, shift = build(scene, scene_dir, centre, radius, mesh, env_file, scale, centred)
        light = render(world, shift, scale, eye, direction, window, per_side, paths)
        image = base.copy()
        image[y0:y0 + h, x0:x0 + w] = linear_to_srgb8(light)
        image_path = out_dir / f"mitsuba-{name}.png"
        Image.fromarray(image).save(image_path)
        eight_bit = srgb_to_linear(image.astype(np.float64))
        mean_ref = reference[disc].sum(1).mean()
        hdr = np.zeros(reference.shape)
        hdr[y0:y0 + h, x0:x0 + w] = light
        figures["renders"][name] = {
            "image": image_path.name,
            "disc_mean_reference": mean_ref,
            "disc_mean_reference_unclipped": reference_hdr[disc].sum(1).mean(),
            "disc_mean_8bit": eight_bit[disc].sum(1).mean(),
            "disc_mean_unclipped": hdr[disc].sum(1).mean(),
        }
    (out_dir / "crosscheck-means.json").write_text(json.dumps(figures, indent=2))


if __name__ == "__main__":
    main()
