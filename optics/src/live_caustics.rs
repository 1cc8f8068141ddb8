//! The settings of the caustic gain map the renderer computes for each pose of the object and
//! the light on the GPU (`[caustics] mode = "live"`, docs/caustics.md): photons, path length
//! and smoothing, their defaults, and the limits a scene file is held to.

/// How caustics are computed live.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiveCausticsDesc {
    /// Photons along each side of the emission grid (its square is the photon count).
    pub photons_per_side: u32,
    /// Most reflections and refractions on one light path (the bake's default: 12).
    pub max_interactions: u32,
    /// Light paths carrying less than this share of their photon's light end (greater than
    /// 0, less than 1; the bake follows them to 1e-4).
    pub min_path_weight: f32,
    /// Radius of the box the map is smoothed with, texels of the map (0: not smoothed): each
    /// texel becomes the mean of the 2 r + 1 texels around it, three times along the rows,
    /// then three times along the columns, a kernel close to a Gaussian of standard deviation
    /// sqrt(r (r + 1)) texels, 6r + 1 texels wide.
    pub smoothing_px: u32,
    /// Whether a smoothing of radius 0 to 2 skips the tiles whose gains are certain to be
    /// stored as 0 (docs/caustics.md, *Smoothing*); the map is the same either way.
    pub skip_tiles: bool,
}

impl Default for LiveCausticsDesc {
    /// 128 x 128 photons, 12 interactions, paths ending below [`MIN_WEIGHT`], a smoothing box
    /// of radius 2 texels (on the default
    /// [`DEFAULT_RESOLUTION_PX`] map, the glass sphere's map within 0.6 % of its bake and the
    /// diamond's within 3.3 %, both bakes averaged to that resolution and smoothed alike;
    /// docs/caustics.md).
    fn default() -> LiveCausticsDesc {
        LiveCausticsDesc {
            photons_per_side: 128,
            max_interactions: 12,
            min_path_weight: MIN_WEIGHT,
            smoothing_px: 2,
            skip_tiles: true,
        }
    }
}

/// Default side of the live gain map, texels: 1 mm texels on the shipped 1 m floors, half the
/// bakes' 1980. Smoothed with the default box (standard deviation sqrt(6) texels, 2.5 mm
/// there) it keeps as much detail as the bakes' resolution smoothed with a box of radius 5
/// (2.8 mm), at a quarter of the texels each computation clears, smooths and copies.
pub const DEFAULT_RESOLUTION_PX: u32 = 990;

/// Largest photon grid side accepted.
pub const MAX_PHOTONS_PER_SIDE: u32 = 4096;
/// Largest smoothing box radius accepted, texels.
pub const MAX_SMOOTHING_PX: u32 = 64;
/// Paths below this weight end by default. The bake follows them to 1e-4; the live maps of the
/// sphere, the diamond and the torus are as close to their bakes with 1e-2 (0.52 %, 3.23 % and
/// 3.38 % against 0.51 %, 3.23 % and 3.40 %), and the sphere's stage after a move costs about
/// 10 ms less on lavapipe (a ball's second internal reflection, 0.16 % of the light, is one
/// more walk through the glass for every photon).
pub const MIN_WEIGHT: f32 = 1e-2;
