//! Caller-owned render targets.
//!
//! The rasterizer never allocates: the integrator hands it a colour slice, a depth slice and the
//! viewport size, and [`Target::new`] checks once that they agree. Two pixel formats are provided:
//! [`Rgba8`] for PNG output and host windows, [`Rgb565`] for the 16-bit panels common on
//! microcontrollers. Other formats implement [`Pixel`].

use core::fmt;

/// Largest accepted width or height in pixels.
///
/// Together with the clipping guard band (see [`crate::clip`]) this bounds every snapped screen
/// coordinate below 2^14 pixels, which keeps every edge-function product far inside `i64`.
pub const MAX_DIMENSION: usize = 4096;

/// Depth value of an empty pixel: farther than anything the rasterizer writes.
pub const DEPTH_CLEAR: u32 = u32::MAX;

/// A pixel format the rasterizer can write.
pub trait Pixel: Copy {
    /// Packs an opaque colour.
    fn from_rgb(r: u8, g: u8, b: u8) -> Self;
    /// Unpacks to 8-bit channels (formats with fewer bits replicate their high bits).
    fn to_rgb(self) -> [u8; 3];
}

/// 8-bit red, green, blue, alpha in memory order; alpha is written as 255.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(transparent)]
pub struct Rgba8(pub [u8; 4]);

impl Pixel for Rgba8 {
    #[inline(always)]
    fn from_rgb(r: u8, g: u8, b: u8) -> Self {
        Rgba8([r, g, b, 255])
    }
    #[inline(always)]
    fn to_rgb(self) -> [u8; 3] {
        [self.0[0], self.0[1], self.0[2]]
    }
}

/// 16-bit 5:6:5 colour (red in the high bits), the native format of many small LCD panels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(transparent)]
pub struct Rgb565(pub u16);

impl Pixel for Rgb565 {
    #[inline(always)]
    fn from_rgb(r: u8, g: u8, b: u8) -> Self {
        Rgb565(((r as u16 & 0xF8) << 8) | ((g as u16 & 0xFC) << 3) | (b as u16 >> 3))
    }
    #[inline(always)]
    fn to_rgb(self) -> [u8; 3] {
        let r = ((self.0 >> 11) & 0x1F) as u8;
        let g = ((self.0 >> 5) & 0x3F) as u8;
        let b = (self.0 & 0x1F) as u8;
        [
            (r << 3) | (r >> 2),
            (g << 2) | (g >> 4),
            (b << 3) | (b >> 2),
        ]
    }
}

/// Why a [`Target`] could not be made from the given buffers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetError {
    /// Width or height is zero.
    ZeroSize,
    /// Width or height exceeds [`MAX_DIMENSION`].
    TooLarge {
        /// Requested width.
        width: usize,
        /// Requested height.
        height: usize,
    },
    /// The colour slice does not hold exactly `width * height` pixels.
    ColorLength {
        /// `width * height`.
        expected: usize,
        /// The slice's length.
        actual: usize,
    },
    /// The depth slice does not hold exactly `width * height` values.
    DepthLength {
        /// `width * height`.
        expected: usize,
        /// The slice's length.
        actual: usize,
    },
}

impl fmt::Display for TargetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TargetError::ZeroSize => write!(f, "viewport has zero width or height"),
            TargetError::TooLarge { width, height } => write!(
                f,
                "viewport {width}x{height} exceeds the maximum of {MAX_DIMENSION} pixels per side"
            ),
            TargetError::ColorLength { expected, actual } => write!(
                f,
                "colour buffer holds {actual} pixels, the viewport needs {expected}"
            ),
            TargetError::DepthLength { expected, actual } => write!(
                f,
                "depth buffer holds {actual} values, the viewport needs {expected}"
            ),
        }
    }
}

impl core::error::Error for TargetError {}

