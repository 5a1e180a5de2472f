//! Caller-owned render targets: the whole frame, or one band (or tile) of it at a time.
//!
//! The rasterizer never allocates: the integrator hands it a colour slice, a depth slice and the
//! frame's size, and [`Target::new`] checks once that they agree. A device with too little RAM
//! for a whole frame draws it in horizontal bands instead: [`Target::window`] wraps buffers that
//! hold only a [`Window`] of the frame (an origin, a size and a row stride), the rasterizer draws
//! into that window exactly the pixels a full-frame draw would put there, and the caller flushes
//! the band to its panel before drawing the next one ([`Window::bands`] lists them).
//!
//! Pixel formats: [`Rgba8`] for PNG output and host windows, [`Rgb565`] for the 16-bit panels
//! common on microcontrollers, and [`Rgb565Be`], the same colour with its bytes in the order SPI
//! panels read them. Other formats implement [`Pixel`]. Depth is `u32` (24 significant bits) or
//! `u16` (the top 16 of them), the caller's choice through [`Depth`].

use core::fmt;

use crate::edge::DEPTH_MAX;

/// Largest accepted width or height in pixels.
///
/// Together with the clipping guard band (see [`crate::clip`]) this bounds every snapped screen
/// coordinate below 2^14 pixels, which keeps every edge-function product far inside `i64`.
pub const MAX_DIMENSION: usize = 4096;

/// Depth value of an empty `u32` pixel: farther than anything the rasterizer writes.
pub const DEPTH_CLEAR: u32 = u32::MAX;

/// How far (in depth units of `0..=DEPTH_MAX`) a wireframe line may lie behind the surface and
/// still show.
pub const WIRE_DEPTH_BIAS: u32 = DEPTH_MAX / 4096;

/// A pixel format the rasterizer can write.
pub trait Pixel: Copy {
    /// Packs an opaque colour.
    fn from_rgb(r: u8, g: u8, b: u8) -> Self;
    /// Unpacks to 8-bit channels (formats with fewer bits replicate their high bits).
    fn to_rgb(self) -> [u8; 3];
}

/// A depth-buffer element: `u32` keeps all 24 bits the rasterizer computes, `u16` the top 16
/// (half the memory; nearby surfaces may then tie, and the first drawn wins).
pub trait Depth: Copy + Ord + fmt::Debug {
    /// The value of an empty pixel, farther than anything written.
    const CLEAR: Self;
    /// Stores a depth of `0..=DEPTH_MAX` (smaller is nearer).
    fn from_depth(z: u32) -> Self;
    /// Whether a wireframe line at depth `z` shows over a surface at `stored` (it may lie up to
    /// [`WIRE_DEPTH_BIAS`] behind it).
    fn shows_line(z: u32, stored: Self) -> bool;
}

impl Depth for u32 {
    const CLEAR: u32 = DEPTH_CLEAR;
    #[inline(always)]
    fn from_depth(z: u32) -> u32 {
        z
    }
    #[inline(always)]
    fn shows_line(z: u32, stored: u32) -> bool {
        z <= stored.saturating_add(WIRE_DEPTH_BIAS)
    }
}

impl Depth for u16 {
    const CLEAR: u16 = u16::MAX;
    #[inline(always)]
    fn from_depth(z: u32) -> u16 {
        // The far plane's 0xFFFF is kept below CLEAR, so that it still draws on an empty pixel.
        ((z >> 8) as u16).min(u16::MAX - 1)
    }
    #[inline(always)]
    fn shows_line(z: u32, stored: u16) -> bool {
        Self::from_depth(z) <= stored.saturating_add((WIRE_DEPTH_BIAS >> 8) as u16)
    }
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

/// [`Rgb565`] with its high byte first in memory, whatever the machine's byte order: what an SPI
/// panel expects on the wire (ST7789, ILI9341 and kin), so a band can be sent by DMA as it is,
/// without swapping bytes on a little-endian microcontroller.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[repr(transparent)]
pub struct Rgb565Be(pub [u8; 2]);

impl From<Rgb565> for Rgb565Be {
    #[inline(always)]
    fn from(c: Rgb565) -> Self {
        Rgb565Be(c.0.to_be_bytes())
    }
}

impl From<Rgb565Be> for Rgb565 {
    #[inline(always)]
    fn from(c: Rgb565Be) -> Self {
        Rgb565(u16::from_be_bytes(c.0))
    }
}

/// Implements [`Pixel`] for a 16-bit 5:6:5 type through its conversions to and from [`Rgb565`],
/// so that every such format packs and unpacks exactly as [`Rgb565`] does.
macro_rules! pixel_via_rgb565 {
    ($t:ty) => {
        impl $crate::target::Pixel for $t {
            #[inline(always)]
            fn from_rgb(r: u8, g: u8, b: u8) -> Self {
                $crate::target::Rgb565::from_rgb(r, g, b).into()
            }
            #[inline(always)]
            fn to_rgb(self) -> [u8; 3] {
                $crate::target::Rgb565::from(self).to_rgb()
            }
        }
    };
}
#[cfg(feature = "embedded-graphics")]
pub(crate) use pixel_via_rgb565;

pixel_via_rgb565!(Rgb565Be);

/// A rectangle of a frame, in pixels: the part of it a [`Target`]'s buffers hold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Window {
    /// Leftmost column.
    pub x: usize,
    /// Top row.
    pub y: usize,
    /// Columns.
    pub width: usize,
    /// Rows.
    pub height: usize,
}

