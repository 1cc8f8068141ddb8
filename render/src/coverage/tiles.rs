//! An eye's image in tiles, sets of them (those the frame's proof covers, those the glass
//! shows in), and the image split into rectangles for the two glass pipelines: covered tiles
//! without the environment's lookup, the rest of the glass with it.

/// Tiles per side of an eye's image in [`Tiles`]: at 1280 x 960, 40 x 30 pixels each,
/// fine enough that the thin band at a ball's rim whose rays pass beside the photo through
/// two surfaces costs the lookup in a few tiles' width rather than a quarter of the image.
pub const TILES: u32 = u32::BITS;
/// Rectangles drawn without the lookup at most, per eye.
const MOST_COVERED_RECTS: usize = 4;

/// A set of the tiles of an eye's image ([`TILES`] x [`TILES`], tile `(col, row)` holding
/// pixels `col * width / TILES` up to the next tile's first, rows alike): a row's tiles are
/// the bits of a word, column 0 the lowest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tiles([u32; TILES as usize]);

/// An image split for drawing: rectangles as pixels (x, y, width, height), disjoint, together
/// every tile the glass shows in.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Split {
    /// Covered tiles only: drawn without the environment's lookup.
    pub covered: Vec<[u32; 4]>,
    /// The rest of the image: drawn with it.
    pub rest: Vec<[u32; 4]>,
}

impl Tiles {
    /// No tile.
    pub const NONE: Tiles = Tiles([0; TILES as usize]);
    /// Every tile.
    pub const ALL: Tiles = Tiles([u32::MAX; TILES as usize]);

    /// Whether tile (`col`, `row`) is in the set.
    pub fn contains(self, col: u32, row: u32) -> bool {
        self.0[row as usize] & 1 << col != 0
    }

    /// Puts tile (`col`, `row`) in.
    pub fn put_in(&mut self, col: u32, row: u32) {
        self.0[row as usize] |= 1 << col;
    }

    /// Takes tile (`col`, `row`) out.
    pub fn take_out(&mut self, col: u32, row: u32) {
        self.0[row as usize] &= !(1 << col);
    }

    /// Tiles in the set.
    pub fn count(self) -> u32 {
        self.0.iter().map(|w| w.count_ones()).sum()
    }

    /// Takes out every tile that holds a pixel of the box from `lo` to `hi` (pixels) in an
    /// image of `extent`.
    pub fn remove(&mut self, lo: glam::Vec2, hi: glam::Vec2, extent: (u32, u32)) {
        let span = |lo: f32, hi: f32, size: u32| {
            (hi >= 0.0 && lo < size as f32).then(|| tile_of(lo, size)..=tile_of(hi, size))
        };
        let cols = span(lo.x, hi.x, extent.0);
        if let (Some(cols), Some(rows)) = (cols, span(lo.y, hi.y, extent.1)) {
            self.take_rect([*cols.start(), cols.end() + 1, *rows.start(), rows.end() + 1]);
        }
    }

    /// The image of `extent` split for drawing, this set the tiles the proof covers and
    /// `shown` those the glass may show in, a rectangle drawn costing as much as `draw_px`
    /// pixels drawn with the lookup rather than without it. Without the lookup: the rectangle
    /// of covered tiles that holds the most shown ones, then the same among the covered tiles
    /// left, as many as pay for their draw ([`MOST_COVERED_RECTS`] at most). With it: the rest
    /// of the shown tiles, taken the same way (a rectangle may take in tiles the glass does
    /// not show in), until none is left.
    pub fn split(self, shown: Tiles, extent: (u32, u32), draw_px: u64) -> Split {
        let tile_px = u64::from(extent.0) * u64::from(extent.1) / u64::from(TILES * TILES);
        let mut free = Tiles::ALL;
        let mut split = Split::default();
        while split.covered.len() < MOST_COVERED_RECTS {
            let left = self.and(free);
            let (rect, held) = largest(left, left.and(shown));
            if held == 0 || u64::from(held) * tile_px <= draw_px {
                break;
            }
            free.take_rect(rect);
            split.covered.extend(pixels(rect, extent));
        }
        loop {
            let (rect, held) = largest(free, free.and(shown));
            if held == 0 {
                break;
            }
            free.take_rect(rect);
            split.rest.extend(pixels(rect, extent));
        }
        split
    }