/// A colour and a depth buffer of the same size, borrowed from the caller.
///
/// Rows are stored top to bottom, pixels left to right, without padding.
///
/// ```
/// use vdlod_raster::{Rgba8, Target};
/// let mut color = [Rgba8::default(); 64 * 48];
/// let mut depth = [0u32; 64 * 48];
/// let mut target = Target::new(&mut color, &mut depth, 64, 48).unwrap();
/// target.clear(Rgba8([16, 16, 32, 255]));
/// assert_eq!(target.width(), 64);
/// ```
pub struct Target<'a, P: Pixel> {
    pub(crate) color: &'a mut [P],
    pub(crate) depth: &'a mut [u32],
    pub(crate) width: usize,
    pub(crate) height: usize,
}

impl<'a, P: Pixel> Target<'a, P> {
    /// Wraps caller-owned buffers; both must hold exactly `width * height` entries.
    pub fn new(
        color: &'a mut [P],
        depth: &'a mut [u32],
        width: usize,
        height: usize,
    ) -> Result<Self, TargetError> {
        if width == 0 || height == 0 {
            return Err(TargetError::ZeroSize);
        }
        if width > MAX_DIMENSION || height > MAX_DIMENSION {
            return Err(TargetError::TooLarge { width, height });
        }
        let expected = width * height;
        if color.len() != expected {
            return Err(TargetError::ColorLength {
                expected,
                actual: color.len(),
            });
        }
        if depth.len() != expected {
            return Err(TargetError::DepthLength {
                expected,
                actual: depth.len(),
            });
        }
        Ok(Target {
            color,
            depth,
            width,
            height,
        })
    }

    /// Fills the colour buffer with `background` and resets depth to [`DEPTH_CLEAR`].
    pub fn clear(&mut self, background: P) {
        self.color.fill(background);
        self.depth.fill(DEPTH_CLEAR);
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The colour buffer, row-major.
    pub fn color(&self) -> &[P] {
        self.color
    }

    /// The depth buffer, row-major; smaller is nearer.
    pub fn depth(&self) -> &[u32] {
        self.depth
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_mismatched_buffers() {
        let mut c = [Rgba8::default(); 12];
        let mut d = [0u32; 12];
        assert_eq!(
            Target::new(&mut c, &mut d, 4, 4).err(),
            Some(TargetError::ColorLength {
                expected: 16,
                actual: 12
            })
        );
        let mut c = [Rgba8::default(); 16];
        assert_eq!(
            Target::new(&mut c, &mut d, 4, 4).err(),
            Some(TargetError::DepthLength {
                expected: 16,
                actual: 12
            })
        );
        assert_eq!(
            Target::new(&mut c, &mut d, 0, 4).err(),
            Some(TargetError::ZeroSize)
        );
        let mut none: [Rgba8; 0] = [];
        let mut dnone: [u32; 0] = [];
        assert_eq!(
            Target::new(&mut none, &mut dnone, 5000, 0).err(),
            Some(TargetError::ZeroSize)
        );
    }

    #[test]
    fn rejects_oversized_viewport() {
        let mut c: [Rgba8; 0] = [];
        let mut d: [u32; 0] = [];
        assert_eq!(
            Target::new(&mut c, &mut d, MAX_DIMENSION + 1, 1).err(),
            Some(TargetError::TooLarge {
                width: MAX_DIMENSION + 1,
                height: 1
            })
        );
    }

    #[test]
    fn rgb565_round_trips_high_bits() {
        let p = Rgb565::from_rgb(0xFF, 0x80, 0x08);
        assert_eq!(p.0, (0b11111 << 11) | (0b100000 << 5) | 0b00001);
        assert_eq!(p.to_rgb(), [0xFF, 0x82, 0x08]);
        assert_eq!(Rgb565::from_rgb(0, 0, 0).to_rgb(), [0, 0, 0]);
        assert_eq!(Rgb565::from_rgb(255, 255, 255).to_rgb(), [255, 255, 255]);
    }
}