impl Window {
    /// The whole of a `width` by `height` frame.
    pub const fn full(width: usize, height: usize) -> Window {
        Window {
            x: 0,
            y: 0,
            width,
            height,
        }
    }

    /// The horizontal bands of `rows` rows (the last one shorter when `rows` does not divide the
    /// height) that cover a `width` by `height` frame, top to bottom; none when `rows` is 0.
    ///
    /// ```
    /// use vdlod_raster::Window;
    /// let bands: Vec<Window> = Window::bands(320, 40, 16).collect();
    /// assert_eq!(bands.len(), 3);
    /// assert_eq!(bands[2], Window { x: 0, y: 32, width: 320, height: 8 });
    /// ```
    pub fn bands(width: usize, height: usize, rows: usize) -> impl Iterator<Item = Window> {
        let count = if rows == 0 { 0 } else { height.div_ceil(rows) };
        (0..count).map(move |k| Window {
            x: 0,
            y: k * rows,
            width,
            height: rows.min(height - k * rows),
        })
    }
}

/// Why a [`Target`] could not be made from the given buffers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TargetError {
    /// The frame's or the window's width or height is zero.
    ZeroSize,
    /// Width or height exceeds [`MAX_DIMENSION`].
    TooLarge {
        /// Requested width.
        width: usize,
        /// Requested height.
        height: usize,
    },
    /// The window reaches past the frame's right or bottom edge.
    WindowOutside {
        /// The window.
        window: Window,
        /// Frame width.
        width: usize,
        /// Frame height.
        height: usize,
    },
    /// The row stride is shorter than the window's width.
    StrideTooShort {
        /// Elements from one row to the next.
        stride: usize,
        /// The window's width.
        width: usize,
    },
    /// The colour slice does not hold the window (exactly `width * height` pixels for
    /// [`Target::new`], at least `(rows - 1) * stride + columns` for [`Target::window`]).
    ColorLength {
        /// What it must hold.
        expected: usize,
        /// The slice's length.
        actual: usize,
    },
    /// The depth slice does not hold the window (as for [`TargetError::ColorLength`]).
    DepthLength {
        /// What it must hold.
        expected: usize,
        /// The slice's length.
        actual: usize,
    },
}

impl fmt::Display for TargetError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            TargetError::ZeroSize => write!(f, "frame or window has zero width or height"),
            TargetError::TooLarge { width, height } => write!(
                f,
                "frame {width}x{height} exceeds the maximum of {MAX_DIMENSION} pixels per side"
            ),
            TargetError::WindowOutside {
                window,
                width,
                height,
            } => write!(
                f,
                "window {}x{} at ({}, {}) reaches outside the {width}x{height} frame",
                window.width, window.height, window.x, window.y
            ),
            TargetError::StrideTooShort { stride, width } => write!(
                f,
                "row stride {stride} is shorter than the window's width {width}"
            ),
            TargetError::ColorLength { expected, actual } => write!(
                f,
                "colour buffer holds {actual} pixels, the window needs {expected}"
            ),
            TargetError::DepthLength { expected, actual } => write!(
                f,
                "depth buffer holds {actual} values, the window needs {expected}"
            ),
        }
    }
}

impl core::error::Error for TargetError {}

/// Colour and depth buffers for a frame, or for a window of it, borrowed from the caller.
///
/// Rows are stored top to bottom, pixels left to right, `stride` elements from one row to the
/// next (the window's width for [`Target::new`]).
///
/// ```
/// use vdlod_raster::{Rgba8, Target};
/// let mut color = [Rgba8::default(); 64 * 48];
/// let mut depth = [0u32; 64 * 48];
/// let mut target = Target::new(&mut color, &mut depth, 64, 48).unwrap();
/// target.clear(Rgba8([16, 16, 32, 255]));
/// assert_eq!(target.width(), 64);
/// ```
pub struct Target<'a, P: Pixel, D: Depth = u32> {
    pub(crate) color: &'a mut [P],
    pub(crate) depth: &'a mut [D],
    pub(crate) width: usize,
    pub(crate) height: usize,
    pub(crate) window: Window,
    pub(crate) stride: usize,
}

