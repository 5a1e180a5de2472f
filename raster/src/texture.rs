//! Textures: texels in a caller-provided slice, sampled in fixed point.
//!
//! A [`Texture`] borrows `width x height` texels of any [`Pixel`] format ([`crate::Rgb565`],
//! [`crate::Rgba8`], ...), row by row from the top. The textured draw
//! ([`crate::ShadedMesh::draw_textured`]) interpolates `u / w`, `v / w` and `1 / w` across each
//! triangle (perspective-correct mapping, one division per covered pixel), turns `(u, v)` into
//! texel coordinates with [`FRACTION_BITS`] fractional bits, and from there everything is integer
//! arithmetic: the texel lookup, the bilinear weights and the modulation by the lit colour. So
//! the same inputs give the same pixels on every target.
//!
//! `(0, 0)` is the top-left corner of the first texel and `(1, 1)` the bottom-right corner of the
//! last; texel `(x, y)`'s centre is at `((x + 0.5) / width, (y + 0.5) / height)`.
//!
//! ```
//! use vdlod_raster::texture::{Filter, Texture, Wrap};
//! use vdlod_raster::Rgba8;
//! // A 2 x 2 checker.
//! let (b, w) = (Rgba8([0, 0, 0, 255]), Rgba8([255, 255, 255, 255]));
//! let texels = [b, w, w, b];
//! let t = Texture::new(&texels, 2, 2, Filter::Nearest, Wrap::Repeat).unwrap();
//! assert_eq!(t.sample(0.25, 0.25), [0, 0, 0]);
//! assert_eq!(t.sample(0.75, 0.25), [255, 255, 255]);
//! assert_eq!(t.sample(1.25, 0.25), [0, 0, 0]); // repeats
//! ```

use core::fmt;

use crate::target::{Pixel, MAX_DIMENSION};

/// Fractional bits of a texel coordinate.
pub const FRACTION_BITS: u32 = 8;
const ONE: i32 = 1 << FRACTION_BITS;
const MASK: i32 = ONE - 1;

/// How a texel is chosen between texel centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The texel the point falls in.
    #[default]
    Nearest,
    /// The four texels around the point, weighted by its distance to their centres.
    Bilinear,
}

/// What coordinates outside `0..1` read.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// The texture tiles the plane.
    #[default]
    Repeat,
    /// The border texels extend outwards.
    Clamp,
}

/// Why texels cannot be a texture.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TextureError {
    /// A side is zero or larger than [`MAX_DIMENSION`].
    BadSize {
        /// Width asked for.
        width: usize,
        /// Height asked for.
        height: usize,
    },
    /// The slice does not hold `width x height` texels.
    WrongLength {
        /// Texels needed.
        expected: usize,
        /// Texels given.
        actual: usize,
    },
}

impl fmt::Display for TextureError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TextureError::BadSize { width, height } => write!(
                f,
                "a texture of {width} x {height} texels: each side must be 1 to {MAX_DIMENSION}"
            ),
            TextureError::WrongLength { expected, actual } => write!(
                f,
                "a texture needs {expected} texels (width x height), {actual} were given"
            ),
        }
    }
}

impl core::error::Error for TextureError {}

/// Texels borrowed from the caller, with the way they are sampled.
#[derive(Clone, Copy, Debug)]
pub struct Texture<'a, T: Pixel> {
    texels: &'a [T],
    width: i32,
    height: i32,
    /// How a texel is chosen.
    pub filter: Filter,
    /// What coordinates outside `0..1` read.
    pub wrap: Wrap,
}

impl<'a, T: Pixel> Texture<'a, T> {
    /// `width x height` texels, row by row from the top.
    pub fn new(
        texels: &'a [T],
        width: usize,
        height: usize,
        filter: Filter,
        wrap: Wrap,
    ) -> Result<Texture<'a, T>, TextureError> {
        if width == 0 || height == 0 || width > MAX_DIMENSION || height > MAX_DIMENSION {
            return Err(TextureError::BadSize { width, height });
        }
        if texels.len() != width * height {
            return Err(TextureError::WrongLength {
                expected: width * height,
                actual: texels.len(),
            });
        }
        Ok(Texture {
            texels,
            width: width as i32,
            height: height as i32,
            filter,
            wrap,
        })
    }

    /// Width and height in texels.
    pub fn size(&self) -> (usize, usize) {
        (self.width as usize, self.height as usize)
    }

    /// The colour at `(u, v)` (see the module doc for the coordinates); NaN reads as 0.
    #[inline]
    pub fn sample(&self, u: f32, v: f32) -> [u8; 3] {
        self.sample_fixed(fixed(u, self.width), fixed(v, self.height))
    }

    /// The colour at texel coordinates with [`FRACTION_BITS`] fractional bits.
    #[inline]
    pub fn sample_fixed(&self, x: i32, y: i32) -> [u8; 3] {
        match self.filter {
            Filter::Nearest => self.texel(x >> FRACTION_BITS, y >> FRACTION_BITS),
            Filter::Bilinear => {
                // Relative to texel centres.
                let (x, y) = (x - ONE / 2, y - ONE / 2);
                let (x0, y0) = (x >> FRACTION_BITS, y >> FRACTION_BITS);
                let (fx, fy) = ((x & MASK) as u32, (y & MASK) as u32);
                let t = [
                    self.texel(x0, y0),
                    self.texel(x0 + 1, y0),
                    self.texel(x0, y0 + 1),
                    self.texel(x0 + 1, y0 + 1),
                ];
                let one = ONE as u32;
                let w = [
                    (one - fx) * (one - fy),
                    fx * (one - fy),
                    (one - fx) * fy,
                    fx * fy,
                ];
                // The weights add up to 2^16: round to nearest.
                core::array::from_fn(|k| {
                    let sum: u32 = (0..4).map(|j| w[j] * t[j][k] as u32).sum();
                    ((sum + (1 << 15)) >> 16) as u8
                })
            }
        }
    }

    /// Texel `(x, y)` after wrapping.
    #[inline(always)]
    fn texel(&self, x: i32, y: i32) -> [u8; 3] {
        let (x, y) = match self.wrap {
            Wrap::Repeat => (x.rem_euclid(self.width), y.rem_euclid(self.height)),
            Wrap::Clamp => (x.clamp(0, self.width - 1), y.clamp(0, self.height - 1)),
        };
        // In range after wrapping, and `new` proved the slice long enough.
        self.texels
            .get((y * self.width + x) as usize)
            .map_or([0; 3], |t| t.to_rgb())
    }
}