    /// Takes out a rectangle of tiles: first and end column, first and end row.
    fn take_rect(&mut self, [c0, c1, r0, r1]: [u32; 4]) {
        for row in &mut self.0[r0 as usize..r1 as usize] {
            *row &= !columns(c0, c1);
        }
    }

    /// The tiles in both sets.
    pub fn and(self, other: Tiles) -> Tiles {
        Tiles(std::array::from_fn(|row| self.0[row] & other.0[row]))
    }
}

/// The bits of columns `c0` up to `c1` in a row's word.
fn columns(c0: u32, c1: u32) -> u32 {
    let below = |c: u32| 1u32.checked_shl(c).map_or(u32::MAX, |bit| bit - 1);
    below(c1) & !below(c0)
}

/// The tile holding pixel `x` (clamped into the image) along a side of `size` pixels: the last
/// whose first pixel is not past it.
fn tile_of(x: f32, size: u32) -> u32 {
    let x = x.clamp(0.0, size as f32 - 1.0) as u32;
    let mut tile = (u64::from(x) * u64::from(TILES) / u64::from(size)) as u32;
    while tile > 0 && edge(tile, size) > x {
        tile -= 1;
    }
    while tile + 1 < TILES && edge(tile + 1, size) <= x {
        tile += 1;
    }
    tile
}

/// The first pixel of tile `i` along an image side of `size` pixels (the side's end for
/// [`TILES`]): a multiple of 4, so that no 2 x 2 quad of pixels a GPU shades together, nor a
/// 4 x 4 block lavapipe does, straddles two rectangles of a split (a tile is empty where the
/// side has under 4 pixels per tile).
pub fn edge(i: u32, size: u32) -> u32 {
    if i >= TILES {
        return size;
    }
    (u64::from(i) * u64::from(size) / u64::from(TILES)) as u32 & !3
}

/// A rectangle of tiles (first and end column, first and end row) as pixels of `extent`;
/// `None` where its tiles hold no pixel.
fn pixels([c0, c1, r0, r1]: [u32; 4], (w, h): (u32, u32)) -> Option<[u32; 4]> {
    let (x0, y0) = (edge(c0, w), edge(r0, h));
    let [width, height] = [edge(c1, w) - x0, edge(r1, h) - y0];
    (width > 0 && height > 0).then_some([x0, y0, width, height])
}

/// The rectangle inside `allowed` that holds the most tiles of `wanted`, as first and end
/// column, first and end row, and how many it holds (0: none); of equal ones, the first found
/// going down from the top row, then along from the left. Each span of rows meets the
/// columns allowed in all of them in runs, and every rectangle lies in one of those.
fn largest(allowed: Tiles, wanted: Tiles) -> ([u32; 4], u32) {
    let n = TILES as usize;
    // held[row][col]: wanted tiles above and left of (col, row).
    let mut held = [[0u16; TILES as usize + 1]; TILES as usize + 1];
    for row in 0..n {
        let mut along = 0;
        for col in 0..n {
            along += (wanted.0[row] >> col & 1) as u16;
            held[row + 1][col + 1] = held[row][col + 1] + along;
        }
    }
    let mut best = ([0; 4], 0);
    for r0 in 0..n {
        let mut across = u32::MAX;
        for r1 in r0..n {
            across &= allowed.0[r1];
            let mut left = across;
            while left != 0 {
                let c0 = left.trailing_zeros();
                let c1 = c0 + (left >> c0).trailing_ones();
                left &= !columns(c0, c1);
                let [a, b] = [c0 as usize, c1 as usize];
                let count = held[r1 + 1][b] + held[r0][a] - held[r0][b] - held[r1 + 1][a];
                if u32::from(count) > best.1 {
                    best = ([c0, c1, r0 as u32, r1 as u32 + 1], u32::from(count));
                }
            }
            if across == 0 {
                break;
            }
        }
    }
    best
}