impl<'a, P: Pixel, D: Depth> Target<'a, P, D> {
    /// Wraps buffers of a whole `width` by `height` frame; both must hold exactly
    /// `width * height` entries.
    pub fn new(
        color: &'a mut [P],
        depth: &'a mut [D],
        width: usize,
        height: usize,
    ) -> Result<Self, TargetError> {
        check_frame(width, height)?;
        let expected = width * height;
        check_length(color.len(), depth.len(), expected, true)?;
        Ok(Target {
            color,
            depth,
            width,
            height,
            window: Window::full(width, height),
            stride: width,
        })
    }

    /// Wraps buffers holding only `window` of a `width` by `height` frame, `stride` elements per
    /// row (at least the window's width); both must hold at least
    /// `(window.height - 1) * stride + window.width` entries. A draw into it writes exactly what
    /// a draw of the whole frame writes into that window.
    ///
    /// ```
    /// use vdlod_raster::{Rgb565, Target, Window};
    /// // One 320x16 band of a 320x240 frame, in 10 KiB of colour and 10 KiB of 16-bit depth.
    /// let mut color = [Rgb565(0); 320 * 16];
    /// let mut depth = [0u16; 320 * 16];
    /// for band in Window::bands(320, 240, 16) {
    ///     let mut target = Target::window(&mut color, &mut depth, 320, 240, band, 320).unwrap();
    ///     target.clear(Rgb565(0));
    ///     // draw into it, then send `target.color()` to the panel
    /// }
    /// ```
    pub fn window(
        color: &'a mut [P],
        depth: &'a mut [D],
        width: usize,
        height: usize,
        window: Window,
        stride: usize,
    ) -> Result<Self, TargetError> {
        check_frame(width, height)?;
        if window.width == 0 || window.height == 0 {
            return Err(TargetError::ZeroSize);
        }
        let right = window.x.checked_add(window.width);
        let bottom = window.y.checked_add(window.height);
        if !matches!((right, bottom), (Some(r), Some(b)) if r <= width && b <= height) {
            return Err(TargetError::WindowOutside {
                window,
                width,
                height,
            });
        }
        if stride < window.width {
            return Err(TargetError::StrideTooShort {
                stride,
                width: window.width,
            });
        }
        // Cannot overflow: stride <= a slice length is checked first.
        let expected = match stride.checked_mul(window.height - 1) {
            Some(rows) => rows.saturating_add(window.width),
            None => usize::MAX,
        };
        check_length(color.len(), depth.len(), expected, false)?;
        Ok(Target {
            color,
            depth,
            width,
            height,
            window,
            stride,
        })
    }

    /// Fills the window's pixels with `background` and their depths with [`Depth::CLEAR`]
    /// (the padding after each row, and whatever the slices hold past the window, are left as
    /// they are).
    pub fn clear(&mut self, background: P) {
        let (width, rows, stride) = (self.window.width, self.window.height, self.stride);
        if stride == width {
            let len = width * rows;
            self.color[..len].fill(background);
            self.depth[..len].fill(D::CLEAR);
        } else {
            for y in 0..rows {
                let row = y * stride..y * stride + width;
                self.color[row.clone()].fill(background);
                self.depth[row].fill(D::CLEAR);
            }
        }
    }

    /// Frame width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Frame height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The part of the frame the buffers hold.
    pub fn area(&self) -> Window {
        self.window
    }

    /// Elements from one row of the buffers to the next.
    pub fn stride(&self) -> usize {
        self.stride
    }

    /// The colour buffer, row-major.
    pub fn color(&self) -> &[P] {
        self.color
    }

    /// The depth buffer, row-major; smaller is nearer.
    pub fn depth(&self) -> &[D] {
        self.depth
    }

    /// The colour of row `y` of the window (0 is its top row): `window.width` pixels.
    pub fn row(&self, y: usize) -> &[P] {
        let start = (y * self.stride).min(self.color.len());
        let end = (start + self.window.width).min(self.color.len());
        &self.color[start..end]
    }

    /// Index into the buffers of frame pixel `(x, y)`, which must lie in the window.
    #[inline(always)]
    pub(crate) fn index(&self, x: usize, y: usize) -> usize {
        (y - self.window.y) * self.stride + (x - self.window.x)
    }
}