/// `t` (in units of the texture's side) times `side` texels, with [`FRACTION_BITS`] fractional
/// bits, rounded to nearest; clamped to `±2^22` (a million repeats of the largest texture) and 0
/// for NaN, so that the integer steps after it never overflow.
#[inline(always)]
#[allow(clippy::manual_clamp)] // NaN must map into range
fn fixed(t: f32, side: i32) -> i32 {
    const LIMIT: f32 = 4_194_304.0;
    let v = (t * (side * ONE) as f32).max(-LIMIT).min(LIMIT);
    if v.is_nan() {
        0
    } else {
        libm::rintf(v) as i32
    }
}

/// `a * b / 255` rounded to nearest, exactly, for 8-bit `a` and `b`: a texel modulated by a lit
/// colour channel.
#[inline(always)]
pub fn modulate(a: u8, b: u8) -> u8 {
    let x = a as u32 * b as u32 + 128;
    ((x + (x >> 8)) >> 8) as u8
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::target::{Rgb565, Rgba8};

    fn grey(v: u8) -> Rgba8 {
        Rgba8([v, v, v, 255])
    }

    #[test]
    fn modulation_is_exact() {
        for a in 0..=255u32 {
            for b in 0..=255u32 {
                let exact = (a * b * 2 + 255) / 510;
                assert_eq!(modulate(a as u8, b as u8) as u32, exact, "{a} {b}");
            }
        }
    }

    #[test]
    fn nearest_picks_the_texel_the_point_is_in() {
        let texels = [grey(0), grey(10), grey(20), grey(30), grey(40), grey(50)];
        let t = Texture::new(&texels, 3, 2, Filter::Nearest, Wrap::Clamp).unwrap();
        assert_eq!(t.sample(0.1, 0.1), [0; 3]);
        assert_eq!(t.sample(0.5, 0.1), [10; 3]);
        assert_eq!(t.sample(0.9, 0.9), [50; 3]);
        // Clamped outside.
        assert_eq!(t.sample(-3.0, 7.0), [30; 3]);
        assert_eq!(t.sample(f32::NAN, 0.9), [30; 3]);
    }

    #[test]
    fn bilinear_is_exact_at_centres_and_blends_between() {
        let texels = [grey(0), grey(100), grey(200), grey(250)];
        let t = Texture::new(&texels, 2, 2, Filter::Bilinear, Wrap::Clamp).unwrap();
        assert_eq!(t.sample(0.25, 0.25), [0; 3]);
        assert_eq!(t.sample(0.75, 0.75), [250; 3]);
        // Halfway between the two top centres, and the middle of all four.
        assert_eq!(t.sample(0.5, 0.25), [50; 3]);
        assert_eq!(t.sample(0.5, 0.5), [138; 3]); // (0 + 100 + 200 + 250) / 4 = 137.5, rounded up
    }

    #[test]
    fn repeat_wraps_both_ways() {
        let texels = [Rgb565(0), Rgb565(0xFFFF)];
        let t = Texture::new(&texels, 2, 1, Filter::Nearest, Wrap::Repeat).unwrap();
        assert_eq!(t.sample(-0.25, 0.0), [255; 3]);
        assert_eq!(t.sample(2.25, 5.5), [0; 3]);
        // Bilinear across the seam blends the last texel with the first.
        let t = Texture {
            filter: Filter::Bilinear,
            ..t
        };
        assert_eq!(t.sample(0.0, 0.5), [128; 3]);
    }

    #[test]
    fn bad_sizes_are_refused() {
        let texels = [grey(0); 4];
        assert_eq!(
            Texture::new(&texels, 3, 2, Filter::Nearest, Wrap::Repeat).unwrap_err(),
            TextureError::WrongLength {
                expected: 6,
                actual: 4
            }
        );
        assert!(matches!(
            Texture::new(&texels[..0], 0, 4, Filter::Nearest, Wrap::Repeat),
            Err(TextureError::BadSize { .. })
        ));
    }
}