pub(crate) fn check_frame(width: usize, height: usize) -> Result<(), TargetError> {
    if width == 0 || height == 0 {
        return Err(TargetError::ZeroSize);
    }
    if width > MAX_DIMENSION || height > MAX_DIMENSION {
        return Err(TargetError::TooLarge { width, height });
    }
    Ok(())
}

fn check_length(
    color: usize,
    depth: usize,
    expected: usize,
    exact: bool,
) -> Result<(), TargetError> {
    let fits = |len: usize| {
        if exact {
            len == expected
        } else {
            len >= expected
        }
    };
    if !fits(color) {
        return Err(TargetError::ColorLength {
            expected,
            actual: color,
        });
    }
    if !fits(depth) {
        return Err(TargetError::DepthLength {
            expected,
            actual: depth,
        });
    }
    Ok(())
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
    fn rejects_bad_windows() {
        let mut c = [Rgba8::default(); 40];
        let mut d = [0u16; 40];
        let band = |y, height| Window {
            x: 0,
            y,
            width: 10,
            height,
        };
        let make = |c: &mut [Rgba8], d: &mut [u16], w: Window, stride| {
            Target::window(c, d, 10, 8, w, stride).err()
        };
        assert_eq!(
            make(&mut c, &mut d, band(0, 0), 10),
            Some(TargetError::ZeroSize)
        );
        assert_eq!(
            make(&mut c, &mut d, band(6, 4), 10),
            Some(TargetError::WindowOutside {
                window: band(6, 4),
                width: 10,
                height: 8
            })
        );
        assert_eq!(
            make(&mut c, &mut d, band(usize::MAX, 4), 10),
            Some(TargetError::WindowOutside {
                window: band(usize::MAX, 4),
                width: 10,
                height: 8
            })
        );
        assert_eq!(
            make(&mut c, &mut d, band(0, 4), 9),
            Some(TargetError::StrideTooShort {
                stride: 9,
                width: 10
            })
        );
        // Four rows of stride 12 need 3 * 12 + 10 = 46 entries.
        assert_eq!(
            make(&mut c, &mut d, band(0, 4), 12),
            Some(TargetError::ColorLength {
                expected: 46,
                actual: 40
            })
        );
        assert_eq!(make(&mut c[..30], &mut d, band(4, 3), 10), None);
        assert_eq!(
            make(&mut c, &mut d[..29], band(4, 3), 10),
            Some(TargetError::DepthLength {
                expected: 30,
                actual: 29
            })
        );
        let t = Target::window(&mut c, &mut d, 10, 8, band(4, 4), 10).unwrap();
        assert_eq!(
            (t.width(), t.height(), t.area(), t.stride()),
            (10, 8, band(4, 4), 10)
        );
        assert_eq!(t.row(1).len(), 10);
    }

    #[test]
    fn bands_cover_the_frame_once() {
        for rows in 1..=9 {
            let mut next = 0;
            for b in Window::bands(5, 17, rows) {
                assert_eq!((b.x, b.y, b.width), (0, next, 5));
                assert!(b.height > 0 && b.height <= rows);
                next += b.height;
            }
            assert_eq!(next, 17);
        }
        assert_eq!(Window::bands(5, 17, 0).count(), 0);
    }

    #[test]
    fn u16_depth_keeps_the_top_bits_and_order() {
        assert_eq!(u16::from_depth(DEPTH_MAX), 0xFFFE);
        assert_eq!(u16::CLEAR, 0xFFFF);
        assert!(u32::from_depth(DEPTH_MAX) < u32::CLEAR);
        assert_eq!(u16::from_depth(0x12_3456), 0x1234);
        assert!(u16::shows_line(DEPTH_MAX, u16::CLEAR));
        assert!(u32::shows_line(DEPTH_MAX, DEPTH_CLEAR));
        assert!(!u16::shows_line(0x10_0000, 0x0F00));
        assert!(u16::shows_line(0x10_0000, 0x0FF1)); // bias 4095 >> 8 = 15
        assert!(!u16::shows_line(0x10_0000, 0x0FF0));
    }

    #[test]
    fn rgb565_be_is_big_endian_in_memory() {
        let c = Rgb565Be::from_rgb(0xFF, 0x80, 0x08);
        assert_eq!(c.0, Rgb565::from_rgb(0xFF, 0x80, 0x08).0.to_be_bytes());
        assert_eq!(c.0[0] >> 3, 0b11111);
        assert_eq!(c.to_rgb(), Rgb565::from_rgb(0xFF, 0x80, 0x08).to_rgb());
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
